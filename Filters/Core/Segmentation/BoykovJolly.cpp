#include "BoykovJolly.h"
#include "FlowGraph.h"
#include "Memory.h"
#include "Percentile.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <tuple>
#include <type_traits>

namespace featuremesh
{
namespace
{
// Values whose squares and sums stay finite in double precision.
constexpr double LargestIntensity = 1e150;

bool Usable(double v)
{
  return std::isfinite(v) && std::fabs(v) <= LargestIntensity;
}

std::string UnusableIntensities(std::int64_t count)
{
  return std::to_string(count) + " intensities are NaN, infinite or beyond +-1e150; replace or rescale them (e.g. with a Calculator) first.";
}

using Clock = std::chrono::steady_clock;
} // namespace

std::string ValidateParameters(const BoykovJollyParameters& p)
{
  if (p.Bins != 0 && (p.Bins < 2 || p.Bins > 4096))
  {
    return "the histogram bin count must be 0 (automatic) or between 2 and 4096.";
  }
  if (!(p.Sigma >= 0.0) || !std::isfinite(p.Sigma))
  {
    return "sigma must be 0 (automatic) or positive.";
  }
  if (!(p.Lambda >= 0.0 && p.Lambda <= 1e6))
  {
    return "lambda must lie in [0, 1e6].";
  }
  if (!(p.Bandwidth > 0.0 && p.Bandwidth <= 100.0))
  {
    return "the bandwidth factor must lie in (0, 100].";
  }
  return std::string();
}

double SilvermanBandwidth(const std::vector<double>& s, const std::vector<double>& w, double factor)
{
  double total = 0.0, mean = 0.0;
  for (size_t i = 0; i < s.size(); ++i)
  {
    const double wi = w.empty() ? 1.0 : w[i];
    total += wi;
    mean += wi * s[i];
  }
  if (!(total > 0.0))
  {
    return 0.0;
  }
  mean /= total;
  double var = 0.0;
  for (size_t i = 0; i < s.size(); ++i)
  {
    var += (w.empty() ? 1.0 : w[i]) * (s[i] - mean) * (s[i] - mean);
  }
  const double sd = std::sqrt(var / total);
  // The unweighted sample count: weights say how much a sample counts, not how many independent
  // draws it is.
  return factor * 1.06 * sd * std::pow(static_cast<double>(s.size()), -0.2);
}

std::vector<double> SmoothedHistogram(
  const std::vector<double>& s, const std::vector<double>& w, double low, double high, int bins, double bandwidth)
{
  std::vector<double> hist(bins, 0.0);
  const double width = (high - low) / bins;
  double total = 0.0;
  for (size_t i = 0; i < s.size(); ++i)
  {
    const double wi = w.empty() ? 1.0 : w[i];
    const int b = std::min(bins - 1, std::max(0, static_cast<int>((s[i] - low) / width)));
    hist[b] += wi;
    total += wi;
  }
  std::vector<double> density(bins, 1.0 / bins);
  if (total <= 0.0)
  {
    return density;
  }
  const double h = std::max(1.0, SilvermanBandwidth(s, w, bandwidth) / width);
  const int radius = static_cast<int>(std::ceil(3.0 * h));
  double sum = 0.0;
  for (int b = 0; b < bins; ++b)
  {
    double acc = 0.0;
    for (int t = std::max(0, b - radius); t <= std::min(bins - 1, b + radius); ++t)
    {
      acc += hist[t] * std::exp(-0.5 * (b - t) * (b - t) / (h * h));
    }
    density[b] = acc;
    sum += acc;
  }
  for (double& d : density)
  {
    d = 0.99 * d / sum + 0.01 / bins;
  }
  return density;
}

int AutomaticBins(const std::vector<WeightedSamples>& samples, double low, double high, double bandwidth)
{
  constexpr int base = 64;
  const double width = (high - low) / base;
  double narrowest = 1.0; // bandwidth in bins of `width`
  for (const WeightedSamples& set : samples)
  {
    const double h = set.Values->size() < 2 || !(width > 0.0)
      ? 0.0
      : SilvermanBandwidth(*set.Values, set.Weights ? *set.Weights : std::vector<double>(), bandwidth) / width;
    // A density of one value is a spike at any bin width.
    if (h > 0.0)
    {
      narrowest = std::min(narrowest, h);
    }
  }
  // Up to half a bin the histogram's one-bin floor on the kernel widens it at most twice.
  return narrowest < 0.5 ? static_cast<int>(std::min(4096.0, std::ceil(base / narrowest))) : base;
}

namespace
{
// The value types a NodeVoxelValues may view, by ValueType.
using VoxelTypes = std::tuple<float, double, char, signed char, unsigned char, short, unsigned short, int, unsigned int,
  long, unsigned long, long long, unsigned long long>;

template <typename T, std::size_t I = 0>
constexpr int VoxelTypeIndex()
{
  if constexpr (I == std::tuple_size<VoxelTypes>::value)
  {
    return -1;
  }
  else if constexpr (std::is_same<T, std::tuple_element_t<I, VoxelTypes>>::value)
  {
    return static_cast<int>(I);
  }
  else
  {
    return VoxelTypeIndex<T, I + 1>();
  }
}

// f(values as a pointer to their own type).
template <typename F, std::size_t I = 0>
auto VisitVoxelValues(const NodeVoxelValues& voxels, F&& f)
{
  if constexpr (I + 1 < std::tuple_size<VoxelTypes>::value)
  {
    if (voxels.ValueType != static_cast<int>(I))
    {
      return VisitVoxelValues<F, I + 1>(voxels, std::forward<F>(f));
    }
  }
  return f(static_cast<const std::tuple_element_t<I, VoxelTypes>*>(voxels.Values));
}
} // namespace

double NodeVoxelValues::Value(std::int64_t v) const
{
  return VisitVoxelValues(*this, [v](const auto* values) { return static_cast<double>(values[v]); });
}

std::vector<double> NodeMeans(const NodeVoxelValues& grouped)
{
  std::vector<double> sum(grouped.Nodes, 0.0), count(grouped.Nodes, 0.0);
  VisitVoxelValues(grouped, [&](const auto* values) {
    for (std::int64_t v = 0; v < grouped.Voxels; ++v)
    {
      if (grouped.Owner[v] >= 0)
      {
        sum[grouped.Owner[v]] += static_cast<double>(values[v]);
        count[grouped.Owner[v]] += 1.0;
      }
    }
  });
  for (std::int64_t p = 0; p < grouped.Nodes; ++p)
  {
    sum[p] = count[p] > 0.0 ? sum[p] / count[p] : 0.0;
  }
  return sum;
}

namespace
{
// Node p's values in ascending order at [Offset[p], Offset[p + 1]): a counting sort by node in a
// fixed number of voxel chunks (whatever the threads), so each node's voxels stay in raster order
// and the result does not depend on how the work is split; then each node's values are sorted.
template <typename T>
bool SortByNode(const std::int32_t* owner, const T* values, std::int64_t voxels, std::int64_t nodes,
  NodeVoxelValues& grouped, std::string& error, const ParallelFor& parallel, const ProgressFunction& progress)
{
  constexpr std::int64_t chunks = 4;
  const std::int64_t size = (voxels + chunks - 1) / chunks;
  std::vector<std::int64_t> cursor(static_cast<size_t>(chunks * nodes), 0), badPerChunk(chunks, 0);
  parallel(chunks, 1, [&](std::int64_t c0, std::int64_t c1) {
    for (std::int64_t c = c0; c < c1; ++c)
    {
      std::int64_t* count = cursor.data() + c * nodes;
      std::int64_t bad = 0;
      for (std::int64_t v = c * size, e = std::min(voxels, (c + 1) * size); v < e; ++v)
      {
        const double x = static_cast<double>(values[v]);
        bad += Usable(x) ? 0 : 1;
        if (owner[v] >= 0)
        {
          ++count[owner[v]];
        }
      }
      badPerChunk[c] = bad;
    }
  });
  const std::int64_t bad = std::accumulate(badPerChunk.begin(), badPerChunk.end(), std::int64_t(0));
  if (bad)
  {
    error = UnusableIntensities(bad);
    return false;
  }
  if (!progress(0.3))
  {
    return false;
  }
  grouped.Offset.assign(nodes + 1, 0);
  std::int64_t total = 0;
  for (std::int64_t p = 0; p < nodes; ++p)
  {
    grouped.Offset[p] = total;
    for (std::int64_t c = 0; c < chunks; ++c)
    {
      const std::int64_t n = cursor[c * nodes + p];
      cursor[c * nodes + p] = total;
      total += n;
    }
  }
  grouped.Offset[nodes] = total;
  // Not zero-filled: every element is written below (a 9 M-voxel volume's 71 MB would be written twice).
  auto scatterAndSort = [&](auto* out) {
    parallel(chunks, 1, [&](std::int64_t c0, std::int64_t c1) {
      for (std::int64_t c = c0; c < c1; ++c)
      {
        std::int64_t* next = cursor.data() + c * nodes;
        for (std::int64_t v = c * size, e = std::min(voxels, (c + 1) * size); v < e; ++v)
        {
          if (owner[v] >= 0)
          {
            out[next[owner[v]]++] = static_cast<std::remove_pointer_t<decltype(out)>>(values[v]);
          }
        }
      }
    });
    if (!progress(0.6))
    {
      return false;
    }
    return BatchedFor(nodes, 4096, parallel, SubProgress(progress, 0.6, 1.0), [&](std::int64_t b, std::int64_t e) {
      for (std::int64_t p = b; p < e; ++p)
      {
        std::sort(out + grouped.Offset[p], out + grouped.Offset[p + 1]);
      }
    });
  };
  constexpr bool single = std::is_same<T, float>::value || (std::is_integral<T>::value && sizeof(T) <= 2);
  if (single)
  {
    grouped.Single.reset(new float[total]);
    AdviseHugePages(grouped.Single.get(), total * sizeof(float));
    return scatterAndSort(grouped.Single.get());
  }
  grouped.Double.reset(new double[total]);
  AdviseHugePages(grouped.Double.get(), total * sizeof(double));
  return scatterAndSort(grouped.Double.get());
}

// Node p's value bounds and whether voxels of more than one chunk are its own.
template <typename T>
bool BoundByNode(const std::int32_t* owner, const T* values, std::int64_t voxels, std::int64_t nodes,
  NodeVoxelValues& grouped, std::string& error, const ParallelFor& parallel, const ProgressFunction& progress)
{
  // One pass in fixed voxel chunks (whatever the threads): each chunk's bounds of its nodes' values,
  // merged below; a node seen by one chunk only is that chunk's alone when cuts count its voxels.
  constexpr std::int64_t chunks = NodeVoxelValues::Chunks;
  const std::int64_t size = (voxels + chunks - 1) / chunks;
  std::vector<std::int64_t> badPerChunk(chunks, 0);
  std::vector<std::vector<float>> low(chunks), high(chunks);
  parallel(chunks, 1, [&](std::int64_t c0, std::int64_t c1) {
    for (std::int64_t c = c0; c < c1; ++c)
    {
      std::vector<float>& lo = low[c];
      std::vector<float>& hi = high[c];
      AssignFresh(lo, static_cast<std::size_t>(nodes), std::numeric_limits<float>::infinity());
      AssignFresh(hi, static_cast<std::size_t>(nodes), -std::numeric_limits<float>::infinity());
      std::int64_t bad = 0;
      for (std::int64_t v = c * size, e = std::min(voxels, (c + 1) * size); v < e; ++v)
      {
        const double x = static_cast<double>(values[v]);
        bad += Usable(x) ? 0 : 1;
        const std::int32_t p = owner[v];
        if (p >= 0)
        {
          // Rounded outward to float: a wider bound only adds runs of no voxels.
          float down = static_cast<float>(x), up = down;
          if (static_cast<double>(down) > x)
          {
            down = std::nextafter(down, -std::numeric_limits<float>::infinity());
          }
          if (static_cast<double>(up) < x)
          {
            up = std::nextafter(up, std::numeric_limits<float>::infinity());
          }
          lo[p] = std::min(lo[p], down);
          hi[p] = std::max(hi[p], up);
        }
      }
      badPerChunk[c] = bad;
    }
  });
  const std::int64_t bad = std::accumulate(badPerChunk.begin(), badPerChunk.end(), std::int64_t(0));
  if (bad)
  {
    error = UnusableIntensities(bad);
    return false;
  }
  AssignFresh(grouped.Min, static_cast<std::size_t>(nodes));
  AssignFresh(grouped.Max, static_cast<std::size_t>(nodes));
  AssignFresh(grouped.Shared, static_cast<std::size_t>(nodes));
  parallel(nodes, 65536, [&](std::int64_t p0, std::int64_t p1) {
    for (std::int64_t p = p0; p < p1; ++p)
    {
      float lo = std::numeric_limits<float>::infinity(), hi = -lo;
      int seen = 0;
      for (std::int64_t c = 0; c < chunks; ++c)
      {
        seen += low[c][p] <= high[c][p] ? 1 : 0;
        lo = std::min(lo, low[c][p]);
        hi = std::max(hi, high[c][p]);
      }
      grouped.Min[p] = lo;
      grouped.Max[p] = hi;
      grouped.Shared[p] = seen > 1 ? 1 : 0;
    }
  });
  return progress(1.0);
}
} // namespace

template <typename T>
bool GroupVoxelValues(const std::int32_t* owner, const T* values, std::int64_t voxels, std::int64_t nodes,
  NodeVoxelValues& grouped, std::string& error, const ParallelFor& parallel, const ProgressFunction& progress,
  std::shared_ptr<const void> keep, std::int64_t sortedLimit)
{
  static_assert(VoxelTypeIndex<T>() >= 0, "a voxel value type NodeVoxelValues knows");
  grouped = NodeVoxelValues();
  if (voxels > static_cast<std::int64_t>(std::numeric_limits<std::uint32_t>::max()))
  {
    error = "the voxel region term counts voxels in 32 bits: the image has more than 4 294 967 295; turn VoxelRegionTerm off.";
    return false;
  }
  const ProgressFunction part = SubProgress(progress, 0.0, 0.9);
  if (!(voxels <= sortedLimit ? SortByNode(owner, values, voxels, nodes, grouped, error, parallel, part)
                              : BoundByNode(owner, values, voxels, nodes, grouped, error, parallel, part)))
  {
    grouped = NodeVoxelValues();
    return false;
  }
  grouped.Owner = owner;
  grouped.Values = values;
  grouped.ValueType = VoxelTypeIndex<T>();
  grouped.Voxels = voxels;
  grouped.Nodes = nodes;
  const std::array<double, 2> range = HistogramRange(values, voxels);
  grouped.Low = range[0];
  grouped.High = range[1];
  grouped.Keep = std::move(keep);
  return progress(1.0);
}
#define FEATUREMESH_GROUP_VOXEL_VALUES(T)                                                                        \
  template bool GroupVoxelValues<T>(const std::int32_t*, const T*, std::int64_t, std::int64_t, NodeVoxelValues&, \
    std::string&, const ParallelFor&, const ProgressFunction&, std::shared_ptr<const void>, std::int64_t);
FEATUREMESH_GROUP_VOXEL_VALUES(float)
FEATUREMESH_GROUP_VOXEL_VALUES(double)
FEATUREMESH_GROUP_VOXEL_VALUES(char)
FEATUREMESH_GROUP_VOXEL_VALUES(signed char)
FEATUREMESH_GROUP_VOXEL_VALUES(unsigned char)
FEATUREMESH_GROUP_VOXEL_VALUES(short)
FEATUREMESH_GROUP_VOXEL_VALUES(unsigned short)
FEATUREMESH_GROUP_VOXEL_VALUES(int)
FEATUREMESH_GROUP_VOXEL_VALUES(unsigned int)
FEATUREMESH_GROUP_VOXEL_VALUES(long)
FEATUREMESH_GROUP_VOXEL_VALUES(unsigned long)
FEATUREMESH_GROUP_VOXEL_VALUES(long long)
FEATUREMESH_GROUP_VOXEL_VALUES(unsigned long long)
#undef FEATUREMESH_GROUP_VOXEL_VALUES

namespace
{
// Long loops ask for progress (and abort) every 2^18 steps: a few ms each, ~0.25 s at the worst
// on fresh memory.
constexpr std::int64_t CheckEvery = (std::int64_t(1) << 18) - 1;

} // namespace

using Flow = FlowGraph;

// The graph after its last max-flow, and what it was built from.
struct MaxFlowCache::Kept
{
  std::shared_ptr<Flow> Graph;
  // The boundary term's inputs (explicit edge lists copied unless held; the arrays shared, so a
  // re-cut of the same arrays finds them by their storage) and what it made of them. The sizes and
  // steps too: a problem whose arrays are all the kept ones was checked when they were kept.
  GraphEdges Edges;
  SharedArray<double> Value, Contact, Size, Step;
  double SigmaParameter = 0.0, Sigma = 0.0, WeightTotal = 0.0;
  // The terminal capacities of the last flow.
  std::unique_ptr<double[]> Source, Sink;
};

// Node p's voxels as runs of one bin (ascending) at [Offset[p], Offset[p + 1]), for the bins of
// width Width from Low.
struct MaxFlowCache::BinnedVoxels
{
  const NodeVoxelValues* From = nullptr;
  std::int64_t Nodes = 0;
  int Bins = 0;
  double Low = 0.0, Width = 0.0;
  std::vector<std::int64_t> Offset;
  std::vector<std::uint16_t> Bin;
  std::vector<std::uint32_t> Count;
  bool Matches(const NodeVoxelValues* from, int bins, double low, double width) const
  {
    return this->From == from && this->Nodes == from->Nodes && this->Bins == bins && this->Low == low &&
      this->Width == width;
  }
  bool Empty() const { return this->Offset.empty(); }
};

namespace
{
// Empty when every input of the energy is usable, else a sentence. The arrays of `checked` (the
// last cut's, optional) are not read again.
std::string ValidateProblem(const CutProblem& pr, const ProgressFunction& progress, bool& aborted,
  const MaxFlowCache::Kept* checked)
{
  const std::int64_t n = static_cast<std::int64_t>(pr.Value.size());
  const GraphEdges& edges = pr.Edges;
  const std::int64_t m = edges.Size();
  if (n == 0)
  {
    return "the graph is empty.";
  }
  if (std::string size = GraphSizeProblem(n, m); !size.empty())
  {
    return size;
  }
  const auto& dims = edges.GridDims();
  if ((!pr.Size.empty() && static_cast<std::int64_t>(pr.Size.size()) != n) ||
    static_cast<std::int64_t>(pr.Hard.size()) != n || edges.Malformed() ||
    (edges.IsGrid() && static_cast<std::int64_t>(dims[0]) * dims[1] * dims[2] != n) ||
    (!pr.Contact.empty() && static_cast<std::int64_t>(pr.Contact.size()) != m) ||
    (!pr.Step.empty() && static_cast<std::int64_t>(pr.Step.size()) != m) ||
    (!pr.Reach.empty() && static_cast<std::int64_t>(pr.Reach.size()) != n) ||
    (pr.NodeVoxels && (pr.NodeVoxels->Nodes != n || pr.NodeVoxels->Empty())))
  {
    return "the graph's arrays disagree in length.";
  }
  const bool same = checked && checked->Value.SameStorage(pr.Value) && checked->Size.SameStorage(pr.Size) &&
    checked->Contact.SameStorage(pr.Contact) && checked->Step.SameStorage(pr.Step) && checked->Edges.Same(edges);
  std::int64_t badValue = 0, badSize = 0, badEdge = 0;
  if (!same)
  {
    for (double v : pr.Value)
    {
      badValue += Usable(v) ? 0 : 1;
    }
    for (double size : pr.Size)
    {
      badSize += (std::isfinite(size) && size >= 0.0) ? 0 : 1;
    }
  }
  // Grid edges are valid by construction.
  const auto checkEdge = [&](std::int64_t e, std::int64_t a, std::int64_t b) {
    badEdge += (a >= 0 && a < n && b >= 0 && b < n &&
                 (pr.Contact.empty() || (std::isfinite(pr.Contact[e]) && pr.Contact[e] >= 0.0)) &&
                 (pr.Step.empty() || (std::isfinite(pr.Step[e]) && pr.Step[e] >= 0.0)))
      ? 0
      : 1;
  };
  if (!edges.IsGrid() && !same && !edges.ForEachUntil(checkEdge, [&](double t) { return progress(0.5 * t); }))
  {
    aborted = true;
    return std::string();
  }
  for (const auto* samples : { &pr.ObjectSamples, &pr.BackgroundSamples })
  {
    for (double v : *samples)
    {
      badValue += Usable(v) ? 0 : 1;
    }
  }
  if (badValue)
  {
    return UnusableIntensities(badValue);
  }
  if (badSize)
  {
    return std::to_string(badSize) + " node sizes (voxel counts) are negative or not finite.";
  }
  if (badEdge)
  {
    return std::to_string(badEdge) + " graph edges name missing nodes or have a negative or non-finite contact or length.";
  }
  return std::string();
}

// The histogram's bins as the cut defines them, bin(v) = int((v - low) / width) clamped to
// [0, count), with the smallest value of each bin found once (exactly: a binary search over the
// doubles, in their order), so that sorted values split into runs by comparisons alone.
class HistogramBins
{
public:
  HistogramBins(int count, double low, double width)
    : Count(count)
    , Low(low)
    , Width(width)
    , Start(static_cast<std::size_t>(count) + 1)
  {
    // Doubles as unsigned keys in their numeric order.
    auto key = [](double d) {
      std::uint64_t u;
      std::memcpy(&u, &d, sizeof u);
      return (u >> 63) ? ~u : (u | (std::uint64_t(1) << 63));
    };
    auto value = [](std::uint64_t k) {
      const std::uint64_t u = (k >> 63) ? (k & ~(std::uint64_t(1) << 63)) : ~k;
      double d;
      std::memcpy(&d, &u, sizeof d);
      return d;
    };
    this->Start[0] = -std::numeric_limits<double>::infinity();
    this->Start[count] = std::numeric_limits<double>::infinity();
    // bin() is monotone in v (each IEEE step is), so {v : bin(v) >= b} starts at one double,
    // between low - width and low + (count + 1) width.
    const std::uint64_t first = key(low - width), last = key(low + (count + 1) * width);
    for (int b = 1; b < count; ++b)
    {
      std::uint64_t lo = first, hi = last;
      while (lo < hi)
      {
        const std::uint64_t mid = lo + (hi - lo) / 2;
        if ((*this)(value(mid)) >= b)
        {
          hi = mid;
        }
        else
        {
          lo = mid + 1;
        }
      }
      this->Start[b] = value(lo);
    }
  }
  // ValueBins' rule: an outlier far beyond the range must not overflow the int, which would put it
  // in bin 0 and stall the runs above.
  int operator()(double v) const { return ValueBins{ this->Count, this->Low, this->Width }(v); }
  // The smallest value of bin b (b in [0, Size()]; -inf and +inf at the ends).
  double First(int b) const { return this->Start[b]; }

private:
  int Count;
  double Low, Width;
  std::vector<double> Start;
};

// The runs of one bin in sorted values: a node within one bin costs a division and a comparison,
// one spanning several a binary search of comparisons per bin. f(bin, count), bins ascending.
template <typename Stored, typename RunFunction>
void ForEachRun(const Stored* x, const Stored* end, const HistogramBins& bins, const RunFunction& f)
{
  while (x < end)
  {
    const int b = bins(*x);
    const double nextBin = bins.First(b + 1);
    const Stored* next = static_cast<double>(end[-1]) < nextBin
      ? end
      : std::partition_point(x, end, [&](Stored y) { return static_cast<double>(y) < nextBin; });
    constexpr std::int64_t longest = std::numeric_limits<std::uint32_t>::max();
    for (std::int64_t left = next - x; left > 0; left -= longest)
    {
      f(b, static_cast<std::uint32_t>(std::min(left, longest)));
    }
    x = next;
  }
}

// Every node's sorted voxel values as bin runs, in two passes over them (count, then write). False
// when progress asked to abort.
bool BinSortedVoxels(const NodeVoxelValues& voxels, const HistogramBins& bins, MaxFlowCache::BinnedVoxels& binned,
  const ParallelFor& parallel, const ProgressFunction& progress)
{
  const std::int64_t n = static_cast<std::int64_t>(voxels.Offset.size()) - 1;
  std::vector<std::int64_t>& offset = binned.Offset;
  AssignFresh(offset, static_cast<std::size_t>(n + 1), std::int64_t(0));
  return voxels.Visit([&](const auto* all) {
    auto runs = [&](std::int64_t p, const auto& f) {
      ForEachRun(all + voxels.Offset[p], all + voxels.Offset[p + 1], bins, f);
    };
    if (!BatchedFor(n, 8192, parallel, SubProgress(progress, 0.0, 0.5), [&](std::int64_t first, std::int64_t last) {
          for (std::int64_t p = first; p < last; ++p)
          {
            runs(p, [&](int, std::uint32_t) { ++offset[p + 1]; });
          }
        }))
    {
      return false;
    }
    std::partial_sum(offset.begin(), offset.end(), offset.begin());
    AssignFresh(binned.Bin, static_cast<std::size_t>(offset[n]));
    AssignFresh(binned.Count, static_cast<std::size_t>(offset[n]));
    return BatchedFor(n, 8192, parallel, SubProgress(progress, 0.5, 1.0), [&](std::int64_t first, std::int64_t last) {
      for (std::int64_t p = first; p < last; ++p)
      {
        std::int64_t k = offset[p];
        runs(p, [&](int b, std::uint32_t count) {
          binned.Bin[k] = static_cast<std::uint16_t>(b);
          binned.Count[k++] = count;
        });
      }
    });
  });
}

// Every node's voxels as runs of one bin: a run for every bin between those of its smallest and
// largest value (some may hold no voxel: they add +0 to a sum), counted in one pass over the voxels
// in NodeVoxelValues' chunks. A node only one chunk holds is counted without an atomic; the counts are
// integers, so any split among threads gives the same runs. False when progress asked to abort.
bool BinBoundedVoxels(const NodeVoxelValues& voxels, const HistogramBins& bin, MaxFlowCache::BinnedVoxels& binned,
  const ParallelFor& parallel, const ProgressFunction& progress)
{
  const std::int64_t n = voxels.Nodes;
  std::vector<std::int64_t>& offset = binned.Offset;
  AssignFresh(offset, static_cast<std::size_t>(n + 1), std::int64_t(0));
  // Voxel v of node p counts at base[p] + bin(value): node p's runs are its bins from bin(Min[p]).
  std::vector<std::int64_t> base(static_cast<std::size_t>(n));
  for (std::int64_t p = 0; p < n; ++p)
  {
    const bool any = voxels.Min[p] <= voxels.Max[p];
    const int first = any ? bin(voxels.Min[p]) : 0;
    base[p] = offset[p] - first;
    offset[p + 1] = offset[p] + (any ? bin(voxels.Max[p]) - first + 1 : 0);
  }
  AssignFresh(binned.Bin, static_cast<std::size_t>(offset[n]));
  AssignFresh(binned.Count, static_cast<std::size_t>(offset[n]), std::uint32_t(0));
  parallel(n, 65536, [&](std::int64_t p0, std::int64_t p1) {
    for (std::int64_t p = p0; p < p1; ++p)
    {
      for (std::int64_t k = offset[p]; k < offset[p + 1]; ++k)
      {
        binned.Bin[k] = static_cast<std::uint16_t>(k - base[p]);
      }
    }
  });
  if (!progress(0.2))
  {
    return false;
  }
  const std::int32_t* owner = voxels.Owner;
  const std::uint8_t* shared = voxels.Shared.data();
  std::uint32_t* count = binned.Count.data();
  constexpr std::int64_t chunks = NodeVoxelValues::Chunks;
  const std::int64_t size = (voxels.Voxels + chunks - 1) / chunks;
  VisitVoxelValues(voxels, [&](const auto* values) {
    parallel(chunks, 1, [&](std::int64_t c0, std::int64_t c1) {
      for (std::int64_t c = c0; c < c1; ++c)
      {
        for (std::int64_t v = c * size, e = std::min(voxels.Voxels, (c + 1) * size); v < e; ++v)
        {
          const std::int32_t p = owner[v];
          if (p >= 0)
          {
            std::uint32_t* k = count + base[p] + bin(static_cast<double>(values[v]));
            if (shared[p])
            {
              __atomic_fetch_add(k, 1u, __ATOMIC_RELAXED);
            }
            else
            {
              ++*k;
            }
          }
        }
      }
    });
  });
  return progress(1.0);
}
// Reports progress at step i of count (begin..end) every CheckEvery + 1 steps; false once abort is asked.
bool KeepGoing(const ProgressFunction& progress, std::int64_t i, std::int64_t count, double begin, double end)
{
  return (i & CheckEvery) != CheckEvery ||
    progress(begin + (end - begin) * static_cast<double>(i) / static_cast<double>(count));
}

// Step 1: the histogram's bins on a lattice the image alone fixes: `base` bins (Bins, or
// AutomaticBins) over the values' robust range, their 0.5 and 99.5 percentiles (the exact voxels'
// when the nodes carry them), and `base` more of that width on each side. The histogram takes the
// lattice's bins from the lowest to the highest seed sample's, and at least the robust range's;
// beyond the lattice a sample counts in its end bin, as a node's value does. A seed edit then moves
// only which bins the histogram spans, not their edges, so a re-cut keeps its nodes' voxels binned.
struct HistogramLattice
{
  double Low = 0.0, Width = 1.0; // lattice bin j starts at Low + j Width
  int Size = 0;                  // 3 base
  int First = 0, Bins = 0;       // the histogram's bins: lattice bins [First, First + Bins)
  double HistogramLow() const { return this->Low + this->First * this->Width; }
  double HistogramHigh() const { return this->Low + (this->First + this->Bins) * this->Width; }
};
HistogramLattice MakeHistogramLattice(const CutProblem& pr, const BoykovJollyParameters& par)
{
  const std::int64_t n = static_cast<std::int64_t>(pr.Value.size());
  const NodeVoxelValues* exact = pr.NodeVoxels;
  const std::array<double, 2> range =
    exact ? std::array<double, 2>{ { exact->Low, exact->High } } : HistogramRange(pr.Value.data(), n);
  const double low = range[0], high = range[1];
  const int base = par.Bins > 0
    ? par.Bins
    : AutomaticBins({ { &pr.ObjectSamples, &pr.ObjectWeights }, { &pr.BackgroundSamples, &pr.BackgroundWeights } }, low,
        high, par.Bandwidth);
  HistogramLattice lattice;
  lattice.Width = (high - low) / base;
  lattice.Low = low - base * lattice.Width;
  lattice.Size = 3 * base;
  double sampleLow = low, sampleHigh = high;
  for (const std::vector<double>* samples : { &pr.ObjectSamples, &pr.BackgroundSamples })
  {
    for (double v : *samples)
    {
      sampleLow = std::min(sampleLow, v);
      sampleHigh = std::max(sampleHigh, v);
    }
  }
  const int below = static_cast<int>(std::min<double>(base, std::ceil((low - sampleLow) / lattice.Width)));
  const int above = static_cast<int>(std::min<double>(base, std::ceil((sampleHigh - high) / lattice.Width)));
  lattice.First = base - below;
  lattice.Bins = base + below + above;
  return lattice;
}

// Step 2: each label's cost -ln Pr(bin | label) per lattice bin, from its seeds' smoothed histogram
// (a lattice bin beyond the histogram takes its end bin's).
struct BinCosts
{
  std::vector<double> Object, Background;
};
BinCosts LabelBinCosts(const CutProblem& pr, const HistogramLattice& lattice, double bandwidth, double& overlap)
{
  const double low = lattice.HistogramLow(), high = lattice.HistogramHigh();
  const std::vector<double> pObject = SmoothedHistogram(pr.ObjectSamples, pr.ObjectWeights, low, high, lattice.Bins, bandwidth);
  const std::vector<double> pBackground =
    SmoothedHistogram(pr.BackgroundSamples, pr.BackgroundWeights, low, high, lattice.Bins, bandwidth);
  BinCosts costs{ std::vector<double>(lattice.Size), std::vector<double>(lattice.Size) };
  overlap = 0.0;
  for (int b = 0; b < lattice.Bins; ++b)
  {
    overlap += std::sqrt(pObject[b] * pBackground[b]);
  }
  for (int j = 0; j < lattice.Size; ++j)
  {
    const int b = std::min(lattice.Bins - 1, std::max(0, j - lattice.First));
    costs.Object[j] = -std::log(pObject[b]);
    costs.Background[j] = -std::log(pBackground[b]);
  }
  return costs;
}

// Step 3: the boundary weights w = contact x exp(-d^2 / 2 sigma^2), sigma the RMS neighbour
// difference when not given, and 1 + their sum (the start of K). False when progress asked to abort.
struct BoundaryTerm
{
  double Sigma = 0.0, Total = 1.0;
  std::unique_ptr<double[]> Weight;
};
bool BoundaryWeights(const CutProblem& pr, double sigma, BoundaryTerm& out, const ProgressFunction& progress)
{
  const GraphEdges& edges = pr.Edges;
  const std::int64_t m = edges.Size();
  out.Sigma = sigma;
  if (out.Sigma <= 0.0)
  {
    double ss = 0.0;
    edges.ForEach([&](std::int64_t, std::int64_t a, std::int64_t b) {
      const double d = pr.Value[a] - pr.Value[b];
      ss += d * d;
    });
    out.Sigma = m ? std::sqrt(ss / static_cast<double>(m)) : 1.0;
    if (!(out.Sigma > 0.0))
    {
      out.Sigma = 1.0;
    }
  }
  const double inv2s2 = 1.0 / (2.0 * out.Sigma * out.Sigma);
  if (!progress(0.0))
  {
    return false;
  }
  // Not zero-filled: its pages are first touched in the loop below, which reports progress. The
  // exponentials run on pr.Parallel; the sum stays in edge order (the same total for any split).
  out.Weight.reset(new double[m]);
  double* weight = out.Weight.get();
  if (!BatchedFor(edges.Blocks(), 1, pr.Parallel, progress, [&](std::int64_t first, std::int64_t last) {
        edges.ForEach(first, last, [&](std::int64_t e, std::int64_t a, std::int64_t b) {
          const double d = pr.Value[a] - pr.Value[b];
          // Equal neighbours have weight 1 whatever sigma (a tiny sigma would give 0 * inf).
          const double contact = pr.Contact.empty() ? 1.0 : pr.Contact[e];
          weight[e] = contact * (d == 0.0 ? 1.0 : std::exp(-d * d * inv2s2));
        });
      }))
  {
    return false;
  }
  out.Total = 1.0;
  for (std::int64_t e = 0; e < m; ++e)
  {
    out.Total += weight[e];
  }
  return true;
}

// Step 4 for exact super-voxels: each node's region costs summed over its voxels' bins. The bins
// move only when the bin count does. Sorted values are summed straight from
// the values for a binning seen for the first time, and kept as runs once it repeats; bounded ones
// are binned at once (a pass over the voxels), and the runs kept. False when progress asked to abort.
bool ExactRegionCosts(const CutProblem& pr, const HistogramBins& bin, const BinCosts& costs, double low, double width,
  std::shared_ptr<MaxFlowCache::BinnedVoxels>* kept, double* regionObject, double* regionBackground,
  const ProgressFunction& progress)
{
  const NodeVoxelValues* exact = pr.NodeVoxels;
  const std::int64_t n = static_cast<std::int64_t>(pr.Value.size());
  const int bins = static_cast<int>(costs.Object.size());
  std::shared_ptr<MaxFlowCache::BinnedVoxels> binned = kept ? *kept : nullptr;
  const bool repeated = binned && binned->Matches(exact, bins, low, width);
  if (!repeated)
  {
    if (kept)
    {
      kept->reset(); // the old runs' memory goes before the new runs are made
    }
    binned = std::make_shared<MaxFlowCache::BinnedVoxels>();
    binned->From = exact;
    binned->Nodes = exact->Nodes;
    binned->Bins = bins;
    binned->Low = low;
    binned->Width = width;
    if (kept)
    {
      *kept = binned;
    }
  }
  if (binned->Empty() && (repeated || !exact->Sorted()) &&
    !(exact->Sorted() ? BinSortedVoxels(*exact, bin, *binned, pr.Parallel, SubProgress(progress, 0.0, 0.8))
                      : BinBoundedVoxels(*exact, bin, *binned, pr.Parallel, SubProgress(progress, 0.0, 0.8))))
  {
    if (kept)
    {
      kept->reset();
    }
    return false;
  }
  return !binned->Empty()
    ? BatchedFor(n, 16384, pr.Parallel, SubProgress(progress, 0.8, 1.0),
        [&](std::int64_t first, std::int64_t last) {
          for (std::int64_t p = first; p < last; ++p)
          {
            double sumObject = 0.0, sumBackground = 0.0;
            for (std::int64_t k = binned->Offset[p]; k < binned->Offset[p + 1]; ++k)
            {
              const double count = static_cast<double>(binned->Count[k]);
              sumObject += count * costs.Object[binned->Bin[k]];
              sumBackground += count * costs.Background[binned->Bin[k]];
            }
            regionObject[p] = sumObject;
            regionBackground[p] = sumBackground;
          }
        })
    : exact->Visit([&](const auto* all) {
        return BatchedFor(n, 8192, pr.Parallel, progress, [&](std::int64_t first, std::int64_t last) {
          for (std::int64_t p = first; p < last; ++p)
          {
            double sumObject = 0.0, sumBackground = 0.0;
            ForEachRun(all + exact->Offset[p], all + exact->Offset[p + 1], bin, [&](int b, std::uint32_t count) {
              sumObject += static_cast<double>(count) * costs.Object[b];
              sumBackground += static_cast<double>(count) * costs.Background[b];
            });
            regionObject[p] = sumObject;
            regionBackground[p] = sumBackground;
          }
        });
      });
}

// Step 4: the region costs of each node, object and background (before lambda): its voxels' sum
// (exact super-voxels) or its size times its value's bin cost. False when progress asked to abort.
bool RegionCosts(const CutProblem& pr, const HistogramBins& bin, const BinCosts& costs, double low, double width,
  std::shared_ptr<MaxFlowCache::BinnedVoxels>* kept, double* regionObject, double* regionBackground,
  const ProgressFunction& progress)
{
  if (pr.NodeVoxels)
  {
    return ExactRegionCosts(pr, bin, costs, low, width, kept, regionObject, regionBackground, progress);
  }
  const std::int64_t n = static_cast<std::int64_t>(pr.Value.size());
  for (std::int64_t p = 0; p < n; ++p)
  {
    const int b = bin(pr.Value[p]);
    const double size = pr.Size.empty() ? 1.0 : pr.Size[p];
    regionObject[p] = size * costs.Object[b];
    regionBackground[p] = size * costs.Background[b];
    if (!KeepGoing(progress, p, n, 0.0, 1.0))
    {
      return false;
    }
  }
  return true;
}

// Step 5: the seeds' spatial term per voxel of each node (empty when its weight is 0); it moves
// terminal capacities only, so a kept flow still applies. False when progress asked to abort.
bool SeedGeodesicTerm(const CutProblem& pr, double range, SeedGeodesicCache* kept, SharedArray<double>& spatialObject,
  SharedArray<double>& spatialBackground, const ProgressFunction& progress, double& seconds)
{
  if (!(pr.Geodesic.Weight > 0.0))
  {
    return true;
  }
  const auto t0 = Clock::now();
  GeodesicGraph graph;
  graph.Edges = &pr.Edges;
  graph.Value = pr.Value;
  graph.Step = pr.Step;
  if (!SeedGeodesicCosts(graph, pr.Hard, range, pr.Geodesic, pr.Parallel, spatialObject, spatialBackground, progress, kept))
  {
    return false;
  }
  seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return true;
}

// Step 6 on a kept flow (Kohli-Torr): the residual graph takes the capacity changes as signed
// terminal residuals; only nodes whose residual changes sign (or zero status) need their search
// trees redone.
template <typename Source, typename Sink>
void UpdateTerminals(Flow& g, const MaxFlowCache::Kept& kept, std::int64_t n, const Source& source, const Sink& sink)
{
  for (std::int64_t p = 0; p < n; ++p)
  {
    const double ds = source(p) - kept.Source[p], dt = sink(p) - kept.Sink[p];
    if (ds != 0.0 || dt != 0.0)
    {
      const double before = g.get_trcap(static_cast<int>(p));
      g.add_tweights(static_cast<int>(p), ds, dt);
      const double after = g.get_trcap(static_cast<int>(p));
      if ((before > 0) != (after > 0) || (before < 0) != (after < 0))
      {
        g.mark_node(static_cast<int>(p));
      }
    }
  }
}

// Step 6: a new max-flow graph, its nodes' terminal capacities and its edges' weights. Null when
// progress asked to abort; throws when memory runs out.
template <typename Source, typename Sink>
std::shared_ptr<Flow> NewFlowGraph(const GraphEdges& edges, const double* weight, std::int64_t n, const Source& source,
  const Sink& sink, const ProgressFunction& progress)
{
  auto g = std::make_shared<Flow>(static_cast<int>(n), static_cast<int>(edges.Size()), ThrowOutOfMemory);
  // Nodes in chunks (the same ids as one call): first touching a 9 M-voxel graph's memory takes
  // seconds, and progress must keep coming.
  constexpr std::int64_t chunk = std::int64_t(1) << 20;
  for (std::int64_t p = 0; p < n; p += chunk)
  {
    g->add_node(static_cast<int>(std::min(chunk, n - p)));
    if (!progress(0.3 * static_cast<double>(p) / static_cast<double>(n)))
    {
      return nullptr;
    }
  }
  for (std::int64_t p = 0; p < n; ++p)
  {
    if (!KeepGoing(progress, p, n, 0.3, 0.6))
    {
      return nullptr;
    }
    g->add_tweights(static_cast<int>(p), source(p), sink(p));
  }
  const bool done = edges.ForEachUntil(
    [&](std::int64_t e, std::int64_t a, std::int64_t b) {
      g->add_edge(static_cast<int>(a), static_cast<int>(b), weight[e], weight[e]);
    },
    [&](double t) { return progress(0.6 + 0.4 * t); });
  return done ? g : nullptr;
}
// Step 7: the max-flow and each node's side (1 source = object). It has no progress or abort of its
// own: it runs on its own thread, owning the graph. False when progress asked to abort.
bool MaxFlow(const std::shared_ptr<Flow>& g, std::int64_t n, bool reuse, const ProgressFunction& progress,
  std::pair<double, std::vector<std::uint8_t>>& flow)
{
  using FlowResult = std::pair<double, std::vector<std::uint8_t>>;
  return RunWithHeartbeat<FlowResult>(
    [g, n, reuse]() {
      FlowResult f;
      f.first = g->maxflow(reuse);
      f.second.resize(n);
      for (std::int64_t p = 0; p < n; ++p)
      {
        f.second[p] = g->what_segment(static_cast<int>(p)) == Flow::SOURCE ? 1 : 0;
      }
      return f;
    },
    progress, flow);
}

// Step 8: a new record of the graph a re-cut may reuse. Held edge lists are kept as they are, lists
// only viewed are copied; the weights live in the graph's capacities only.
std::shared_ptr<MaxFlowCache::Kept> NewKept(const CutProblem& pr, double sigmaParameter, double sigma, double weightTotal)
{
  auto kept = std::make_shared<MaxFlowCache::Kept>();
  kept->Edges = pr.Edges.Keepable();
  kept->Value = pr.Value;
  kept->Contact = pr.Contact;
  kept->SigmaParameter = sigmaParameter;
  kept->Sigma = sigma;
  kept->WeightTotal = weightTotal;
  return kept;
}
// Step 5b: the spatial term (per voxel, when there is one) times spatialScale added to both region
// costs, lambda times their sums, and K's share of them (the larger per node) added to `total`, in
// one pass.
// False when progress asked to abort.
bool ScaleRegionCosts(const CutProblem& pr, const SharedArray<double>& spatialObject,
  const SharedArray<double>& spatialBackground, double lambda, std::int64_t n, double* regionObject,
  double* regionBackground, double& total, const ProgressFunction& progress, double spatialScale)
{
  const bool spatial = !spatialObject.empty(), reach = !pr.Reach.empty();
  for (std::int64_t p = 0; p < n; ++p)
  {
    const double size = pr.Size.empty() ? 1.0 : pr.Size[p];
    if (spatial)
    {
      regionObject[p] += spatialScale * size * spatialObject[p];
      regionBackground[p] += spatialScale * size * spatialBackground[p];
    }
    if (reach)
    {
      // Not scaled by the seeds' overlap: where the object lies does not follow how it looks.
      regionObject[p] += size * pr.Reach[p];
    }
    regionObject[p] *= lambda;
    regionBackground[p] *= lambda;
    total += std::max(regionObject[p], regionBackground[p]);
    if (!KeepGoing(progress, p, n, 0.0, 1.0))
    {
      return false;
    }
  }
  return true;
}
} // namespace

CutResult BoykovJollyCut(const CutProblem& pr, const BoykovJollyParameters& par, const ProgressFunction& progress,
  MaxFlowCache* cache)
{
  CutResult r;
  const auto t0 = Clock::now();
  const std::int64_t n = static_cast<std::int64_t>(pr.Value.size());
  const GraphEdges& edges = pr.Edges;
  const std::int64_t m = edges.Size();
  r.Error = ValidateProblem(pr, SubProgress(progress, 0.0, 0.05), r.Aborted, cache ? cache->State.get() : nullptr);
  if (!r.Error.empty() || r.Aborted)
  {
    return r;
  }
  // A phase that returns false was aborted.
  auto aborted = [&](bool goOn) {
    r.Aborted = !goOn;
    return r.Aborted;
  };
  if (aborted(progress(0.05)))
  {
    return r;
  }
  // 1-2. The histogram and each label's cost per bin.
  const HistogramLattice lattice = MakeHistogramLattice(pr, par);
  r.Bins = lattice.Bins;
  const BinCosts costs = LabelBinCosts(pr, lattice, par.Bandwidth, r.SeedOverlap);
  // The spatial term's costs are kept at Geodesic.Weight; the adaptive weight scales them as they join.
  if (pr.Geodesic.Adaptive)
  {
    r.SpatialScale = r.SeedOverlap / SeedOverlapReference;
  }
  const double low = lattice.Low, width = lattice.Width;
  const HistogramBins bin(lattice.Size, low, width);

  // 3. The boundary term depends on the graph alone: a kept flow of this very graph holds its
  // weights in its residual graph (below).
  std::shared_ptr<MaxFlowCache::Kept> kept = cache ? cache->State : nullptr;
  const bool reuse = kept && kept->SigmaParameter == par.Sigma && kept->Edges.Same(edges) && kept->Value == pr.Value &&
    kept->Contact == pr.Contact;
  BoundaryTerm boundary;
  if (reuse)
  {
    boundary.Sigma = kept->Sigma;
    boundary.Total = kept->WeightTotal;
  }
  else if (aborted(progress(0.1)) || aborted(BoundaryWeights(pr, par.Sigma, boundary, SubProgress(progress, 0.1, 0.2))))
  {
    return r;
  }
  r.Sigma = boundary.Sigma;
  double total = boundary.Total;
  if (aborted(progress(0.2)))
  {
    return r;
  }
  // 4-5. Region costs of each node: labelled object it pays regionObject, labelled background
  // regionBackground. Not zero-filled unless summed into: a 9 M-voxel graph's pages are first
  // touched in loops that report progress.
  std::unique_ptr<double[]> regionObject(new double[n]), regionBackground(new double[n]);
  AdviseHugePages(regionObject.get(), n * sizeof(double));
  AdviseHugePages(regionBackground.get(), n * sizeof(double));
  SharedArray<double> spatialObject, spatialBackground;
  if (aborted(RegionCosts(pr, bin, costs, low, width, cache ? &cache->Binned : nullptr, regionObject.get(),
        regionBackground.get(), SubProgress(progress, 0.2, 0.3))) ||
    aborted(SeedGeodesicTerm(pr, lattice.HistogramHigh() - lattice.HistogramLow(), cache ? &cache->Geodesic : nullptr,
      spatialObject, spatialBackground, SubProgress(progress, 0.3, 0.33), r.GeodesicSeconds)) ||
    aborted(ScaleRegionCosts(pr, spatialObject, spatialBackground, par.Lambda, n, regionObject.get(), regionBackground.get(),
      total, SubProgress(progress, 0.33, 0.35), r.SpatialScale)) ||
    aborted(progress(0.35)))
  {
    return r;
  }
  r.SpatialWeight = spatialObject.empty() ? 0.0 : pr.Geodesic.Weight * r.SpatialScale;
  // K exceeds the energy of any labelling, so hard constraints are never cut.
  const double K = total;
  if (!std::isfinite(K))
  {
    r.Error = "the energy overflows (lambda, the contact areas or the graph are too large); lower lambda.";
    return r;
  }
  // 6. Terminal capacities (source = object: a node left on the source side pays its sink
  // capacity), in place of the region costs they are made of, then on the kept flow when only they
  // changed, else on a new graph. A seed's are K to its own side and 0 to the other.
  double* const sourceCapacity = regionBackground.get();
  double* const sinkCapacity = regionObject.get();
  for (std::int64_t p = 0; p < n; ++p)
  {
    if (pr.Hard[p] == 1 || pr.Hard[p] == 2)
    {
      sourceCapacity[p] = pr.Hard[p] == 1 ? K : 0.0;
      sinkCapacity[p] = pr.Hard[p] == 2 ? K : 0.0;
    }
  }
  auto source = [sourceCapacity](std::int64_t p) { return sourceCapacity[p]; };
  auto sink = [sinkCapacity](std::int64_t p) { return sinkCapacity[p]; };
  if (cache)
  {
    cache->State.reset(); // until this cut's flow has finished
  }
  std::shared_ptr<Flow> g;
  try
  {
    g = reuse ? kept->Graph : NewFlowGraph(edges, boundary.Weight.get(), n, source, sink, SubProgress(progress, 0.35, 0.5));
    boundary.Weight.reset(); // in the graph's capacities now
    if (aborted(g != nullptr))
    {
      return r;
    }
    if (reuse)
    {
      UpdateTerminals(*g, *kept, n, source, sink);
    }
  }
  catch (const std::exception&)
  {
    r.Error = "not enough memory for the max-flow graph (" + std::to_string(n) + " nodes, " + std::to_string(m) + " edges).";
    return r;
  }
  const auto t1 = Clock::now();
  r.GraphSeconds = std::chrono::duration<double>(t1 - t0).count();
  // 7. The max-flow, on its own thread.
  std::pair<double, std::vector<std::uint8_t>> flow;
  try
  {
    if (aborted(MaxFlow(g, n, reuse, SubProgress(progress, 0.5, 1.0), flow)))
    {
      return r;
    }
  }
  catch (const std::exception&)
  {
    r.Error = "not enough memory for the max-flow (" + std::to_string(n) + " nodes, " + std::to_string(m) + " edges).";
    return r;
  }
  r.Flow = flow.first;
  r.Label = std::move(flow.second);
  r.ValueBin = ValueBins{ lattice.Size, low, width };
  r.BinCostObject = costs.Object;
  r.BinCostBackground = costs.Background;
  r.SpatialObject = spatialObject;
  r.SpatialBackground = spatialBackground;
  r.Reach = pr.Reach;
  // 8. What a re-cut with other seeds reuses: the graph, its weights and its capacities.
  if (cache)
  {
    if (!reuse)
    {
      kept = NewKept(pr, par.Sigma, r.Sigma, total);
    }
    kept->Size = pr.Size;
    kept->Step = pr.Step;
    kept->Graph = g;
    kept->Source = std::move(regionBackground);
    kept->Sink = std::move(regionObject);
    cache->State = kept;
  }
  r.FlowSeconds = std::chrono::duration<double>(Clock::now() - t1).count();
  // Hard constraints hold by construction; a non-finite energy would break them silently.
  for (std::int64_t p = 0; p < n; ++p)
  {
    if ((pr.Hard[p] == 1 && r.Label[p] != 1) || (pr.Hard[p] == 2 && r.Label[p] != 0) || !std::isfinite(r.Flow))
    {
      r.Label.clear();
      r.Error = "the max-flow did not honour the seeds (a non-finite energy); please report this input.";
      return r;
    }
  }
  return r;
}
} // namespace featuremesh
