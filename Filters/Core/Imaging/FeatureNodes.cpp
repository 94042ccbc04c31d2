#include "FeatureNodes.h"
#include "Memory.h"

#include "Canny.h"
#include "EdgeSampling.h"
#include "Halftoning.h"
#include "ImageFilters.h"
#include "ImagingInternals.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <numeric>

namespace featuremesh
{
using namespace detail;
namespace
{
using Clock = std::chrono::steady_clock;
double SecondsSince(Clock::time_point t0)
{
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// `voxels` voxels of the image's median axis (thick slices: of the in-plane axes), per axis in
// that axis's voxels (at least `least`): the lattices' steps and windows are even in world units on
// an anisotropic grid. Steps in voxels leave the box's edges dense across thin slices and sparse
// across thick ones (slivers stage 3 cannot mend) and stage 3 fills the thick slices' gaps with
// nodes; steps of the finest axis densified the other two axes' lattices when one axis was thinner
// than both (docs/smoothing.md). An isotropic grid keeps `voxels` on every axis.
std::array<int, 3> EvenSteps(const ImageGeometry& g, int voxels, int least)
{
  const double unit = g.MedianSpacing();
  std::array<int, 3> step{ { voxels, voxels, voxels } };
  for (int a = 0; a < g.Dimension(); ++a)
  {
    step[a] = std::max(least, static_cast<int>(std::lround(voxels * unit / std::fabs(g.Spacing[a]))));
  }
  return step;
}

// True when some voxel within the centred box of half-widths h around (i,j,k) is set in mask.
bool AnyInBox(const std::vector<std::uint8_t>& mask, const ImageGeometry& g, int i, int j, int k, const std::array<int, 3>& h)
{
  const int k0 = std::max(0, k - h[2]), k1 = std::min(g.Dims[2] - 1, k + h[2]);
  const int j0 = std::max(0, j - h[1]), j1 = std::min(g.Dims[1] - 1, j + h[1]);
  const int i0 = std::max(0, i - h[0]), i1 = std::min(g.Dims[0] - 1, i + h[0]);
  for (int kk = k0; kk <= k1; ++kk)
  {
    for (int jj = j0; jj <= j1; ++jj)
    {
      const std::uint8_t* row = mask.data() + g.Index(0, jj, kk);
      for (int ii = i0; ii <= i1; ++ii)
      {
        if (row[ii])
        {
          return true;
        }
      }
    }
  }
  return false;
}

// Evenly spaced positions 0..last with gaps of at most `spacing`.
std::vector<int> EvenPositions(int extent, int spacing)
{
  std::vector<int> pos;
  if (extent <= 1)
  {
    pos.push_back(0);
    return pos;
  }
  const int last = extent - 1;
  const int segments = std::max(1, (last + spacing - 1) / spacing);
  for (int s = 0; s <= segments; ++s)
  {
    pos.push_back(static_cast<int>(std::lround(static_cast<double>(s) * last / segments)));
  }
  return pos;
}
// 0 when the largest |value| lies in [2^-40, 2^40] (or all are 0), else its binary exponent.
int ExtremeMagnitudeExponent(const float* v, std::int64_t n, const ParallelFor& parallel)
{
  std::vector<float> blockMax(ReductionBlocks, 0.f);
  const std::int64_t block = (n + ReductionBlocks - 1) / ReductionBlocks;
  parallel(ReductionBlocks, 1, [&](std::int64_t b0, std::int64_t b1) {
    for (std::int64_t b = b0; b < b1; ++b)
    {
      float m = 0.f;
      for (std::int64_t i = b * block, e = std::min(n, (b + 1) * block); i < e; ++i)
      {
        m = std::max(m, std::fabs(v[i]));
      }
      blockMax[b] = m;
    }
  });
  const float largest = *std::max_element(blockMax.begin(), blockMax.end());
  if (largest == 0.f || (largest >= std::ldexp(1.f, -40) && largest <= std::ldexp(1.f, 40)))
  {
    return 0;
  }
  return std::ilogb(largest);
}
} // namespace

std::string ValidateParameters(const FeatureNodeParameters& p)
{
  if (!(p.GaussianSigma >= 0.0 && p.GaussianSigma <= 50.0) || !(p.HessianSigma >= 0.0 && p.HessianSigma <= 50.0))
  {
    return "the Gaussian and Hessian sigmas must lie in [0, 50] voxels.";
  }
  if (!(p.LowThreshold >= 0.0) || !(p.HighThreshold > 0.0))
  {
    return "Canny thresholds must be non-negative and the high threshold positive.";
  }
  if (p.LowThreshold > p.HighThreshold)
  {
    return "the low Canny threshold is above the high one; they are out of order.";
  }
  if (!(p.NoiseLowFactor >= 0.0 && p.NoiseLowFactor <= p.NoiseHighFactor && p.NoiseHighFactor <= 100.0) ||
    !(p.NoiseFeatureFactor >= 0.0 && p.NoiseFeatureFactor <= 100.0))
  {
    return "the noise factors must satisfy 0 <= low <= high <= 100 and 0 <= feature <= 100.";
  }
  if (!(p.MaximumPercentile > 0.0 && p.MaximumPercentile <= 100.0))
  {
    return "the gradient maximum percentile must lie in (0, 100].";
  }
  if (p.CovarianceNeighbourhood < 0 || p.CovarianceNeighbourhood > 41)
  {
    return "the covariance neighbourhood must be 0 (automatic) or an edge length up to 41 voxels.";
  }
  if (!(p.StraightRatio > 0.0 && p.StraightRatio <= p.CurvedRatio && p.CurvedRatio <= 1.0))
  {
    return "eigenvalue-ratio thresholds must satisfy 0 < straight <= curved <= 1.";
  }
  for (int r : { p.Radii2D[0], p.Radii2D[1], p.Radii2D[2], p.Radii3D[0], p.Radii3D[1], p.Radii3D[2] })
  {
    if (r < 0 || r > 50)
    {
      return "sampling radii must lie between 0 and 50 voxels.";
    }
  }
  if (!(p.FeaturePercentile > 0.0 && p.FeaturePercentile <= 100.0))
  {
    return "the feature-map maximum percentile must lie in (0, 100].";
  }
  if (!(p.HalftoneThreshold > 0.0 && p.HalftoneThreshold < 1.0))
  {
    return "the halftone threshold q must lie in (0, 1).";
  }
  if (!(p.HalftoneGamma > 0.0 && p.HalftoneGamma <= 10.0))
  {
    return "the halftone exponent gamma must lie in (0, 10].";
  }
  if (p.ExclusionWindow < 1 || p.ExclusionWindow > 101)
  {
    return "the exclusion window must be between 1 and 101 voxels.";
  }
  if (p.UniformSpacing < 1 || p.BoundarySpacing < 1)
  {
    return "uniform and boundary spacings must be at least one voxel.";
  }
  if (p.EdgeGateRadius < 0 || p.EdgeGateRadius > 1000)
  {
    return "the edge gate radius must lie in [0, 1000] voxels.";
  }
  if (p.CoarseningLevels < 0 || p.CoarseningLevels > 6)
  {
    return "the coarsening levels must lie in [0, 6].";
  }
  return std::string();
}

namespace
{
// The noise's level (NoiseFloor), and the floors it gives the gradient (Canny's thresholds) and
// the Hessian diagonal (the feature map), in the units of the image as read.
struct NoiseFloors
{
  double Sigma = 0.0, Low = 0.0, High = 0.0, Feature = 0.0;
};
NoiseFloors EstimateNoiseFloors(const float* image, const ImageGeometry& g, const FeatureNodeParameters& p,
  const ParallelFor& parallel)
{
  NoiseFloors floors;
  if (p.NoiseFloor)
  {
    floors.Sigma = EstimateNoiseSigma(image, g, parallel);
    const double gradient = floors.Sigma * FilteredNoiseDeviation(g.Dimension(), p.GaussianSigma, { 0.5, 0.0, -0.5 });
    floors.Low = p.NoiseLowFactor * gradient;
    floors.High = p.NoiseHighFactor * gradient;
    floors.Feature =
      p.NoiseFeatureFactor * floors.Sigma * FilteredNoiseDeviation(g.Dimension(), p.HessianSigma, { 1.0, -2.0, 1.0 });
  }
  return floors;
}

// The edge voxels of `edgeMap` in voxel order: per-block lists joined in block order, the same
// order whatever the thread count.
std::vector<std::int64_t> EdgeVoxels(const std::vector<std::uint8_t>& edgeMap, const ParallelFor& parallel)
{
  const std::int64_t n = static_cast<std::int64_t>(edgeMap.size());
  const std::int64_t block = (n + ReductionBlocks - 1) / ReductionBlocks;
  std::vector<std::vector<std::int64_t>> found(ReductionBlocks);
  parallel(ReductionBlocks, 1, [&](std::int64_t b0, std::int64_t b1) {
    for (std::int64_t b = b0; b < b1; ++b)
    {
      for (std::int64_t i = b * block, e = std::min(n, (b + 1) * block); i < e; ++i)
      {
        if (edgeMap[i])
        {
          found[b].push_back(i);
        }
      }
    }
  });
  std::size_t total = 0;
  for (const auto& f : found)
  {
    total += f.size();
  }
  std::vector<std::int64_t> points;
  points.reserve(total);
  for (const auto& f : found)
  {
    points.insert(points.end(), f.begin(), f.end());
  }
  return points;
}

// The nodes as they are placed, one per voxel: the first kind to claim a voxel keeps it (boundary,
// then Canny, halftone, uniform).
class NodePlacer
{
public:
  NodePlacer(const ImageGeometry& g, FeatureNodeResult& out)
    : G(g)
    , Out(out)
  {
    AssignFresh(this->Occupied, g.Size(), std::uint8_t(0));
  }
  void Add(int i, int j, int k, NodeType type, float radius)
  {
    const std::int64_t idx = this->G.Index(i, j, k);
    if (this->Occupied[idx])
    {
      return;
    }
    this->Occupied[idx] = 1;
    this->Out.Positions.push_back({ { i, j, k } });
    this->Out.Type.push_back(type);
    // Smoothing may slide boundary nodes along the box, but never moves a corner.
    bool corner = true;
    const int ijk[3] = { i, j, k };
    for (int a = 0; a < this->G.Dimension(); ++a)
    {
      corner = corner && (ijk[a] == 0 || ijk[a] == this->G.Dims[a] - 1);
    }
    this->Out.Fixed.push_back(type == NodeType::Canny || (type == NodeType::Boundary && corner) ? 1 : 0);
    this->Out.SampleRadius.push_back(radius);
    this->Out.Counts[static_cast<int>(type)]++;
  }
  std::vector<std::uint8_t> Occupied;

private:
  const ImageGeometry& G;
  FeatureNodeResult& Out;
};

// Seed-aware nodes: the distance from the edges sets how coarse the fill may be; a lattice point of
// level l keeps every 2^l-th position (nested lattices, so the levels join without gaps). Level 0
// everywhere without a distance.
struct Coarsening
{
  const std::vector<float>& FromEdges;
  const ImageGeometry& G;
  int Levels, Spacing;
  int operator()(int i, int j, int k) const
  {
    if (this->FromEdges.empty())
    {
      return 0;
    }
    const double d = this->FromEdges[this->G.Index(i, j, k)];
    int l = 0;
    while (l < this->Levels && d >= ((1 << (l + 2)) - 2) * static_cast<double>(this->Spacing))
    {
      ++l;
    }
    return l;
  }
  static bool OnLevel(int index, int last, int l) { return index == last || index % (1 << l) == 0; }
};

// Step 3: boundary nodes, corners always, evenly spaced along the border (2D) or on the box faces (3D).
void PlaceBoundaryNodes(const ImageGeometry& g, int spacing, const Coarsening& level, NodePlacer& nodes)
{
  const std::array<int, 3> step = EvenSteps(g, spacing, 1);
  const std::vector<int> px = EvenPositions(g.Dims[0], step[0]);
  const std::vector<int> py = EvenPositions(g.Dims[1], step[1]);
  const std::vector<int> pz = EvenPositions(g.Dims[2], step[2]);
  const float r = 0.5f * spacing;
  const int lx = g.Dims[0] - 1, ly = g.Dims[1] - 1, lz = g.Dims[2] - 1;
  const int nx = static_cast<int>(px.size()), ny = static_cast<int>(py.size()), nz = static_cast<int>(pz.size());
  for (int c = 0; c < nz; ++c)
  {
    for (int b = 0; b < ny; ++b)
    {
      for (int a = 0; a < nx; ++a)
      {
        const int i = px[a], j = py[b], k = pz[c];
        const bool onFace = i == 0 || i == lx || j == 0 || j == ly || (!g.Is2D() && (k == 0 || k == lz));
        if (!onFace)
        {
          continue;
        }
        const int l = level(i, j, k);
        if (Coarsening::OnLevel(a, nx - 1, l) && Coarsening::OnLevel(b, ny - 1, l) && Coarsening::OnLevel(c, nz - 1, l))
        {
          nodes.Add(i, j, k, NodeType::Boundary, r);
        }
      }
    }
  }
}

// Step 5: uniform lattice points where no edge voxel and no node lies within the window (edge
// voxels count as occupied from here, so none lands on one either).
void PlaceUniformNodes(const ImageGeometry& g, int spacing, int h, const std::vector<std::uint8_t>& edgeMap,
  const Coarsening& level, NodePlacer& nodes)
{
  for (std::int64_t i = 0; i < g.Size(); ++i)
  {
    nodes.Occupied[i] |= edgeMap[i];
  }
  const bool is2D = g.Is2D();
  const int s = spacing;
  const std::array<int, 3> step = EvenSteps(g, spacing, 1), window = EvenSteps(g, h, 0);
  const std::array<int, 3> start{ { step[0] / 2, step[1] / 2, step[2] / 2 } };
  for (int k = is2D ? 0 : start[2]; k < g.Dims[2]; k += step[2])
  {
    for (int j = start[1]; j < g.Dims[1]; j += step[1])
    {
      for (int i = start[0]; i < g.Dims[0]; i += step[0])
      {
        const int m = 1 << level(i, j, k);
        if (((i - start[0]) / step[0]) % m || ((j - start[1]) / step[1]) % m || (!is2D && ((k - start[2]) / step[2]) % m))
        {
          continue;
        }
        if (!AnyInBox(nodes.Occupied, g, i, j, k, window))
        {
          nodes.Add(i, j, k, NodeType::Uniform, 0.5f * s);
        }
      }
    }
  }
}
// Step 4: halftone points of the Hessian feature map (seed-aware: fading away from the edges that
// matter), kept out of the exclusion window of every edge. The Canny-scale image `f` and `work` are
// spent buffers reused for the map. False when progress asked to abort.
bool PlaceHalftoneNodes(const float* image, float* f, float* work, const ImageGeometry& g, const FeatureNodeParameters& p,
  double featureFloor, const std::vector<float>& fromEdges, const std::vector<std::uint8_t>& allCanny,
  const ParallelFor& parallel, const ProgressFunction& progress, FeatureNodeResult& out, NodePlacer& nodes)
{
  auto t0 = Clock::now();
  const float* fh = f;
  float* rho = work;
  if (p.HessianSigma != p.GaussianSigma)
  {
    // The gradient magnitude and the Canny-scale image are spent: reuse both buffers.
    GaussianSmooth(image, work, g, p.HessianSigma, parallel);
    fh = work;
    rho = f;
  }
  HessianFeatureMap(fh, g, p.HalftoneGamma, p.FeaturePercentile, parallel, rho, &out.FeatureMaximum, featureFloor, p.HessianSigma);
  if (!fromEdges.empty())
  {
    // The thesis's density within s of the edges that matter, a Gaussian falloff beyond.
    const double s = p.UniformSpacing;
    parallel(g.Size(), 1 << 16, [&](std::int64_t b, std::int64_t e) {
      for (std::int64_t i = b; i < e; ++i)
      {
        const double x = std::max(0.0, fromEdges[i] - s) / s;
        rho[i] *= static_cast<float>(std::exp(-x * x));
      }
    });
  }
  out.StepSeconds.emplace_back("hessian", SecondsSince(t0));
  if (!progress(0.8))
  {
    return false;
  }
  t0 = Clock::now();
  const int h = p.ExclusionWindow / 2;
  // In voxels on every axis: in median-axis voxels along a thin axis it kept fewer points near the
  // edges and lowered the oracle Dice of the liver with halved slices (0.931 -> 0.925).
  const std::array<int, 3> box{ { h, h, h } };
  for (std::int64_t d : HalftoneInMedianVoxels(rho, g, p.HalftoneThreshold))
  {
    int i, j, k;
    Coordinates(g, d, i, j, k);
    if (!AnyInBox(out.EdgeMap, g, i, j, k, box) && (allCanny.empty() || !AnyInBox(allCanny, g, i, j, k, box)))
    {
      nodes.Add(i, j, k, NodeType::Halftone, static_cast<float>(h));
    }
  }
  out.StepSeconds.emplace_back("halftone", SecondsSince(t0));
  return true;
}
} // namespace

FeatureNodeResult ComputeFeatureNodes(const float* image, const std::uint8_t* edgeInput, const ImageGeometry& g,
  const FeatureNodeParameters& p, const ParallelFor& parallel, const ProgressFunction& progress)
{
  FeatureNodeResult out;
  const std::int64_t n = g.Size();
  // Two volume-sized buffers, each used twice: (Canny-scale image, gradient magnitude), then
  // (feature map, Hessian-scale image). A fresh 36 MB buffer costs ~20 ms of page faults here,
  // and default-initialised storage skips a needless zero fill.
  std::unique_ptr<float[]> bufferA(new float[n]), bufferB(new float[n]);
  float* f = bufferA.get();
  float* work = bufferB.get();
  AdviseHugePages(f, n * sizeof(float));
  AdviseHugePages(work, n * sizeof(float));
  auto t0 = Clock::now();
  // The recipe is scale-invariant (thresholds are fractions of maxima), and scaling by a power of
  // two is exact: images of extreme magnitude, whose gradients would overflow or underflow float,
  // are brought near 1 first; all others are read as they are.
  std::vector<float> rescaled;
  const int exponent = ExtremeMagnitudeExponent(image, n, parallel);
  if (exponent)
  {
    rescaled.resize(n);
    parallel(n, 65536, [&](std::int64_t b, std::int64_t e) {
      for (std::int64_t i = b; i < e; ++i)
      {
        rescaled[i] = std::ldexp(image[i], -exponent);
      }
    });
    image = rescaled.data();
  }
  const NoiseFloors floors = EstimateNoiseFloors(image, g, p, parallel);
  out.NoiseSigma = std::ldexp(floors.Sigma, exponent);
  GaussianSmooth(image, f, g, p.GaussianSigma, parallel);
  out.StepSeconds.emplace_back("gaussian", SecondsSince(t0));
  if (!progress(0.1))
  {
    out.Aborted = true;
    return out;
  }
  t0 = Clock::now();

  // 1. Edges: Canny, the supplied edge map, or (seed-aware) the map and the Canny edges near it.
  const bool seedAware = edgeInput && p.SeedAware;
  // Seed-aware: every Canny edge still keeps halftone points off itself (they would crowd edges
  // the mesh is not meant to follow).
  std::vector<std::uint8_t> allCanny;
  if (seedAware)
  {
    const std::vector<float> fromMap = DistanceToMask(edgeInput, g, parallel);
    allCanny = CannyEdges(f, g, p.LowThreshold, p.HighThreshold, p.MaximumPercentile, parallel, &out.GradientMaximum, work,
      floors.Low, floors.High, p.GaussianSigma);
    const float gate = static_cast<float>(p.EdgeGateRadius);
    out.EdgeMap.resize(n);
    for (std::int64_t i = 0; i < n; ++i)
    {
      out.EdgeMap[i] = edgeInput[i] || (allCanny[i] && fromMap[i] <= gate) ? 1 : 0;
    }
  }
  else if (edgeInput)
  {
    out.EdgeMap.assign(edgeInput, edgeInput + n);
    for (auto& v : out.EdgeMap)
    {
      v = v ? 1 : 0;
    }
  }
  else
  {
    out.EdgeMap = CannyEdges(f, g, p.LowThreshold, p.HighThreshold, p.MaximumPercentile, parallel, &out.GradientMaximum,
      work, floors.Low, floors.High, p.GaussianSigma);
  }
  out.StepSeconds.emplace_back("canny", SecondsSince(t0));
  if (!progress(0.3))
  {
    out.Aborted = true;
    return out;
  }

  // 2. PCA-adaptive sampling of the edge points.
  t0 = Clock::now();
  const std::vector<std::int64_t> edgePoints = EdgeVoxels(out.EdgeMap, parallel);
  out.EdgeVoxels = static_cast<std::int64_t>(edgePoints.size());
  const std::vector<std::uint8_t> radii = EdgeSampleRadii(edgePoints, out.EdgeMap, g, p, parallel);
  out.StepSeconds.emplace_back("pca", SecondsSince(t0));
  t0 = Clock::now();
  const std::vector<std::int64_t> kept = ThinEdgePoints(edgePoints, radii, g);
  out.StepSeconds.emplace_back("thinning", SecondsSince(t0));
  if (!progress(0.5))
  {
    out.Aborted = true;
    return out;
  }

  // 3. Boundary nodes claim first, then the thinned Canny points.
  NodePlacer nodes(g, out);
  const std::vector<float> fromEdges = seedAware ? DistanceToMask(out.EdgeMap.data(), g, parallel) : std::vector<float>();
  const Coarsening level{ fromEdges, g, p.CoarseningLevels, p.UniformSpacing };
  t0 = Clock::now();
  PlaceBoundaryNodes(g, p.BoundarySpacing, level, nodes);
  for (std::int64_t t : kept)
  {
    int i, j, k;
    Coordinates(g, edgePoints[t], i, j, k);
    nodes.Add(i, j, k, NodeType::Canny, static_cast<float>(radii[t]));
  }
  out.StepSeconds.emplace_back("boundary", SecondsSince(t0));

  // 4. Halftoning points, away from edges.
  const int h = p.ExclusionWindow / 2;
  if (p.Halftoning && !PlaceHalftoneNodes(image, f, work, g, p, floors.Feature, fromEdges, allCanny, parallel, progress, out, nodes))
  {
    out.Aborted = true;
    return out;
  }

  // 5. Uniform lattice points.
  t0 = Clock::now();
  PlaceUniformNodes(g, p.UniformSpacing, h, out.EdgeMap, level, nodes);
  out.StepSeconds.emplace_back("uniform", SecondsSince(t0));
  progress(1.0);
  return out;
}
} // namespace featuremesh
