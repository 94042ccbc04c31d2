// Boykov-Jolly graph-cut segmentation on any graph: nodes with an intensity and a size, edges with
// a contact measure. The super-voxel cut (mesh elements) and the voxel cut (the grid) both call it,
// so their energies are the same by construction. Max-flow: Kolmogorov's BK library (maxflow 3).
//
//   E(L) = lambda * sum_p size_p * -ln Pr(I_p | L_p) + sum_pq contact_pq * exp(-(I_p - I_q)^2 / 2 sigma^2) [L_p != L_q]
//
// Pr(I | object/background) is a kernel density estimate of the seed samples on a histogram whose
// bins the image fixes: their width divides a robust intensity range (0.5 to 99.5 percentiles of the
// node intensities, or of the voxel values with the voxel region term), and the histogram spans that
// range and every seed sample in bins of that width. It is mixed with 1 % of a uniform density so
// that no intensity is impossible.
// With the voxel region term (NodeVoxels set) a super-voxel's region cost is the sum of its voxels'
// costs, so for region terms the super-voxel cut is the voxel cut restricted to labellings that are
// constant on elements.
#pragma once

#include "GraphEdges.h"
#include "Parallel.h"
#include "SeedGeodesics.h"
#include "SharedArray.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace featuremesh
{
struct BoykovJollyParameters
{
  // Histogram bins over the robust intensity range (the histogram adds bins of their width to reach
  // seed samples beyond it); 0 = automatic (AutomaticBins: 64, or more when the seeds' densities need them).
  int Bins = 0;
  // Boundary-term sigma (intensity units); 0 = automatic: the root mean square of the intensity
  // differences over all graph edges.
  double Sigma = 0.0;
  // Weight of the region term against the boundary term (per voxel against per voxel face). 0.2
  // has the best mean Dice of both cuts over the shared cases (docs/cut.md).
  double Lambda = 0.2;
  // Kernel bandwidth of the seed histograms as a multiple of Silverman's rule.
  double Bandwidth = 1.0;
};

// The voxels of every node, for the voxel region term: the owner map and the voxel values (an image
// in its own type), viewed, and what a binning of them needs, made once per graph so that a cut
// pays per run of one bin in a node, not per voxel. Up to SortedVoxelLimit voxels, the values
// grouped by node in ascending order (a copy of 4 bytes per voxel for float or 8-/16-bit values,
// else 8): a new binning then costs a few comparisons per run. Beyond, per node the bounds of its
// values: a new binning costs a pass over the voxels (~3.5 ns each on one core here, 10x more than
// the sorted copy) without the copy (0.54 GB at 512^3). The histogram range comes from Low and
// High, the 0.5 and 99.5 percentiles of all voxel values.
struct NodeVoxelValues
{
  const std::int32_t* Owner = nullptr; // one per voxel: -1 none, else a node in [0, Nodes)
  const void* Values = nullptr;        // one per voxel, of the type ValueType names
  int ValueType = -1;
  std::int64_t Voxels = 0, Nodes = 0;
  double Low = 0.0, High = 0.0;
  // Sorted: node p's values in ascending order at [Offset[p], Offset[p + 1]), in single precision
  // when that holds each exactly, else in double.
  std::vector<std::int64_t> Offset;
  std::unique_ptr<float[]> Single;
  std::unique_ptr<double[]> Double;
  // Bounded: node p's values lie in [Min[p], Max[p]] (rounded outward to float; Min > Max without
  // voxels); Shared[p] when voxels of more than one of the Chunks fixed voxel ranges are its own.
  static constexpr std::int64_t Chunks = 8;
  std::vector<float> Min, Max;
  std::vector<std::uint8_t> Shared;
  // What keeps the viewed arrays alive, when the caller does not (optional).
  std::shared_ptr<const void> Keep;
  bool Empty() const { return !this->Owner; }
  bool Sorted() const { return this->Single || this->Double; }
  // f(pointer to the sorted values) with the pointer type they are stored in.
  template <typename F>
  auto Visit(F&& f) const
  {
    return this->Single ? f(static_cast<const float*>(this->Single.get())) : f(static_cast<const double*>(this->Double.get()));
  }
  // Voxel v's value.
  double Value(std::int64_t v) const;
};

// Images up to this many voxels (a 400^3 volume) keep their values sorted by node.
constexpr std::int64_t SortedVoxelLimit = std::int64_t(1) << 26;

// Groups `voxels` values (of any arithmetic type: an image in its own type) by their node
// (owner[v], -1 = none, in [-1, nodes)): sorted when voxels <= sortedLimit, else bounded. The owner
// map and the values must outlive `grouped` (or `keep` holds them). False with a sentence when a
// value is not finite or beyond +-1e150; false without one when progress asked to abort.
template <typename T>
bool GroupVoxelValues(const std::int32_t* owner, const T* values, std::int64_t voxels, std::int64_t nodes,
  NodeVoxelValues& grouped, std::string& error, const ParallelFor& parallel, const ProgressFunction& progress = NoProgress(),
  std::shared_ptr<const void> keep = nullptr, std::int64_t sortedLimit = SortedVoxelLimit);

// Each node's mean voxel value (0 for a node without voxels), summed in raster order.
std::vector<double> NodeMeans(const NodeVoxelValues& grouped);

struct CutProblem
{
  // The arrays are shared, not copied, by the records a MaxFlowCache keeps.
  SharedArray<double> Value;   // intensity of each node (mean intensity for an element)
  SharedArray<double> Size;    // region-term weight of each node (its voxel count); empty = 1 each
  GraphEdges Edges;            // explicit lists (viewed, held or owned) or a voxel grid
  SharedArray<double> Contact; // per edge, in voxel faces; empty = 1 each (the voxel grid)
  std::vector<std::uint8_t> Hard; // 0 free, 1 object seed, 2 background seed
  std::vector<double> ObjectSamples, ObjectWeights, BackgroundSamples, BackgroundWeights;
  // Optional exact region term for super-voxels (not owned): node p's region cost becomes the sum
  // over its voxel values x of -ln Pr(x | L) instead of Size_p * -ln Pr(Value_p | L). A mixed
  // element then costs what its voxels would cost in the voxel cut, rather than what its mean would.
  const NodeVoxelValues* NodeVoxels = nullptr;
  // The seeds' spatial term (SeedGeodesics.h), per voxel of each node, its Weight scaled by the seed
  // densities' overlap when Adaptive; Weight 0 = off. Step: the
  // length of each explicit edge in voxels (empty: 1 each, the voxel grid).
  SeedGeodesicParameters Geodesic{ 0.0 };
  SharedArray<double> Step;
  // The seeds' reach (SeedReach.h): each node's cost per voxel as object; empty = none.
  SharedArray<double> Reach;
  // How loops over nodes may split across threads.
  ParallelFor Parallel = SerialFor();
};

// The lattice bin of a value: Count bins of Width from Low, the end bins open.
struct ValueBins
{
  int Count = 1;
  double Low = 0.0, Width = 1.0;
  // Clamped before the conversion: a value far beyond the range (an outlier a billion bins away)
  // must not overflow the int.
  int operator()(double v) const
  {
    const double q = (v - this->Low) / this->Width;
    return q < 1.0 ? 0 : (q >= this->Count - 1 ? this->Count - 1 : static_cast<int>(q));
  }
};

struct CutResult
{
  std::vector<std::uint8_t> Label; // 1 object, 0 background
  double Flow = 0.0;
  double Sigma = 0.0;
  int Bins = 0;
  double GraphSeconds = 0.0, FlowSeconds = 0.0, GeodesicSeconds = 0.0;
  // Filled by the cuts after their connectivity rule: nodes the rule relabelled, and the object
  // components' sizes in voxels, largest first.
  std::int64_t ConnectivityChanged = 0;
  std::vector<double> ObjectComponentVoxels;
  // The region term of a voxel value, -ln Pr(x | label) = BinCost...[ValueBin(x)], and the spatial
  // term per voxel of each node (empty without one), before lambda: the voxel refinement's terms.
  ValueBins ValueBin;
  std::vector<double> BinCostObject, BinCostBackground;
  SharedArray<double> SpatialObject, SpatialBackground;
  // The seeds' reach per voxel of each node as object (CutProblem::Reach), not scaled; empty = none.
  SharedArray<double> Reach;
  // The seed densities' overlap (Bhattacharyya coefficient) and the spatial term's weight this cut
  // used; SpatialObject / SpatialBackground are at Geodesic.Weight, and SpatialScale takes them to it.
  double SeedOverlap = 0.0, SpatialWeight = 0.0, SpatialScale = 1.0;
  // R of the seeds' reach (SeedReach.h) in frame units, set by the cuts that add it; 0 without one.
  double ReachDistance = 0.0;
  std::string Error;
  bool Aborted = false;
};

std::string ValidateParameters(const BoykovJollyParameters& p);

// Silverman's kernel bandwidth of weighted samples (weights empty: 1 each) times `factor`, in their
// units: factor x 1.06 x the weighted standard deviation x n^-1/5, n the unweighted count; 0 without weight.
double SilvermanBandwidth(const std::vector<double>& samples, const std::vector<double>& weights, double factor);

// Probability density of each histogram bin from weighted samples (Silverman bandwidth, at least
// one bin), on [low, high]; mixed with 1 % uniform.
std::vector<double> SmoothedHistogram(const std::vector<double>& samples, const std::vector<double>& weights,
  double low, double high, int bins, double bandwidth = 1.0);

// A seed density's samples and their weights (empty: 1 each).
struct WeightedSamples
{
  const std::vector<double>* Values = nullptr;
  const std::vector<double>* Weights = nullptr;
};

// The histogram's bins when Bins is 0 (automatic) on [low, high]: 64, or more (at most 4096) when
// the narrowest seed density's Silverman bandwidth (times `bandwidth`) is under half of one of 64
// bins, so that it spans one bin. 64 bins of a CT's robust range (air to bone) put a soft tissue's density
// in one bin of 20 HU, where the kernel cannot resolve it and organs look alike.
int AutomaticBins(const std::vector<WeightedSamples>& samples, double low, double high, double bandwidth);

// What one cut keeps for the next cut of the same graph and node voxels. The max-flow (Kohli and
// Torr's dynamic graph cuts): when the next cut differs only in terminal capacities (a seed edit), it
// starts from this flow and its search trees instead of from zero; any other change starts afresh.
// The node voxels as runs of the histogram's bins, once a binning repeats (the bins' edges depend on
// the image and the bin count alone; bounded node voxels are binned at once): the voxel region
// term then costs a read per bin a node spans. Not for sharing between threads.
class MaxFlowCache
{
public:
  void Clear()
  {
    this->State.reset();
    this->Binned.reset();
    this->Geodesic.Clear();
  }
  bool Empty() const { return !this->State; }
  struct Kept;
  struct BinnedVoxels;

private:
  friend CutResult BoykovJollyCut(const CutProblem&, const BoykovJollyParameters&, const ProgressFunction&, MaxFlowCache*);
  std::shared_ptr<Kept> State;
  std::shared_ptr<BinnedVoxels> Binned;
  // The seeds' geodesic distances, updated rather than redone after a seed edit.
  SeedGeodesicCache Geodesic;
};

// Every input is checked first (finite values within +-1e150, non-negative sizes and contacts,
// edges naming nodes): a problem is an Error sentence, never a NaN in a capacity. Running out of
// memory is an Error, not an exit. Progress is reported on the caller's thread; when it asks to
// abort, the result is Aborted (the max-flow is then left to finish on its own thread).
// With `cache`, the flow is kept for the next cut and taken from the last one when it applies.
CutResult BoykovJollyCut(const CutProblem& problem, const BoykovJollyParameters& parameters,
  const ProgressFunction& progress = NoProgress(), MaxFlowCache* cache = nullptr);
} // namespace featuremesh
