#include "SeedConnectivity.h"
#include "Memory.h"

#include <algorithm>
#include <functional>
#include <numeric>
#include <utility>

namespace featuremesh
{
namespace
{
template <typename Index>
Index Find(std::vector<Index>& parent, Index p)
{
  while (parent[p] != p)
  {
    parent[p] = parent[parent[p]]; // path halving
    p = parent[p];
  }
  return p;
}

// Union-find over the nodes in `Index` (32-bit ids halve the memory the finds wander through on
// graphs under 2^31 nodes).
template <typename Index>
bool Components(const std::vector<std::uint8_t>& label, const GraphEdges& edges, std::vector<std::int64_t>& id,
  std::int64_t& count, std::vector<std::int64_t>* between, const ProgressFunction& progress)
{
  const Index n = static_cast<Index>(label.size());
  std::vector<Index> parent;
  AssignFresh(parent, static_cast<std::size_t>(n));
  std::iota(parent.begin(), parent.end(), Index(0));
  const auto unite = [&](std::int64_t e, std::int64_t p64, std::int64_t q64) {
    const Index p = static_cast<Index>(p64), q = static_cast<Index>(q64);
    if (label[p] == label[q])
    {
      Index a = Find(parent, p), b = Find(parent, q);
      if (a != b)
      {
        // The smaller root wins, so a component's root is its first node whatever the edge order.
        if (b < a)
        {
          std::swap(a, b);
        }
        parent[b] = a;
      }
    }
    else if (between)
    {
      between->insert(between->end(), { p64, q64, e });
    }
  };
  if (!edges.ForEachUntil(unite, [&](double t) { return progress(0.9 * t); }))
  {
    return false;
  }
  // Every root is its component's smallest node, so it is numbered before its other nodes.
  AssignFresh(id, static_cast<std::size_t>(n));
  count = 0;
  for (Index p = 0; p < n; ++p)
  {
    const Index r = Find(parent, p);
    id[p] = r == p ? count++ : id[r];
  }
  return true;
}
} // namespace

std::vector<std::int64_t> LabelComponents(const std::vector<std::uint8_t>& label, const GraphEdges& edges,
  std::int64_t& count, const ProgressFunction& progress, std::vector<std::int64_t>* between)
{
  std::vector<std::int64_t> id;
  if (between)
  {
    between->clear();
  }
  const bool done = label.size() < (std::size_t(1) << 31)
    ? Components<std::int32_t>(label, edges, id, count, between, progress)
    : Components<std::int64_t>(label, edges, id, count, between, progress);
  if (!done)
  {
    id.clear();
  }
  return id; // not a conditional expression, which would copy it
}

bool KeepLabelComponents(const std::vector<std::uint8_t>& label, const GraphEdges& edges, LabelComponentsOf& kept,
  const ProgressFunction& progress)
{
  if (kept.Id.size() == label.size() && !label.empty())
  {
    return true;
  }
  kept.Id = LabelComponents(label, edges, kept.Count, progress, &kept.Between);
  return kept.Id.size() == label.size();
}

void JoinContacts(const std::vector<std::uint8_t>& label, const GraphEdges& contacts, std::vector<std::int64_t>& id,
  std::int64_t& count)
{
  if (contacts.Size() == 0)
  {
    return;
  }
  std::vector<std::int64_t> root(count);
  std::iota(root.begin(), root.end(), std::int64_t(0));
  bool joined = false;
  contacts.ForEach([&](std::int64_t, std::int64_t p, std::int64_t q) {
    if (label[p] == label[q] && id[p] != id[q])
    {
      std::int64_t a = Find(root, id[p]), b = Find(root, id[q]);
      if (a != b)
      {
        root[std::max(a, b)] = std::min(a, b);
        joined = true;
      }
    }
  });
  if (!joined)
  {
    return;
  }
  // A root is the smallest of its components, so it is numbered before them.
  std::vector<std::int64_t> number(count, -1);
  std::int64_t next = 0;
  for (std::int64_t c = 0; c < count; ++c)
  {
    const std::int64_t r = Find(root, c);
    number[c] = r == c ? next++ : number[r];
  }
  for (std::int64_t& c : id)
  {
    c = number[c];
  }
  count = next;
}

const std::vector<std::int64_t>& ComponentIds(const std::vector<std::uint8_t>& label, const GraphEdges& contacts,
  const LabelComponentsOf& components, std::vector<std::int64_t>& joined, std::int64_t& count)
{
  count = components.Count;
  if (contacts.Size() == 0)
  {
    return components.Id;
  }
  joined = components.Id;
  JoinContacts(label, contacts, joined, count);
  return joined;
}

std::int64_t ApplyWithContacts(std::vector<std::uint8_t>& label, const ContactsFunction& contactsOf, const ContactsRule& apply)
{
  const std::vector<std::uint8_t> given = label;
  LabelComponentsOf components;
  std::int64_t changed = apply(label, GraphEdges(), components);
  std::vector<std::uint8_t> seen(label.size(), 0);
  std::vector<std::int64_t> nodes;
  // Each pass adds nodes: at most as many passes as nodes, in practice two or three.
  while (contactsOf && changed > 0)
  {
    const std::size_t before = nodes.size();
    for (std::size_t p = 0; p < label.size(); ++p)
    {
      if (label[p] != given[p] && !seen[p])
      {
        seen[p] = 1;
        nodes.push_back(static_cast<std::int64_t>(p));
      }
    }
    if (nodes.size() == before)
    {
      break;
    }
    std::sort(nodes.begin(), nodes.end());
    // Only pairs of one label can join; without any, the last run stands.
    std::vector<std::int64_t> a, b;
    contactsOf(nodes).ForEach([&](std::int64_t, std::int64_t p, std::int64_t q) {
      if (given[p] == given[q])
      {
        a.push_back(p);
        b.push_back(q);
      }
    });
    if (a.empty())
    {
      break;
    }
    label = given;
    changed = apply(label, GraphEdges(a, b), components);
  }
  return changed;
}

std::int64_t ApplyConnectivity(Connectivity mode, std::vector<std::uint8_t>& label, const GraphEdges& edges,
  const std::vector<std::uint8_t>& hard,
  const std::vector<std::uint8_t>& border, const ProgressFunction& progress, std::vector<double>* objectSizes,
  const std::vector<double>& size, std::vector<std::int64_t>* objectComponent, const GraphEdges& contacts,
  LabelComponentsOf* components)
{
  if (mode == Connectivity::Off && !objectSizes)
  {
    return 0;
  }
  // One pass over the edges: the components of equal label. Every later step relabels or joins
  // whole components, over the (few) edges between labels.
  const std::int64_t n = static_cast<std::int64_t>(label.size());
  LabelComponentsOf own;
  LabelComponentsOf& given = components ? *components : own;
  if (!KeepLabelComponents(label, edges, given, SubProgress(progress, 0.0, 0.8)))
  {
    return -1;
  }
  std::int64_t count = 0;
  std::vector<std::int64_t> joinedId;
  const std::vector<std::int64_t>& id = ComponentIds(label, contacts, given, joinedId, count);
  const std::vector<std::int64_t>& between = given.Between;
  const bool rules = mode != Connectivity::Off;
  std::vector<std::uint8_t> value(count, 0), objectSeed(count, 0), anchored(count, 0);
  std::vector<std::int64_t> nodes(count, 0);
  std::vector<double> weight(count, 0.0);
  for (std::int64_t p = 0; p < n; ++p)
  {
    const std::int64_t c = id[p];
    value[c] = label[p];
    ++nodes[c];
    weight[c] += size.empty() ? 1.0 : size[p];
    if (rules)
    {
      objectSeed[c] |= hard[p] == 1 ? 1 : 0;
      anchored[c] |= hard[p] == 2 || border[p] ? 1 : 0;
    }
  }
  // Components meeting across an edge: always of different labels.
  std::vector<std::pair<std::int64_t, std::int64_t>> meet(between.size() / 3);
  for (std::size_t e = 0; e < meet.size(); ++e)
  {
    const std::int64_t a = id[between[3 * e]], b = id[between[3 * e + 1]];
    meet[e] = { std::min(a, b), std::max(a, b) };
  }
  std::sort(meet.begin(), meet.end());
  meet.erase(std::unique(meet.begin(), meet.end()), meet.end());
  if (!progress(0.9))
  {
    return -1;
  }
  // The root of each component once components of label `v` that meet are joined.
  const auto joined = [&](std::uint8_t v) {
    std::vector<std::int64_t> root(count);
    std::iota(root.begin(), root.end(), std::int64_t(0));
    for (const auto& m : meet)
    {
      if (value[m.first] == v && value[m.second] == v)
      {
        std::int64_t a = Find(root, m.first), b = Find(root, m.second);
        if (a != b)
        {
          root[std::max(a, b)] = std::min(a, b);
        }
      }
    }
    for (std::int64_t c = 0; c < count; ++c)
    {
      root[c] = Find(root, c);
    }
    return root;
  };
  std::int64_t changed = 0;
  if (mode == Connectivity::SeededObject)
  {
    for (std::int64_t c = 0; c < count; ++c)
    {
      if (value[c] == 1 && !objectSeed[c])
      {
        value[c] = 0;
        changed += nodes[c];
      }
    }
  }
  if (rules)
  {
    // Background regions (joined through what the seeded rule relabelled) with no background seed
    // and no border node are holes.
    const std::vector<std::int64_t> root = joined(0);
    std::vector<std::uint8_t> keep(count, 0);
    for (std::int64_t c = 0; c < count; ++c)
    {
      keep[root[c]] |= value[c] == 0 && anchored[c] ? 1 : 0;
    }
    for (std::int64_t c = 0; c < count; ++c)
    {
      if (value[c] == 0 && !keep[root[c]])
      {
        value[c] = 1;
        changed += nodes[c];
      }
    }
    for (std::int64_t p = 0; p < n; ++p)
    {
      label[p] = value[id[p]];
    }
  }
  if (objectSizes)
  {
    const std::vector<std::int64_t> root = joined(1);
    std::vector<double> sum(count, 0.0);
    for (std::int64_t c = 0; c < count; ++c)
    {
      if (value[c] == 1)
      {
        sum[root[c]] += weight[c];
      }
    }
    objectSizes->clear();
    std::vector<std::int64_t> roots;
    for (std::int64_t c = 0; c < count; ++c)
    {
      if (value[c] == 1 && root[c] == c)
      {
        roots.push_back(c);
      }
    }
    // Largest first; equal sizes in order of their first node.
    std::stable_sort(roots.begin(), roots.end(), [&](std::int64_t a, std::int64_t b) { return sum[a] > sum[b]; });
    std::vector<std::int64_t> rank(count, -1);
    for (std::size_t k = 0; k < roots.size(); ++k)
    {
      objectSizes->push_back(sum[roots[k]]);
      rank[roots[k]] = static_cast<std::int64_t>(k);
    }
    if (objectComponent)
    {
      objectComponent->resize(n);
      for (std::int64_t p = 0; p < n; ++p)
      {
        (*objectComponent)[p] = value[id[p]] == 1 ? rank[root[id[p]]] : -1;
      }
    }
  }
  return progress(1.0) ? changed : -1;
}

std::vector<double> ObjectComponentSizes(
  const std::vector<std::uint8_t>& label, const GraphEdges& edges, const std::vector<double>& size, const ProgressFunction& progress)
{
  std::vector<std::uint8_t> unchanged(label);
  std::vector<double> sizes;
  if (ApplyConnectivity(Connectivity::Off, unchanged, edges, {}, {}, progress, &sizes, size) < 0)
  {
    sizes.clear();
  }
  return sizes;
}

} // namespace featuremesh
