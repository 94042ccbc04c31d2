// The seeds' spatial term (Price, Morse & Cohen, "Geodesic graph cut for interactive image
// segmentation", CVPR 2010) on any cut graph: geodesic distances from the object seeds and from
// the background seeds, each edge as long as the intensity step it crosses (in units of the
// histogram's intensity range) plus LengthWeight per voxel of distance between the nodes' centres.
// A node's spatial probability of object is D_B / (D_O + D_B): 1 on object seeds, 0 on background
// seeds, 1/2 where both are as far; its cost per voxel is -Weight ln of it, mixed with 1 % of the
// other label so that the appearance term can still win. The term only changes terminal
// capacities, so a seed edit keeps the max-flow's kept search trees (Kohli and Torr).
#pragma once

#include "GraphEdges.h"
#include "Parallel.h"
#include "SharedArray.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace featuremesh
{
struct SeedGeodesicParameters
{
  // Weight of the spatial term against the appearance term (both per voxel, in nats); 0 = off.
  // 1.5 and 0.005: of the weights and lengths tried on the three shared object cases, the pair that
  // keeps the Delaunay and the smoothed mesh's Dice closest (docs/cut.md, "The seeds' spatial term").
  double Weight = 1.5;
  // Length of one voxel of travel, in units of the intensity range: a path through a homogeneous
  // region costs about this per voxel, so seeds reach far across flat regions and stop at edges.
  double LengthWeight = 0.005;
  // The binary cut's Weight follows the seeds' intensity densities: it holds where the object's and
  // the background's densities overlap by SeedOverlapReference (Bhattacharyya coefficient, 0
  // disjoint to 1 the same) and scales with their overlap, so appearance that tells the seeds apart
  // decides and ambiguous appearance leaves more to the seeds' geometry (after Price, Morse & Cohen's
  // adaptive weighting; docs/cut.md). The multi-label cut keeps Weight: its joint densities of
  // several channels overlap on another scale.
  bool Adaptive = true;
};

// The overlap at which an adaptive Weight holds: BraTS-0005's seed files, the case Weight was chosen on.
constexpr double SeedOverlapReference = 0.75;

// The graph the distances run on: node values and edges; for explicit edges the length of each in
// voxels (Step, centre to centre); the grid's edges are one voxel long. A cache shares the arrays.
struct GeodesicGraph
{
  const GraphEdges* Edges = nullptr;
  SharedArray<double> Value;
  SharedArray<double> Step; // per explicit edge; empty: 1 each (a grid)
  std::int64_t Nodes() const { return static_cast<std::int64_t>(this->Value.size()); }
};

// Geodesic distance of every node from the nodes with hard[p] == seedKind (infinity where none is
// reachable), edge length |dValue| / scale + lengthWeight * step, the step rounded to a float.
// Dijkstra on a radix heap of 8-byte entries; for explicit edges a CSR adjacency of 32-bit ids is
// built first (fewer than 2^31 nodes and edge ends, as the cuts require), each neighbour's id with
// its step. Empty when progress asks to abort.
std::vector<double> GeodesicDistances(const GeodesicGraph& graph, const std::vector<std::uint8_t>& hard,
  std::uint8_t seedKind, double scale, double lengthWeight, const ProgressFunction& progress = NoProgress());

// Which nodes' distances SeedKindDistances changed since the call before, per kind, each node once
// per kind; or All.
struct SeedDistanceChanges
{
  bool All = true;
  std::vector<std::vector<std::int64_t>> Nodes;
};

// f(p) for every node the changes list, on `parallel`'s threads, one kind's list after another (a
// node listed for two kinds is visited twice, never by two threads at once).
template <typename F>
void ForEachChangedNode(const SeedDistanceChanges& changes, const ParallelFor& parallel, F&& f)
{
  for (const std::vector<std::int64_t>& nodes : changes.Nodes)
  {
    parallel(static_cast<std::int64_t>(nodes.size()), 16384, [&](std::int64_t first, std::int64_t last) {
      for (std::int64_t i = first; i < last; ++i)
      {
        f(nodes[i]);
      }
    });
  }
}

// What the spatial term keeps for the next cut of the same graph (values, steps and length weight):
// the adjacency, and per seed kind the seed nodes, their distances with the scale they are in, and
// each node's root seed and the two sums of its path (intensity steps and travel: a kept distance is
// intensity / scale + length weight x travel). A cut whose seeds of a kind are the kept ones, at the
// kept scale, reuses their distances. A new scale weighs each node's sums again and runs
// Dijkstra from the nodes an edge then shortens; added seeds run Dijkstra from themselves, bounded
// by the kept distances (they only shrink); nodes rooted at a removed seed restart from their
// neighbours that kept theirs. Any other change starts afresh. Not for sharing between threads.
class SeedGeodesicCache
{
public:
  void Clear() { this->State.reset(); }
  struct Kept;

private:
  friend std::vector<SharedArray<double>> SeedKindDistances(const GeodesicGraph&, const std::vector<std::uint8_t>&, int,
    double, double, const ProgressFunction&, SeedGeodesicCache*, const ParallelFor&, SeedDistanceChanges*);
  friend bool SeedGeodesicCosts(const GeodesicGraph&, const std::vector<std::uint8_t>&, double, const SeedGeodesicParameters&,
    const ParallelFor&, SharedArray<double>&, SharedArray<double>&, const ProgressFunction&, SeedGeodesicCache*);
  std::shared_ptr<Kept> State;
  // The kept distances when they were made on this graph, else a fresh record; the cache is empty
  // until the caller stores the record back whole.
  static std::shared_ptr<Kept> Take(const GeodesicGraph& graph, double lengthWeight, int kinds, SeedGeodesicCache* cache);
};

// The spatial term per voxel of each node (costObject, costBackground), from the distances to the
// object and the background seeds; the two runs share `parallel`'s threads (two at most; progress
// is then reported between them only). False when progress asks to abort; true with empty costs
// when Weight is 0 or either seed kind is absent. `cache` (optional) keeps what the next cut reuses,
// the costs among it: they are shared with the cache, which redoes them where the distances changed
// (on a copy while a holder still has them).
bool SeedGeodesicCosts(const GeodesicGraph& graph, const std::vector<std::uint8_t>& hard, double scale,
  const SeedGeodesicParameters& parameters, const ParallelFor& parallel, SharedArray<double>& costObject,
  SharedArray<double>& costBackground, const ProgressFunction& progress = NoProgress(),
  SeedGeodesicCache* cache = nullptr);

// Distances of every node from the seeds of each kind 1..kinds (hard[p] == kind), kept in `cache`
// (optional) as SeedGeodesicCosts keeps its two kinds: a kind whose seeds changed is updated (added
// seeds run Dijkstra from themselves, nodes rooted at removed ones restart from their neighbours),
// the others reused; the kinds share `parallel`'s threads as SeedGeodesicCosts's two do. The
// distances are shared with the cache, which copies them before changing them while a holder has
// them. `changes` (optional) receives what changed since the last call on this cache that asked
// (All without a cache or before such a call). Empty when progress asks to abort.
std::vector<SharedArray<double>> SeedKindDistances(const GeodesicGraph& graph, const std::vector<std::uint8_t>& hard,
  int kinds, double scale, double lengthWeight, const ProgressFunction& progress = NoProgress(),
  SeedGeodesicCache* cache = nullptr, const ParallelFor& parallel = SerialFor(), SeedDistanceChanges* changes = nullptr);

// Empty when usable, else a sentence.
std::string ValidateParameters(const SeedGeodesicParameters& p);
} // namespace featuremesh
