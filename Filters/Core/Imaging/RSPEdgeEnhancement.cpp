#include "RSPEdgeEnhancement.h"
#include "Memory.h"

#include "ImageFilters.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <queue>
#include <random>
#include <thread>
#include <unordered_set>

namespace featuremesh
{
namespace
{
using Clock = std::chrono::steady_clock;
double SecondsSince(Clock::time_point t0)
{
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

constexpr float Infinity = std::numeric_limits<float>::infinity();

// Step lengths of the three axes in units of the smallest spacing (1 along a one-voxel axis).
std::array<double, 3> AxisSteps(const ImageGeometry& g)
{
  const double h = g.FinestSpacing();
  std::array<double, 3> s{ { 1, 1, 1 } };
  for (int a = 0; a < g.Dimension(); ++a)
  {
    s[a] = std::fabs(g.Spacing[a]) / h;
  }
  return s;
}

// The grey-level range that maps to 255: 1st to 99th percentile of at most ~1 M voxels taken at a
// fixed stride (the full range when those agree, 0 for a constant image).
double RobustRange(const float* v, std::int64_t n)
{
  const std::int64_t stride = std::max<std::int64_t>(1, n / (1 << 20));
  std::vector<float> s;
  s.reserve(static_cast<std::size_t>(n / stride + 1));
  for (std::int64_t i = 0; i < n; i += stride)
  {
    s.push_back(v[i]);
  }
  const auto at = [&](double q) {
    auto it = s.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(s.size() - 1));
    std::nth_element(s.begin(), it, s.end());
    return static_cast<double>(*it);
  };
  double range = at(0.99) - at(0.01);
  if (!(range > 0.0))
  {
    const auto mm = std::minmax_element(v, v + n);
    range = static_cast<double>(*mm.second) - static_cast<double>(*mm.first);
  }
  return range;
}

// Neighbour offsets of the 4- (2D) or 6-connected grid: axis a, direction +/-.
struct Grid
{
  std::array<int, 3> Dims;
  ImageGeometry Frame; // the dimensions only, for Coordinates
  int Directions; // 4 or 6
  std::array<std::int64_t, 6> Offset;
  explicit Grid(const std::array<int, 3>& dims)
    : Dims(dims)
  {
    Frame.Dims = dims;
    Directions = dims[2] == 1 ? 4 : 6;
    const std::int64_t sy = dims[0], sz = static_cast<std::int64_t>(dims[0]) * dims[1];
    Offset = { { 1, -1, sy, -sy, sz, -sz } };
  }
  // Whether voxel ijk has a neighbour in direction d.
  bool Inside(const std::array<int, 3>& ijk, int d) const
  {
    const int a = d / 2, c = ijk[a] + ((d & 1) ? -1 : 1);
    return c >= 0 && c < Dims[a];
  }
  std::array<int, 3> Coordinates(std::int64_t v) const { return Frame.Coordinates(v); }
};

using HeapEntry = std::pair<double, std::int64_t>;
using MinHeap = std::priority_queue<HeapEntry, std::vector<HeapEntry>, std::greater<HeapEntry>>;
} // namespace

std::string ValidateParameters(const RSPParameters& p)
{
  if (!(p.GradientScale >= 0.0) || !std::isfinite(p.GradientScale))
  {
    return "GradientScale must be zero or positive.";
  }
  if (!(p.GradientSigma >= 0.0) || p.GradientSigma > 20.0)
  {
    return "GradientSigma must lie in [0, 20] voxels.";
  }
  if (p.Sources < 1 || p.Sinks < 1 || p.Sources > 10000 || p.Sinks > 10000)
  {
    return "the numbers of sources and sinks must lie in [1, 10000].";
  }
  if (!(p.SamplingThreshold >= 0.0) || !std::isfinite(p.SamplingThreshold))
  {
    return "SamplingThreshold must be zero (automatic) or positive.";
  }
  if (p.MaximumPathVoxels < 0)
  {
    return "MaximumPathVoxels must be zero (never coarsen) or positive.";
  }
  if (p.PathMargin < 0)
  {
    return "PathMargin must be zero or positive.";
  }
  if (!(p.EdgeThreshold >= 0.0 && p.EdgeThreshold <= 1.0))
  {
    return "EdgeThreshold must lie in [0, 1] (a fraction of the paths).";
  }
  if (!(p.GapCost >= 1.0) || !std::isfinite(p.GapCost))
  {
    return "GapCost must be at least 1.";
  }
  return {};
}

std::vector<float> FastMarching(const float* slowness, const ImageGeometry& g, const std::vector<std::int64_t>& seeds,
  double stopAt, const std::vector<std::int64_t>* medianOf, double* median, const ProgressFunction& progress)
{
  const std::int64_t n = g.Size();
  const Grid grid(g.Dims);
  const std::array<double, 3> h = AxisSteps(g);
  std::vector<double> T;
  std::vector<std::uint8_t> known;
  AssignFresh(T, static_cast<std::size_t>(n), std::numeric_limits<double>::infinity());
  AssignFresh(known, static_cast<std::size_t>(n), std::uint8_t(0));
  std::vector<std::int64_t> targets;
  if (medianOf && median && stopAt <= 0.0)
  {
    targets = *medianOf;
    std::sort(targets.begin(), targets.end());
    targets.erase(std::unique(targets.begin(), targets.end()), targets.end());
  }
  const std::size_t needed = (targets.size() + 1) / 2;
  std::size_t reached = 0;
  std::int64_t settled = 0;
  MinHeap heap;
  for (std::int64_t s : seeds)
  {
    T[s] = 0.0;
    heap.emplace(0.0, s);
  }
  while (!heap.empty())
  {
    const HeapEntry top = heap.top();
    heap.pop();
    const std::int64_t v = top.second;
    if (known[v] || top.first != T[v])
    {
      continue;
    }
    if (stopAt > 0.0 && top.first > stopAt)
    {
      break;
    }
    known[v] = 1;
    if ((++settled & 0xFFFF) == 0 && !progress(static_cast<double>(settled) / static_cast<double>(n)))
    {
      return {};
    }
    if (reached < needed && std::binary_search(targets.begin(), targets.end(), v) && ++reached == needed)
    {
      *median = top.first;
      stopAt = std::max(top.first, std::numeric_limits<double>::min());
    }
    const std::array<int, 3> c = grid.Coordinates(v);
    for (int d = 0; d < grid.Directions; ++d)
    {
      if (!grid.Inside(c, d))
      {
        continue;
      }
      const std::int64_t q = v + grid.Offset[d];
      if (known[q])
      {
        continue;
      }
      // Upwind neighbours of q per axis, then the first-order update from the smallest ones.
      const std::array<int, 3> cq = grid.Coordinates(q);
      std::array<std::pair<double, double>, 3> u; // (value, step)
      int m = 0;
      for (int a = 0; a < grid.Directions / 2; ++a)
      {
        double best = std::numeric_limits<double>::infinity();
        for (int d2 = 2 * a; d2 < 2 * a + 2; ++d2)
        {
          if (grid.Inside(cq, d2))
          {
            const std::int64_t r = q + grid.Offset[d2];
            if (known[r])
            {
              best = std::min(best, T[r]);
            }
          }
        }
        if (best < std::numeric_limits<double>::infinity())
        {
          u[m++] = { best, h[a] };
        }
      }
      std::sort(u.begin(), u.begin() + m);
      const double f = slowness[q];
      double A = 0, B = 0, C = -f * f, t = u[0].first + f * u[0].second;
      for (int k = 0; k < m; ++k)
      {
        if (k > 0 && t <= u[k].first)
        {
          break;
        }
        const double w = 1.0 / (u[k].second * u[k].second);
        A += w;
        B += w * u[k].first;
        C += w * u[k].first * u[k].first;
        const double disc = B * B - A * C;
        t = (B + std::sqrt(std::max(0.0, disc))) / A;
      }
      if (t < T[q])
      {
        T[q] = t;
        heap.emplace(t, q);
      }
    }
  }
  std::vector<float> out;
  AssignFresh(out, static_cast<std::size_t>(n), Infinity);
  for (std::int64_t i = 0; i < n; ++i)
  {
    if (known[i])
    {
      out[i] = static_cast<float>(T[i]);
    }
  }
  return out;
}

std::vector<std::int64_t> RejectionSample(const std::vector<float>& map, double T, int count, std::uint64_t seed)
{
  std::vector<std::int64_t> pool;
  for (std::int64_t i = 0, n = static_cast<std::int64_t>(map.size()); i < n; ++i)
  {
    if (map[i] <= T)
    {
      pool.push_back(i);
    }
  }
  std::vector<std::int64_t> kept;
  if (pool.empty() || count <= 0)
  {
    return kept;
  }
  // Own uniform maps from the raw generator: the standard distributions differ between libraries.
  std::mt19937_64 random(seed);
  const auto unit = [&]() { return static_cast<double>(random() >> 11) * (1.0 / 9007199254740992.0); };
  std::unordered_set<std::int64_t> taken;
  const std::int64_t draws = 1000 * static_cast<std::int64_t>(count) + 10000;
  for (std::int64_t d = 0; d < draws && static_cast<int>(kept.size()) < count; ++d)
  {
    const std::int64_t p = pool[static_cast<std::size_t>(unit() * static_cast<double>(pool.size()))];
    if (map[p] <= unit() * T && taken.insert(p).second)
    {
      kept.push_back(p);
    }
  }
  return kept;
}

namespace
{
// Shortest-path trees of integer edge weights (Dial's bucket queue) in a box of the image.
struct PathBox
{
  std::array<int, 3> Lo, Dims;
  ImageGeometry Frame; // Dims only, for Coordinates
  std::int64_t Size() const { return static_cast<std::int64_t>(Dims[0]) * Dims[1] * Dims[2]; }
  std::int64_t Local(const ImageGeometry& g, std::int64_t v) const
  {
    const std::array<int, 3> c = g.Coordinates(v);
    return (static_cast<std::int64_t>(c[2] - Lo[2]) * Dims[1] + (c[1] - Lo[1])) * Dims[0] + (c[0] - Lo[0]);
  }
  std::int64_t Global(const ImageGeometry& g, std::int64_t l) const
  {
    const std::array<int, 3> c = Frame.Coordinates(l);
    return g.Index(c[0] + Lo[0], c[1] + Lo[1], c[2] + Lo[2]);
  }
};

struct Workspace
{
  // Per voxel: distance << 3 | the direction it was reached from (7 at the source).
  std::vector<std::uint32_t> Label;
  std::vector<std::uint32_t> Count;
  std::vector<std::vector<std::uint32_t>> Buckets;
};

// One source's tree until every sink is settled; each sink's path back to the source adds 1 to
// the voxels on it. `weight` holds, per voxel, one weight per axis for the edge to the next voxel
// along it (0: no edge, where the box ends).
void PathsFromSource(std::uint32_t source, const std::vector<std::uint32_t>& sinks, const std::vector<std::uint8_t>& isSink,
  const std::vector<std::uint16_t>& weight, const Grid& grid, Workspace& w, const std::atomic<bool>& cancel)
{
  constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
  constexpr std::uint64_t farthest = (std::uint64_t(1) << 29) - 1;
  std::fill(w.Label.begin(), w.Label.end(), none);
  const std::size_t mask = w.Buckets.size() - 1; // a power of two above the largest weight
  const int axes = grid.Directions / 2;
  const std::int64_t size = static_cast<std::int64_t>(w.Label.size());
  std::uint64_t queued = 1;
  std::size_t settledSinks = 0;
  w.Label[source] = 7;
  w.Buckets[0].push_back(source);
  for (std::uint64_t d = 0; queued > 0 && settledSinks < sinks.size() && !cancel.load(std::memory_order_relaxed); ++d)
  {
    auto& bucket = w.Buckets[d & mask];
    while (!bucket.empty())
    {
      const std::uint32_t v = bucket.back();
      bucket.pop_back();
      --queued;
      if ((w.Label[v] >> 3) != d)
      {
        continue;
      }
      settledSinks += isSink[v];
      for (int dir = 0; dir < grid.Directions; ++dir)
      {
        const std::int64_t off = grid.Offset[dir];
        const std::int64_t q = v + off;
        if (q < 0 || q >= size)
        {
          continue;
        }
        const std::uint16_t edge = weight[static_cast<std::size_t>((dir & 1) ? q : v) * axes + dir / 2];
        const std::uint64_t nd = d + edge;
        if (edge && nd < (w.Label[q] >> 3) && nd <= farthest)
        {
          w.Label[q] = static_cast<std::uint32_t>(nd << 3) | static_cast<std::uint32_t>(dir);
          w.Buckets[nd & mask].push_back(static_cast<std::uint32_t>(q));
          ++queued;
        }
      }
    }
  }
  for (auto& b : w.Buckets)
  {
    b.clear();
  }
  for (std::uint32_t t : sinks)
  {
    if (w.Label[t] == none)
    {
      continue;
    }
    for (std::uint32_t v = t;; v = static_cast<std::uint32_t>(v - grid.Offset[w.Label[v] & 7]))
    {
      ++w.Count[v];
      if (v == source)
      {
        break;
      }
    }
  }
}
// The stage on the grid coarsened by the smallest integer factor f that brings it within
// MaximumPathVoxels (block means of the image), its maps and EC brought back by nearest neighbour.
// The smallest block factor f >= 2 whose coarse grid (f x f (x f) blocks, spacing x f) holds at
// most `maxVoxels` voxels.
int CoarseGrid(const ImageGeometry& g, std::int64_t maxVoxels, ImageGeometry& c)
{
  const int dim = g.Dimension();
  c = g;
  for (int f = 2;; ++f)
  {
    for (int a = 0; a < dim; ++a)
    {
      c.Dims[a] = (g.Dims[a] + f - 1) / f;
      c.Spacing[a] = g.Spacing[a] * f;
    }
    if (c.Size() <= maxVoxels || (c.Dims[0] <= 2 && c.Dims[1] <= 2))
    {
      return f;
    }
  }
}

// The image's block means on the coarse grid c: coarse slab by coarse slab (independent sums), row
// by row without divisions.
std::vector<float> BlockMeans(const float* image, const ImageGeometry& g, const ImageGeometry& c, int f, const ParallelFor& parallel)
{
  const int dim = g.Dimension();
  std::vector<float> coarse(static_cast<std::size_t>(c.Size()), 0.f);
  parallel(c.Dims[2], 1, [&](std::int64_t c0, std::int64_t c1) {
    std::vector<double> sum(static_cast<std::size_t>(c.SliceStride()));
    std::vector<int> count(sum.size());
    for (std::int64_t ck = c0; ck < c1; ++ck)
    {
      std::fill(sum.begin(), sum.end(), 0.0);
      std::fill(count.begin(), count.end(), 0);
      const int k0 = dim == 3 ? static_cast<int>(ck) * f : 0, k1 = dim == 3 ? std::min(g.Dims[2], k0 + f) : 1;
      for (int k = k0; k < k1; ++k)
      {
        for (int j = 0; j < g.Dims[1]; ++j)
        {
          const float* row = image + g.Index(0, j, k);
          const std::int64_t base = static_cast<std::int64_t>(j / f) * c.Dims[0];
          for (int i = 0, ci = 0, left = f; i < g.Dims[0]; ++i)
          {
            sum[base + ci] += row[i];
            ++count[base + ci];
            if (--left == 0)
            {
              ++ci;
              left = f;
            }
          }
        }
      }
      for (std::int64_t b = 0; b < c.SliceStride(); ++b)
      {
        coarse[ck * c.SliceStride() + b] = static_cast<float>(sum[b] / count[b]);
      }
    }
  });
  return coarse;
}

// The coarse result on the fine grid: each voxel takes its block's edge confidence, edge map and
// distances (the distances in fine units); row by row without divisions.
void Upsample(const RSPResult& r, const ImageGeometry& g, const ImageGeometry& c, int f, const ParallelFor& parallel,
  RSPResult& out)
{
  const int dim = g.Dimension();
  const std::int64_t n = g.Size();
  AssignFresh(out.EdgeConfidence, static_cast<std::size_t>(n));
  AssignFresh(out.EdgeMap, static_cast<std::size_t>(n));
  AssignFresh(out.ObjectDistance, static_cast<std::size_t>(n));
  AssignFresh(out.BackgroundDistance, static_cast<std::size_t>(n));
  const float scale = static_cast<float>(f);
  parallel(static_cast<std::int64_t>(g.Dims[1]) * g.Dims[2], 64, [&](std::int64_t r0, std::int64_t r1) {
    for (std::int64_t row = r0; row < r1; ++row)
    {
      const int j = static_cast<int>(row % g.Dims[1]), k = static_cast<int>(row / g.Dims[1]);
      const std::int64_t v0 = g.Index(0, j, k), k0 = c.Index(0, j / f, dim == 3 ? k / f : 0);
      for (int i = 0, ci = 0, left = f; i < g.Dims[0]; ++i)
      {
        const std::int64_t v = v0 + i, kc = k0 + ci;
        out.EdgeConfidence[v] = r.EdgeConfidence[kc];
        out.EdgeMap[v] = r.EdgeMap[kc];
        out.ObjectDistance[v] = r.ObjectDistance[kc] * scale;
        out.BackgroundDistance[v] = r.BackgroundDistance[kc] * scale;
        if (--left == 0)
        {
          ++ci;
          left = f;
        }
      }
    }
  });
}

RSPResult OnCoarserGrid(const float* image, const ImageGeometry& g, const std::vector<std::int64_t>& objectSeeds,
  const std::vector<std::int64_t>& backgroundSeeds, const RSPParameters& p, const ParallelFor& parallel,
  const ProgressFunction& progress)
{
  const int dim = g.Dimension();
  ImageGeometry c;
  const int f = CoarseGrid(g, p.MaximumPathVoxels, c);
  const auto t0 = Clock::now();
  const std::vector<float> coarse = BlockMeans(image, g, c, f, parallel);
  if (!progress(0.03))
  {
    RSPResult aborted;
    aborted.Aborted = true;
    return aborted;
  }
  // The seeds' blocks; a block holding seeds of both kinds counts as object: seeds of the two kinds
  // a voxel or two apart.
  const auto toCoarse = [&](const std::vector<std::int64_t>& seeds) {
    std::vector<std::int64_t> out;
    for (std::int64_t s : seeds)
    {
      const std::array<int, 3> x = g.Coordinates(s);
      out.push_back(c.Index(x[0] / f, x[1] / f, dim == 3 ? x[2] / f : 0));
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  };
  const std::vector<std::int64_t> object = toCoarse(objectSeeds);
  std::vector<std::int64_t> background;
  for (std::int64_t b : toCoarse(backgroundSeeds))
  {
    if (!std::binary_search(object.begin(), object.end(), b))
    {
      background.push_back(b);
    }
  }
  RSPParameters q = p;
  q.MaximumPathVoxels = 0;
  q.GradientSigma = p.GradientSigma / f;
  // Gradients per coarse voxel are up to f times those per voxel.
  q.GradientScale = p.GradientScale / f;
  q.SamplingThreshold = p.SamplingThreshold / f;
  q.PathMargin = (p.PathMargin + f - 1) / f;
  const double coarsening = SecondsSince(t0);
  RSPResult r = RSPEdgeEnhancement(coarse.data(), c, object, background, q, parallel, SubProgress(progress, 0.03, 0.9));
  if (!r.Error.empty() || r.Aborted)
  {
    return r;
  }
  const auto t1 = Clock::now();
  RSPResult out;
  out.PathGridFactor = f;
  out.ObjectThreshold = r.ObjectThreshold * f;
  out.BackgroundThreshold = r.BackgroundThreshold * f;
  out.GradientRange = r.GradientRange;
  out.Paths = r.Paths;
  out.PathVoxels = r.PathVoxels;
  Upsample(r, g, c, f, parallel, out);
  // Samples at their block's centre voxel (inside the image).
  const auto toFine = [&](const std::vector<std::int64_t>& voxels) {
    std::vector<std::int64_t> fine;
    const Grid cg(c.Dims);
    for (std::int64_t v : voxels)
    {
      const std::array<int, 3> x = cg.Coordinates(v);
      fine.push_back(g.Index(std::min(g.Dims[0] - 1, x[0] * f + f / 2), std::min(g.Dims[1] - 1, x[1] * f + f / 2),
        dim == 3 ? std::min(g.Dims[2] - 1, x[2] * f + f / 2) : 0));
    }
    return fine;
  };
  if (!progress(0.95))
  {
    out.Aborted = true;
    return out;
  }
  out.SourceVoxels = toFine(r.SourceVoxels);
  out.SinkVoxels = toFine(r.SinkVoxels);
  if (g.Is2D())
  {
    out.Contour = FinalContour(out.EdgeConfidence, g, objectSeeds, p.GapCost);
    out.Region = FillContour(out.Contour, g);
  }
  out.StepSeconds.emplace_back("coarsening", coarsening + SecondsSince(t1));
  out.StepSeconds.insert(out.StepSeconds.end(), r.StepSeconds.begin(), r.StepSeconds.end());
  progress(1.0);
  return out;
}

// The seeds' check: both kinds, no voxel holding both.
std::string SeedsProblem(const std::vector<std::int64_t>& objectSeeds, const std::vector<std::int64_t>& backgroundSeeds)
{
  if (objectSeeds.empty() || backgroundSeeds.empty())
  {
    return "both object and background seeds are needed.";
  }
  std::vector<std::int64_t> a = objectSeeds, b = backgroundSeeds, both;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(both));
  return both.empty() ? std::string() : std::to_string(both.size()) + " voxel(s) hold both an object and a background seed.";
}

// Step 1: the pixel cost G = exp(-beta |grad|) (eq. 25) and the marching slowness 1/G (eq. 27).
void PixelCosts(const float* image, const ImageGeometry& g, const RSPParameters& p, double gradientRange,
  const ParallelFor& parallel, std::vector<float>& cost, std::vector<float>& slowness)
{
  const std::int64_t n = g.Size();
  AssignFresh(cost, static_cast<std::size_t>(n));
  AssignFresh(slowness, static_cast<std::size_t>(n));
  if (p.GradientSigma > 0.0)
  {
    GaussianSmooth(image, slowness.data(), g, p.GradientSigma, parallel);
    GradientMagnitude(slowness.data(), g, cost.data(), parallel);
  }
  else
  {
    GradientMagnitude(image, g, cost.data(), parallel);
  }
  const double beta = p.GradientScale * 255.0 / gradientRange;
  parallel(n, 1 << 16, [&](std::int64_t b, std::int64_t e) {
    for (std::int64_t i = b; i < e; ++i)
    {
      // e^-40 ~ 4e-18: keeps 1/G finite in float.
      const double x = std::min(40.0, beta * cost[i]);
      cost[i] = static_cast<float>(std::exp(-x));
      slowness[i] = static_cast<float>(std::exp(x));
    }
  });
}

// Step 4a: the box the paths run in: what both marching maps reach, grown by the margin.
PathBox SeedPathBox(const RSPResult& out, const ImageGeometry& g, int margin)
{
  PathBox box;
  const Grid grid(g.Dims);
  std::array<int, 3> lo{ { g.Dims[0], g.Dims[1], g.Dims[2] } }, hi{ { -1, -1, -1 } };
  for (std::int64_t i = 0; i < g.Size(); ++i)
  {
    if (out.ObjectDistance[i] <= out.ObjectThreshold || out.BackgroundDistance[i] <= out.BackgroundThreshold)
    {
      const std::array<int, 3> c = grid.Coordinates(i);
      for (int a = 0; a < 3; ++a)
      {
        lo[a] = std::min(lo[a], c[a]);
        hi[a] = std::max(hi[a], c[a]);
      }
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    box.Lo[a] = std::max(0, lo[a] - margin);
    box.Dims[a] = std::min(g.Dims[a] - 1, hi[a] + margin) - box.Lo[a] + 1;
  }
  box.Frame.Dims = box.Dims;
  return box;
}

// Step 4b: integer edge weights (G_i + G_j) / 2 x step in the box, in 1/256 of a flat voxel step, at
// least 1 (0: no edge, beyond the box), `axes` per voxel; returns the largest.
int PathWeights(const std::vector<float>& cost, const ImageGeometry& g, const PathBox& box, const ParallelFor& parallel,
  std::vector<std::uint16_t>& weight)
{
  constexpr double Quantum = 256.0;
  const Grid local(box.Dims), full(g.Dims);
  const int axes = local.Directions / 2;
  const std::array<double, 3> h = AxisSteps(g);
  weight.assign(static_cast<std::size_t>(box.Size()) * axes, 0);
  std::vector<int> rowMax(static_cast<std::size_t>(box.Dims[1]) * box.Dims[2], 1);
  parallel(static_cast<std::int64_t>(rowMax.size()), 16, [&](std::int64_t r0, std::int64_t r1) {
    for (std::int64_t r = r0; r < r1; ++r)
    {
      const int j = static_cast<int>(r % box.Dims[1]), k = static_cast<int>(r / box.Dims[1]);
      for (int i = 0; i < box.Dims[0]; ++i)
      {
        const std::array<int, 3> c{ { i, j, k } };
        const std::int64_t l = (static_cast<std::int64_t>(k) * box.Dims[1] + j) * box.Dims[0] + i;
        const std::int64_t v = g.Index(i + box.Lo[0], j + box.Lo[1], k + box.Lo[2]);
        for (int a = 0; a < axes; ++a)
        {
          if (!local.Inside(c, 2 * a))
          {
            continue;
          }
          const std::int64_t q = v + full.Offset[2 * a];
          const double x = Quantum * 0.5 * (static_cast<double>(cost[v]) + cost[q]) * h[a];
          const int wq = std::max(1, std::min(65535, static_cast<int>(std::lround(x))));
          weight[static_cast<std::size_t>(l) * axes + a] = static_cast<std::uint16_t>(wq);
          rowMax[r] = std::max(rowMax[r], wq);
        }
      }
    }
  });
  return *std::max_element(rowMax.begin(), rowMax.end());
}

// Step 4c: every source's shortest-path tree to all sinks, counting the voxels each path crosses
// (out.EdgeConfidence). Workspaces are shared by the threads through a pool; the counts are
// integers, so their sum does not depend on which workspace ran which source. The trees run on a
// worker thread (itself using `parallel`); this thread reports progress as sources finish, every
// 0.1 s at most, and on abort cancels the trees, which stop within a bucket. False when aborted.
bool CountPaths(const ImageGeometry& g, const PathBox& box, const std::vector<std::uint16_t>& weight, int maxWeight,
  const ParallelFor& parallel, const ProgressFunction& progress, RSPResult& out)
{
  const Grid local(box.Dims);
  std::vector<std::uint32_t> sinks;
  std::vector<std::uint8_t> isSink(static_cast<std::size_t>(box.Size()), 0);
  for (std::int64_t t : out.SinkVoxels)
  {
    const std::uint32_t l = static_cast<std::uint32_t>(box.Local(g, t));
    sinks.push_back(l);
    isSink[l] = 1;
  }
  std::mutex poolLock;
  std::vector<std::unique_ptr<Workspace>> all;
  std::vector<Workspace*> idle;
  const auto acquire = [&]() {
    std::lock_guard<std::mutex> lock(poolLock);
    if (!idle.empty())
    {
      Workspace* w = idle.back();
      idle.pop_back();
      return w;
    }
    all.push_back(std::make_unique<Workspace>());
    Workspace* w = all.back().get();
    w->Label.resize(static_cast<std::size_t>(box.Size()));
    w->Count.assign(static_cast<std::size_t>(box.Size()), 0);
    std::size_t buckets = 1;
    while (buckets <= static_cast<std::size_t>(maxWeight))
    {
      buckets *= 2;
    }
    w->Buckets.resize(buckets);
    return w;
  };
  const auto release = [&](Workspace* w) {
    std::lock_guard<std::mutex> lock(poolLock);
    idle.push_back(w);
  };
  const std::int64_t nSources = static_cast<std::int64_t>(out.SourceVoxels.size());
  std::atomic<bool> cancel{ false };
  std::atomic<std::int64_t> done{ 0 };
  std::mutex doneLock;
  std::condition_variable doneSignal;
  std::exception_ptr failure;
  std::thread worker([&]() {
    try
    {
      parallel(nSources, 1, [&](std::int64_t s0, std::int64_t s1) {
        Workspace* w = acquire();
        for (std::int64_t s = s0; s < s1 && !cancel; ++s)
        {
          PathsFromSource(static_cast<std::uint32_t>(box.Local(g, out.SourceVoxels[s])), sinks, isSink, weight, local, *w, cancel);
          std::lock_guard<std::mutex> lock(doneLock);
          ++done;
          doneSignal.notify_all();
        }
        release(w);
      });
    }
    catch (...)
    {
      failure = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(doneLock);
    done = nSources; // also after a failure or cancel: the waiting ends
    doneSignal.notify_all();
  });
  bool go = true;
  {
    std::unique_lock<std::mutex> lock(doneLock);
    while (done < nSources)
    {
      doneSignal.wait_for(lock, std::chrono::milliseconds(100));
      const double fraction = static_cast<double>(done) / static_cast<double>(nSources);
      lock.unlock();
      go = progress(fraction);
      lock.lock();
      if (!go)
      {
        cancel = true;
        break;
      }
    }
  }
  worker.join();
  if (failure)
  {
    std::rethrow_exception(failure);
  }
  if (!go)
  {
    return false;
  }
  out.Paths = nSources * static_cast<std::int64_t>(sinks.size());
  AssignFresh(out.EdgeConfidence, static_cast<std::size_t>(g.Size()), 0.f);
  for (std::int64_t l = 0; l < box.Size(); ++l)
  {
    std::uint64_t c = 0;
    for (const auto& w : all)
    {
      c += w->Count[l];
    }
    if (c)
    {
      out.EdgeConfidence[box.Global(g, l)] = static_cast<float>(c);
    }
  }
  return true;
}
} // namespace

RSPResult RSPEdgeEnhancement(const float* image, const ImageGeometry& g, const std::vector<std::int64_t>& objectSeeds,
  const std::vector<std::int64_t>& backgroundSeeds, const RSPParameters& p, const ParallelFor& parallel,
  const ProgressFunction& progress)
{
  RSPResult out;
  out.Error = ValidateParameters(p);
  if (out.Error.empty())
  {
    out.Error = SeedsProblem(objectSeeds, backgroundSeeds);
  }
  if (!out.Error.empty())
  {
    return out;
  }
  const std::int64_t n = g.Size();
  if (p.MaximumPathVoxels > 0 && n > p.MaximumPathVoxels)
  {
    return OnCoarserGrid(image, g, objectSeeds, backgroundSeeds, p, parallel, progress);
  }
  auto aborted = [&](bool goOn) {
    out.Aborted = !goOn;
    return out.Aborted;
  };
  auto t0 = Clock::now();

  // 1. Pixel cost and marching slowness.
  out.GradientRange = RobustRange(image, n);
  if (!(out.GradientRange > 0.0))
  {
    out.Error = "the image is constant: it has no edges to enhance.";
    return out;
  }
  std::vector<float> cost, slowness;
  PixelCosts(image, g, p, out.GradientRange, parallel, cost, slowness);
  out.StepSeconds.emplace_back("cost", SecondsSince(t0));
  if (aborted(progress(0.05)))
  {
    return out;
  }

  // 2. Marching distance maps, each only as far as its sampling threshold.
  t0 = Clock::now();
  out.ObjectThreshold = p.SamplingThreshold;
  out.BackgroundThreshold = p.SamplingThreshold;
  out.ObjectDistance = FastMarching(slowness.data(), g, objectSeeds, p.SamplingThreshold, &backgroundSeeds,
    &out.ObjectThreshold, SubProgress(progress, 0.05, 0.15));
  if (aborted(!out.ObjectDistance.empty() && progress(0.15)))
  {
    return out;
  }
  out.BackgroundDistance = FastMarching(slowness.data(), g, backgroundSeeds, p.SamplingThreshold, &objectSeeds,
    &out.BackgroundThreshold, SubProgress(progress, 0.15, 0.25));
  if (aborted(!out.BackgroundDistance.empty()))
  {
    return out;
  }
  out.StepSeconds.emplace_back("marching", SecondsSince(t0));
  std::vector<float>().swap(slowness);
  if (aborted(progress(0.25)))
  {
    return out;
  }

  // 3. Sources and sinks.
  t0 = Clock::now();
  out.SourceVoxels = RejectionSample(out.ObjectDistance, out.ObjectThreshold, p.Sources, p.RandomSeed * 2ull + 1);
  out.SinkVoxels = RejectionSample(out.BackgroundDistance, out.BackgroundThreshold, p.Sinks, p.RandomSeed * 2ull + 2);
  if (out.SourceVoxels.empty() || out.SinkVoxels.empty())
  {
    out.Error = "no sources or sinks could be drawn from the marching maps.";
    return out;
  }
  out.StepSeconds.emplace_back("sampling", SecondsSince(t0));
  if (aborted(progress(0.27)))
  {
    return out;
  }

  // 4. All source-sink shortest paths in the box both maps reach.
  t0 = Clock::now();
  const PathBox box = SeedPathBox(out, g, p.PathMargin);
  out.PathVoxels = box.Size();
  if (aborted(progress(0.28)))
  {
    return out;
  }
  if (box.Size() >= std::numeric_limits<std::uint32_t>::max())
  {
    out.Error = "the region the paths run in is too large (more than 4 G voxels).";
    return out;
  }
  std::vector<std::uint16_t> weight;
  const int maxWeight = PathWeights(cost, g, box, parallel, weight);
  if (aborted(progress(0.3)) || aborted(CountPaths(g, box, weight, maxWeight, parallel, SubProgress(progress, 0.3, 0.9), out)))
  {
    return out;
  }
  out.StepSeconds.emplace_back("paths", SecondsSince(t0));

  // 5. The binary edge map, and the 2D final contour with its region.
  t0 = Clock::now();
  const float edgeLevel = static_cast<float>(std::max(1.0, p.EdgeThreshold * static_cast<double>(out.Paths)));
  out.EdgeMap.resize(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i)
  {
    out.EdgeMap[i] = out.EdgeConfidence[i] >= edgeLevel ? 1 : 0;
  }
  if (g.Is2D())
  {
    out.Contour = FinalContour(out.EdgeConfidence, g, objectSeeds, p.GapCost);
    out.Region = FillContour(out.Contour, g);
  }
  out.StepSeconds.emplace_back("contour", SecondsSince(t0));
  progress(1.0);
  return out;
}

std::vector<std::int64_t> FinalContour(
  const std::vector<float>& ec, const ImageGeometry& g, const std::vector<std::int64_t>& inside, double gapCost)
{
  std::vector<std::int64_t> contour;
  if (!g.Is2D() || ec.empty() || inside.empty())
  {
    return contour;
  }
  const std::int64_t n = g.Size();
  const Grid grid(g.Dims);
  const std::int64_t A = std::max_element(ec.begin(), ec.end()) - ec.begin();
  if (!(ec[A] > 0.f))
  {
    return contour;
  }
  const std::array<int, 3> a = grid.Coordinates(A);
  std::int64_t S = inside[0];
  double best = std::numeric_limits<double>::max();
  for (std::int64_t s : inside)
  {
    const std::array<int, 3> c = grid.Coordinates(s);
    const double d = std::hypot(c[0] - a[0], c[1] - a[1]);
    if (d < best)
    {
      best = d;
      S = s;
    }
  }
  // Closed paths through A that wind around S: a ray leaves S's lower-left corner along +x, every
  // crossing of it flips a parity bit, and the cheapest path from (A, even) to (A, odd) is the
  // cheapest closed path through A around S (the thesis blocks one edge A-B next to A, which also
  // admits a 3-edge loop around no pixel).
  const std::array<int, 3> sc = grid.Coordinates(S);
  const auto crosses = [&](const std::array<int, 3>& u, int d) {
    // Only moves along y between rows sc[1] - 1 and sc[1], at x >= sc[0], cross the ray.
    return d / 2 == 1 && u[0] >= sc[0] && ((d == 2 && u[1] == sc[1] - 1) || (d == 3 && u[1] == sc[1]));
  };
  std::vector<double> cost(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i)
  {
    cost[i] = ec[i] > 0.f ? 1.0 / ec[i] : gapCost;
  }
  std::vector<double> dist(static_cast<std::size_t>(2 * n), std::numeric_limits<double>::infinity());
  std::vector<std::int8_t> parent(static_cast<std::size_t>(2 * n), -1);
  MinHeap heap;
  dist[2 * A] = 0.0;
  heap.emplace(0.0, 2 * A);
  const std::int64_t goal = 2 * A + 1;
  while (!heap.empty())
  {
    const HeapEntry top = heap.top();
    heap.pop();
    const std::int64_t state = top.second;
    if (top.first != dist[state])
    {
      continue;
    }
    if (state == goal)
    {
      break;
    }
    const std::int64_t v = state / 2;
    const std::array<int, 3> c = grid.Coordinates(v);
    for (int d = 0; d < grid.Directions; ++d)
    {
      if (!grid.Inside(c, d))
      {
        continue;
      }
      const std::int64_t q = v + grid.Offset[d];
      const std::int64_t next = 2 * q + ((state & 1) ^ (crosses(c, d) ? 1 : 0));
      const double nd = top.first + 0.5 * (cost[v] + cost[q]);
      if (nd < dist[next])
      {
        dist[next] = nd;
        parent[next] = static_cast<std::int8_t>(d);
        heap.emplace(nd, next);
      }
    }
  }
  if (!std::isfinite(dist[goal]))
  {
    return contour;
  }
  // Back from (A, odd) to (A, even); the parity before a step is recovered from the step itself.
  for (std::int64_t state = goal; state != 2 * A;)
  {
    const std::int64_t v = state / 2;
    contour.push_back(v);
    const int d = parent[state];
    const std::int64_t u = v - grid.Offset[d];
    state = 2 * u + ((state & 1) ^ (crosses(grid.Coordinates(u), d) ? 1 : 0));
  }
  std::reverse(contour.begin(), contour.end());
  // A far from the ridge gives a lasso: a tail out to A and back along the same voxels. The
  // contour is the loop: strip the tail (the voxels before and after its tip coincide).
  std::size_t first = 0, last = contour.size(); // the cycle is contour[first, last), its tip last - 1
  while (last - first >= 3 && contour[first] == contour[last - 2])
  {
    ++first;
    --last;
  }
  return std::vector<std::int64_t>(contour.begin() + static_cast<std::ptrdiff_t>(first),
    contour.begin() + static_cast<std::ptrdiff_t>(last));
}

std::vector<std::uint8_t> FillContour(const std::vector<std::int64_t>& contour, const ImageGeometry& g)
{
  const std::int64_t n = g.Size();
  std::vector<std::uint8_t> region;
  if (contour.empty() || !g.Is2D())
  {
    return region;
  }
  // Outside = 4-connected to the border without crossing the contour; the rest is enclosed.
  std::vector<std::uint8_t> state(static_cast<std::size_t>(n), 0); // 1 contour, 2 outside
  for (std::int64_t v : contour)
  {
    state[v] = 1;
  }
  const Grid grid(g.Dims);
  std::vector<std::int64_t> stack;
  for (std::int64_t v = 0; v < n; ++v)
  {
    const std::array<int, 3> c = grid.Coordinates(v);
    const bool border = c[0] == 0 || c[1] == 0 || c[0] == g.Dims[0] - 1 || c[1] == g.Dims[1] - 1;
    if (border && state[v] == 0)
    {
      state[v] = 2;
      stack.push_back(v);
    }
  }
  while (!stack.empty())
  {
    const std::int64_t v = stack.back();
    stack.pop_back();
    const std::array<int, 3> c = grid.Coordinates(v);
    for (int d = 0; d < 4; ++d)
    {
      if (grid.Inside(c, d) && state[v + grid.Offset[d]] == 0)
      {
        state[v + grid.Offset[d]] = 2;
        stack.push_back(v + grid.Offset[d]);
      }
    }
  }
  region.resize(static_cast<std::size_t>(n));
  for (std::int64_t v = 0; v < n; ++v)
  {
    region[v] = state[v] != 2 ? 1 : 0;
  }
  return region;
}
} // namespace featuremesh
