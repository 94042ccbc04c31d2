// What the seeds reach: connected components of a labelled graph (mesh elements sharing a face,
// voxels sharing a face) and the connectivity rule applied after either cut.
#pragma once

#include "GraphEdges.h"
#include "Parallel.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace featuremesh
{
enum class Connectivity : int
{
  // The cut's labels as they are: every object component the energy prefers is kept.
  Off = 0,
  // Background components that hold no background seed and touch no image border become object:
  // a hole inside the object is object. Unseeded object components are kept (several objects of
  // one kind, such as nuclei or cells, stay labelled with a few seeds).
  FillHoles = 1,
  // One object: object components that hold no object seed become background, then holes are
  // filled as above.
  SeededObject = 2,
  // The task's rule: Seeded Object for Task Object, Fill Holes for Task Class.
  FromTask = 3,
};

// What the user asks of the seeds.
enum class Task : int
{
  // The one object the object seeds lie in (a tumour, an organ).
  Object = 0,
  // Every object that looks like the seeded ones (all nuclei, all cells, all vessels).
  Class = 1,
};

// The rule `mode` names for `task` (FromTask resolved).
inline Connectivity ConnectivityFor(Connectivity mode, Task task)
{
  return mode != Connectivity::FromTask ? mode : (task == Task::Object ? Connectivity::SeededObject : Connectivity::FillHoles);
}

// Components of equal label over the graph's edges: an id per node, numbered in order of each
// component's first node (deterministic); `count` receives their number. Empty when `progress`
// (asked every 2^18 edges: a voxel graph has tens of millions) aborts. `between` (optional)
// receives the edges between different labels as (p, q, e) triples, in edge order.
std::vector<std::int64_t> LabelComponents(const std::vector<std::uint8_t>& label, const GraphEdges& edges,
  std::int64_t& count, const ProgressFunction& progress = NoProgress(), std::vector<std::int64_t>* between = nullptr);

// A labelling's components with the edges between labels (LabelComponents' id, count and
// between), kept while the labels and edges stay: ApplyWithContacts runs its rule from the labels
// as given on every pass, and only the contacts differ.
struct LabelComponentsOf
{
  std::vector<std::int64_t> Id, Between;
  std::int64_t Count = 0;
};

// The components of `label` into `kept` unless it holds `label`'s already (as many ids as nodes):
// false when `progress` aborts.
bool KeepLabelComponents(const std::vector<std::uint8_t>& label, const GraphEdges& edges, LabelComponentsOf& kept,
  const ProgressFunction& progress = NoProgress());

// Joins the components `id` (LabelComponents' numbering, `count` of them) of equal label that a
// pair of `contacts` links, renumbered in order of each joined component's first node.
void JoinContacts(const std::vector<std::uint8_t>& label, const GraphEdges& contacts, std::vector<std::int64_t>& id,
  std::int64_t& count);

// Each node's component: `components`' ids as they are when no contact is given (`count` their
// number), else a copy in `joined` with the contacts' components joined (JoinContacts; `count`
// updated).
const std::vector<std::int64_t>& ComponentIds(const std::vector<std::uint8_t>& label, const GraphEdges& contacts,
  const LabelComponentsOf& components, std::vector<std::int64_t>& joined, std::int64_t& count);

// The contacts (node pairs, as JoinContacts takes them) of the given nodes.
using ContactsFunction = std::function<GraphEdges(const std::vector<std::int64_t>& nodes)>;

// A connectivity rule, `apply(label, contacts, components)` (returning the nodes it relabelled, -1 on
// abort), run on `label` with the contacts of the nodes it relabels: first without contacts, then
// again from the labels as given with those of every node relabelled so far, until no new node is
// relabelled. A pair whose two nodes keep their labels changes no label, so the contacts of the
// relabelled nodes are all the rule needs; a pass whose new contacts join no two nodes of one label
// is not run. `components` are the given labels' (KeepLabelComponents): made by the first run, read
// by the others. Without `contactsOf`, one run without contacts.
using ContactsRule =
  std::function<std::int64_t(std::vector<std::uint8_t>& label, const GraphEdges& contacts, LabelComponentsOf& components)>;
std::int64_t ApplyWithContacts(std::vector<std::uint8_t>& label, const ContactsFunction& contactsOf, const ContactsRule& apply);

// Applies `mode` to `label` (1 object, 0 background) in place; `hard` (0 free, 1 object seed, 2
// background seed) and `border` (node touches the image border) per node. Seeded nodes keep their
// label. Returns how many node relabellings it made (a node the seeded rule drops and hole filling
// takes back counts twice), or -1 when `progress` aborts. `objectSizes` (optional) receives the
// sizes of the resulting object components as ObjectComponentSizes gives them, from the same pass,
// and `objectComponent` (optional, with objectSizes) each node's index among them (-1 background).
// `contacts` (optional) are node pairs that connect besides the edges (mesh elements whose voxels
// share a face without the elements sharing one): they join components of equal label.
// `components` (optional) keeps `label`'s components as given (KeepLabelComponents).
std::int64_t ApplyConnectivity(Connectivity mode, std::vector<std::uint8_t>& label, const GraphEdges& edges,
  const std::vector<std::uint8_t>& hard,
  const std::vector<std::uint8_t>& border, const ProgressFunction& progress = NoProgress(),
  std::vector<double>* objectSizes = nullptr, const std::vector<double>& size = {},
  std::vector<std::int64_t>* objectComponent = nullptr, const GraphEdges& contacts = GraphEdges(),
  LabelComponentsOf* components = nullptr);

// The sizes of the object components (sum of `size` over their nodes, 1 per node when `size` is
// empty), largest first; empty when `progress` aborts.
std::vector<double> ObjectComponentSizes(const std::vector<std::uint8_t>& label, const GraphEdges& edges,
  const std::vector<double>& size, const ProgressFunction& progress = NoProgress());
} // namespace featuremesh
