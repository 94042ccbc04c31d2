// Unit tests of the Imaging library (Canny, PCA, halftoning, noise, kernels, Feature Nodes, RSP).
#include "Canny.h"
#include "EdgeSampling.h"
#include "FeatureNodes.h"
#include "Halftoning.h"
#include "ImageFilters.h"
#include "RSPEdgeEnhancement.h"
#include "TestHelpers.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <thread>

using namespace featuremesh;
using namespace featuremesh_test;

TEST(LocalContrast, IgnoresGainAndOffsetAndMarksTheDisk)
{
  const ImageGeometry g = Grid2(48, 48);
  const std::vector<float> disk = Disk(g, 24, 24, 8);
  std::vector<float> scaled(disk.size());
  for (std::size_t v = 0; v < disk.size(); ++v)
    scaled[v] = 3.0f * disk[v] - 500.0f;
  std::vector<float> a(disk.size()), b(disk.size());
  LocalContrast(disk.data(), a.data(), g, 6.0, SerialFor());
  LocalContrast(scaled.data(), b.data(), g, 6.0, Chunked);
  for (std::size_t v = 0; v < disk.size(); ++v)
    EXPECT_NEAR(a[v], b[v], 1e-3) << v;
  EXPECT_GT(a[g.Index(24, 24, 0)], 0.5f);
  EXPECT_LT(a[g.Index(24, 34, 0)], -0.5f);
  // A constant image has no contrast (and no 0 / 0).
  const std::vector<float> flat(disk.size(), 7.0f);
  LocalContrast(flat.data(), a.data(), g, 6.0, SerialFor());
  for (float x : a)
    EXPECT_EQ(x, 0.0f);
}

TEST(Canny, DiskGivesRingAtRadius)
{
  const ImageGeometry g = Grid2(64, 64);
  const std::vector<float> raw = Disk(g, 31.5, 31.5, 15.0);
  std::vector<float> f(raw.size());
  GaussianSmooth(raw.data(), f.data(), g, 0.7, SerialFor());
  const std::vector<std::uint8_t> edges = CannyEdges(f.data(), g, 0.1, 0.6, 99.0, SerialFor());
  int count = 0;
  for (int j = 0; j < 64; ++j)
    for (int i = 0; i < 64; ++i)
      if (edges[g.Index(i, j, 0)])
      {
        ++count;
        EXPECT_NEAR(std::hypot(i - 31.5, j - 31.5), 15.0, 1.0) << "edge at " << i << "," << j;
      }
  // A closed ring: about the circumference in pixels.
  EXPECT_GT(count, 0.6 * 2 * M_PI * 15);
}

TEST(Canny, ConstantImageHasNoEdges)
{
  const ImageGeometry g = Grid2(32, 32);
  std::vector<float> f(g.Size(), 5.f);
  const auto edges = CannyEdges(f.data(), g, 0.1, 0.6, 99.0, SerialFor());
  for (auto e : edges)
    EXPECT_EQ(e, 0);
}

TEST(PCA, TightCornerIsDenseAndStraightLineSparse)
{
  const ImageGeometry g = Grid2(64, 64);
  FeatureNodeParameters p;
  std::vector<std::uint8_t> map(g.Size(), 0);
  // A straight line; a tight hairpin corner (a 3x3 closed contour, the edge of a speck); and a
  // right-angle L with 6-pixel arms, which the thesis's ratio classes call straight (ratio 0.26 in
  // an 11x11 window: (var - |cov|) / (var + |cov|)).
  for (int i = 2; i < 30; ++i)
    map[g.Index(i, 10, 0)] = 1;
  for (int j = 40; j <= 42; ++j)
    for (int i = 40; i <= 42; ++i)
      map[g.Index(i, j, 0)] = (i == 41 && j == 41) ? 0 : 1;
  for (int t = 0; t < 6; ++t)
  {
    map[g.Index(10 + t, 50, 0)] = 1;
    map[g.Index(10, 50 + t, 0)] = 1;
  }
  const std::vector<std::int64_t> pts = { g.Index(15, 10, 0), g.Index(40, 40, 0), g.Index(10, 50, 0) };
  const auto radii = EdgeSampleRadii(pts, map, g, p, SerialFor());
  EXPECT_EQ(radii[0], 5);
  EXPECT_EQ(radii[1], 1);
  EXPECT_EQ(radii[2], 5);
}

TEST(PCA, ThinningKeepsCornerAndSpacesLine)
{
  const ImageGeometry g = Grid2(64, 64);
  std::vector<std::int64_t> pts;
  std::vector<std::uint8_t> radii;
  for (int i = 0; i < 30; ++i)
  {
    pts.push_back(g.Index(i, 10, 0));
    radii.push_back(i == 12 ? 1 : 5);
  }
  const auto kept = ThinEdgePoints(pts, radii, g);
  // The curved point goes first, and no two kept points lie within 5 of each other otherwise.
  ASSERT_FALSE(kept.empty());
  EXPECT_EQ(kept[0], 12);
  EXPECT_LE(kept.size(), 30u / 5 + 2);
  EXPECT_GE(kept.size(), 30u / 6);
}

TEST(PCA, ThinningMatchesTheGreedyDefinition)
{
  // Random 3D points, radii up to 4 (the distance-map path) and up to 12 (the bucket-grid path),
  // against the O(n^2) definition: visit by (radius, index); keep a point when no kept point lies
  // within its (2R+1)-box. Radii are in voxels of the median axis: with slices half as thick as
  // the in-plane spacing the box spans (2R+1) x (2R+1) x (4R+1) voxels.
  ImageGeometry g;
  g.Dims = { { 40, 30, 20 } };
  std::mt19937 rng(3);
  for (const int thin : { 1, 2 })
  for (int largest : { 4, 12 })
  {
    g.Spacing = { { 1.0, 1.0, 1.0 / thin } };
    ASSERT_EQ(g.MedianVoxelFactors()[2], thin);
    std::vector<std::int64_t> pts;
    std::vector<std::uint8_t> radii;
    std::uniform_int_distribution<std::int64_t> voxel(0, g.Size() - 1);
    std::uniform_int_distribution<int> radius(0, largest);
    std::vector<char> used(g.Size(), 0);
    while (pts.size() < 600)
    {
      const std::int64_t v = voxel(rng);
      if (!used[v]++)
      {
        pts.push_back(v);
        radii.push_back(static_cast<std::uint8_t>(radius(rng)));
      }
    }
    std::vector<std::int64_t> order(pts.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](std::int64_t a, std::int64_t b) { return radii[a] < radii[b]; });
    auto xyz = [&](std::int64_t v) {
      return std::array<std::int64_t, 3>{ { v % 40, (v / 40) % 30, v / 1200 } };
    };
    std::vector<std::int64_t> want;
    for (std::int64_t t : order)
    {
      bool blocked = false;
      for (std::int64_t q : want)
      {
        const auto a = xyz(pts[t]), b = xyz(pts[q]);
        blocked |= std::abs(a[0] - b[0]) <= radii[t] && std::abs(a[1] - b[1]) <= radii[t] &&
          std::abs(a[2] - b[2]) <= thin * radii[t];
      }
      if (!blocked)
      {
        want.push_back(t);
      }
    }
    EXPECT_EQ(ThinEdgePoints(pts, radii, g), want) << "radii up to " << largest << ", slices 1/" << thin;
  }
}

TEST(Halftone, CountFallsAsThresholdRises)
{
  const ImageGeometry g = Grid2(128, 128);
  std::vector<float> rho(g.Size());
  for (int j = 0; j < 128; ++j)
    for (int i = 0; i < 128; ++i)
      rho[g.Index(i, j, 0)] = static_cast<float>(i) / 255.f;
  size_t previous = SIZE_MAX;
  for (double q : { 0.1, 0.2, 0.3, 0.5, 0.7, 0.9 })
  {
    const size_t n = Halftone(rho.data(), g, q).size();
    EXPECT_LT(n, previous) << "q = " << q;
    previous = n;
  }
}

// Slices thinner than the pixel: the dots are those of the median-axis grid (runs of m voxels as
// one cell of their mean), each at its run's largest value, so a constant map gives as many dots
// per mm^3 as on cubic voxels instead of m times as many.
TEST(Halftone, ThinSlicesHaveTheDotsOfTheMedianAxisGrid)
{
  ImageGeometry g;
  g.Dims = { { 24, 20, 41 } }; // an odd slice count: the last run is one voxel
  g.Spacing = { { 1.0, 1.0, 0.5 } };
  ASSERT_EQ(g.MedianVoxelFactors(), (std::array<int, 3>{ { 1, 1, 2 } }));
  ImageGeometry cells = g;
  cells.Dims[2] = 21;
  cells.Spacing[2] = 1.0;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.f, 0.6f);
  std::vector<float> rho(g.Size());
  for (float& r : rho)
    r = u(rng);
  std::vector<float> mean(cells.Size());
  std::vector<std::int64_t> peak(cells.Size());
  for (int k = 0; k < cells.Dims[2]; ++k)
    for (int j = 0; j < g.Dims[1]; ++j)
      for (int i = 0; i < g.Dims[0]; ++i)
      {
        const std::int64_t a = g.Index(i, j, 2 * k), c = cells.Index(i, j, k);
        const bool pair = 2 * k + 1 < g.Dims[2];
        const std::int64_t b = pair ? g.Index(i, j, 2 * k + 1) : a;
        mean[c] = pair ? (rho[a] + rho[b]) / 2.f : rho[a];
        peak[c] = rho[b] > rho[a] ? b : a;
      }
  for (double q : { 0.3, 0.5 })
  {
    std::vector<std::int64_t> want;
    for (std::int64_t d : Halftone(mean.data(), cells, q))
      want.push_back(peak[d]);
    std::sort(want.begin(), want.end());
    EXPECT_EQ(HalftoneInMedianVoxels(rho.data(), g, q), want) << "q = " << q;
  }
  const std::vector<float> flat(g.Size(), 0.25f), flatCells(cells.Size(), 0.25f);
  const std::size_t thin = HalftoneInMedianVoxels(flat.data(), g, 0.3).size();
  EXPECT_EQ(thin, Halftone(flatCells.data(), cells, 0.3).size());
  EXPECT_GT(Halftone(flat.data(), g, 0.3).size(), 3 * thin / 2) << "the voxel grid's dots are denser across thin slices";
  // Cubic voxels keep the voxel grid's dots.
  ImageGeometry cubic = g;
  cubic.Spacing[2] = 1.0;
  EXPECT_EQ(HalftoneInMedianVoxels(rho.data(), cubic, 0.3), Halftone(rho.data(), cubic, 0.3));
}

TEST(Hessian, LargestAbsEigenvalueMatchesEigen)
{
  // Random symmetric matrices plus the degenerate cases of the closed form: zero, multiples of
  // the identity, double roots (r = -1 and r = 1) and rank one.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-100.0, 100.0);
  std::vector<std::array<double, 6>> cases = { { 0, 0, 0, 0, 0, 0 }, { 3, 3, 3, 0, 0, 0 }, { -2, -2, -2, 0, 0, 0 },
    { 5, 5, -1, 0, 0, 0 }, { 1, -4, -4, 0, 0, 0 }, { 1, 1, 1, 1, 1, 1 }, { 1e-3, 0, 0, 0, 0, 0 } };
  for (int t = 0; t < 20000; ++t)
  {
    cases.push_back({ { u(rng), u(rng), u(rng), u(rng), u(rng), u(rng) } });
  }
  for (const auto& a : cases)
  {
    Eigen::Matrix3d m;
    m << a[0], a[3], a[4], a[3], a[1], a[5], a[4], a[5], a[2];
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(m, Eigen::EigenvaluesOnly);
    const double want = es.eigenvalues().cwiseAbs().maxCoeff();
    const double got = LargestAbsEigenvalue(static_cast<float>(a[0]), static_cast<float>(a[1]),
      static_cast<float>(a[2]), static_cast<float>(a[3]), static_cast<float>(a[4]), static_cast<float>(a[5]));
    EXPECT_NEAR(got, want, 1e-5 * std::max(1.0, m.norm())) << a[0] << " " << a[1] << " " << a[2] << " " << a[3]
                                                           << " " << a[4] << " " << a[5];
  }
}

TEST(FeatureNodes, CornersAreNodesAndOneNodePerVoxel)
{
  const ImageGeometry g = Grid2(50, 40);
  const std::vector<float> f = Disk(g, 25, 20, 10);
  FeatureNodeParameters p;
  p.GaussianSigma = p.HessianSigma = 0.0; // the disk is used as it is
  const auto r = ComputeFeatureNodes(f.data(), nullptr, g, p, SerialFor(), NoProgress());
  std::vector<int> seen(g.Size(), 0);
  for (const auto& x : r.Positions)
    EXPECT_EQ(seen[g.Index(x[0], x[1], x[2])]++, 0);
  EXPECT_EQ(seen[g.Index(0, 0, 0)], 1);
  EXPECT_EQ(seen[g.Index(49, 0, 0)], 1);
  EXPECT_EQ(seen[g.Index(0, 39, 0)], 1);
  EXPECT_EQ(seen[g.Index(49, 39, 0)], 1);
  EXPECT_GT(r.Counts[int(NodeType::Canny)], 0);
}

namespace
{
// The smallest gap in voxels between two uniform nodes on one line along each axis (2^30: none).
std::array<int, 3> UniformGaps(const FeatureNodeResult& r)
{
  std::array<int, 3> gap{ { 1 << 30, 1 << 30, 1 << 30 } };
  for (std::size_t m = 0; m < r.Positions.size(); ++m)
    for (std::size_t n = 0; n < r.Positions.size(); ++n)
    {
      if (r.Type[m] != NodeType::Uniform || r.Type[n] != NodeType::Uniform)
        continue;
      const auto &x = r.Positions[m], &y = r.Positions[n];
      for (int a = 0; a < 3; ++a)
        if (y[a] > x[a] && y[(a + 1) % 3] == x[(a + 1) % 3] && y[(a + 2) % 3] == x[(a + 2) % 3])
          gap[a] = std::min(gap[a], y[a] - x[a]);
    }
  return gap;
}
} // namespace

TEST(FeatureNodes, LatticesAreEvenInWorldUnitsOnThickSlices)
{
  // A constant volume (boundary and uniform nodes only) of 3 x 3 x 12 mm voxels, as a thick-slice
  // CT: along every box edge the boundary nodes' gaps, and the uniform lattice's, are about as
  // long in mm on each axis as the spacing in voxels of the finest axis (7 x 3 mm); steps in
  // voxels on every axis gave 7 x 12 mm across the slices.
  ImageGeometry g;
  g.Dims = { { 60, 50, 12 } };
  g.Spacing = { { 3.0, 3.0, 12.0 } };
  const std::vector<float> f(g.Size(), 10.f);
  FeatureNodeParameters p;
  const auto r = ComputeFeatureNodes(f.data(), nullptr, g, p, SerialFor(), NoProgress());
  ASSERT_EQ(r.Counts[int(NodeType::Canny)], 0);
  // Largest gap (mm) between boundary nodes on the box edge along axis a (the other two at 0).
  auto edgeGap = [&](int a) {
    std::vector<int> at;
    for (std::size_t n = 0; n < r.Positions.size(); ++n)
    {
      const auto& x = r.Positions[n];
      if (r.Type[n] == NodeType::Boundary && x[(a + 1) % 3] == 0 && x[(a + 2) % 3] == 0)
        at.push_back(x[a]);
    }
    std::sort(at.begin(), at.end());
    int gap = 0;
    for (std::size_t k = 1; k < at.size(); ++k)
      gap = std::max(gap, at[k] - at[k - 1]);
    return gap * g.Spacing[a];
  };
  const double mean = 3.0 * p.BoundarySpacing; // 21 mm
  for (int a = 0; a < 3; ++a)
  {
    EXPECT_GT(edgeGap(a), 0.6 * mean) << "axis " << a;
    EXPECT_LT(edgeGap(a), 1.4 * mean) << "axis " << a;
  }
  // The uniform lattice: the smallest gap between two uniform nodes on one line along each axis.
  const std::array<int, 3> gaps = UniformGaps(r);
  for (int a = 0; a < 3; ++a)
  {
    EXPECT_GT(gaps[a] * g.Spacing[a], 0.6 * mean) << "axis " << a;
    EXPECT_LT(gaps[a] * g.Spacing[a], 1.4 * mean) << "axis " << a;
  }
  // Isotropic voxels of any size keep the step in voxels.
  g.Spacing = { { 0.7, 0.7, 0.7 } };
  const auto iso = ComputeFeatureNodes(f.data(), nullptr, g, p, SerialFor(), NoProgress());
  int lastX = -1;
  for (std::size_t n = 0; n < iso.Positions.size(); ++n)
    if (iso.Type[n] == NodeType::Uniform && iso.Positions[n][1] == iso.Positions[0][1] && iso.Positions[n][2] == iso.Positions[0][2])
    {
      if (lastX >= 0)
        EXPECT_EQ(iso.Positions[n][0] - lastX, p.UniformSpacing);
      lastX = iso.Positions[n][0];
    }
  // One axis thinner than the other two (0.7 x 0.7 x 0.35 mm, as a volume resampled to as many
  // voxels on each axis): the uniform lattice keeps the step in voxels of the other two axes, and its
  // step across the thin one is as long in mm. Steps in voxels of the finest axis halved the other
  // two axes' steps (about four times the nodes). (A box deep enough on every axis for uniform nodes
  // beyond the boundary nodes' window.)
  g.Dims = { { 60, 50, 60 } };
  const std::vector<float> deep(g.Size(), 10.f);
  auto uniformGaps = [&](const std::array<double, 3>& spacing, std::int64_t& count) {
    g.Spacing = spacing;
    const auto r2 = ComputeFeatureNodes(deep.data(), nullptr, g, p, SerialFor(), NoProgress());
    count = r2.Counts[int(NodeType::Uniform)];
    return UniformGaps(r2);
  };
  std::int64_t isoCount = 0, thinCount = 0;
  const std::array<int, 3> isoGap = uniformGaps({ { 0.7, 0.7, 0.7 } }, isoCount);
  const std::array<int, 3> thinGap = uniformGaps({ { 0.7, 0.7, 0.35 } }, thinCount);
  ASSERT_GT(isoCount, 0);
  ASSERT_GT(thinCount, 0);
  for (int a = 0; a < 3; ++a)
    EXPECT_EQ(isoGap[a], p.UniformSpacing) << "axis " << a;
  EXPECT_EQ(thinGap[0], p.UniformSpacing);
  EXPECT_EQ(thinGap[1], p.UniformSpacing);
  EXPECT_EQ(thinGap[2], 2 * p.UniformSpacing);
  EXPECT_LE(thinCount, isoCount);
}

TEST(FeatureNodes, VolumeNodesDoNotDependOnHowLoopsAreSplit)
{
  // A noisy ball in a box: the 3D paths (slice-blocked Gaussian, 26-connected hysteresis, packed
  // PCA rows, 3D halftone). A parallel-for that runs small chunks in reverse order stands in for
  // threads; results must equal the serial run bit for bit.
  ImageGeometry g;
  g.Dims = { { 37, 29, 23 } };
  std::vector<float> f(g.Size());
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.f, 3.f);
  for (int k = 0; k < g.Dims[2]; ++k)
    for (int j = 0; j < g.Dims[1]; ++j)
      for (int i = 0; i < g.Dims[0]; ++i)
        f[g.Index(i, j, k)] = (std::hypot(i - 18.0, j - 14.0, k - 11.0) <= 8.0 ? 100.f : 20.f) + noise(rng);
  const ParallelFor chunked = [](std::int64_t n, std::int64_t, const RangeFunction& body) {
    for (std::int64_t b = ((n - 1) / 3) * 3; b >= 0; b -= 3)
      body(b, std::min(n, b + 3));
  };
  FeatureNodeParameters p;
  const auto serial = ComputeFeatureNodes(f.data(), nullptr, g, p, SerialFor(), NoProgress());
  const auto split = ComputeFeatureNodes(f.data(), nullptr, g, p, chunked, NoProgress());
  EXPECT_EQ(serial.Positions, split.Positions);
  EXPECT_EQ(serial.Type, split.Type);
  EXPECT_EQ(serial.EdgeMap, split.EdgeMap);
  EXPECT_GT(serial.Counts[int(NodeType::Canny)], 20);
  std::vector<int> seen(g.Size(), 0);
  for (const auto& x : serial.Positions)
    EXPECT_EQ(seen[g.Index(x[0], x[1], x[2])]++, 0);
  for (int k : { 0, 22 })
    for (int j : { 0, 28 })
      for (int i : { 0, 36 })
        EXPECT_EQ(seen[g.Index(i, j, k)], 1);
  // Canny nodes lie on the ball's surface (within a voxel and a half).
  for (size_t t = 0; t < serial.Positions.size(); ++t)
  {
    if (serial.Type[t] != NodeType::Canny)
      continue;
    const auto& x = serial.Positions[t];
    EXPECT_NEAR(std::hypot(x[0] - 18.0, x[1] - 14.0, x[2] - 11.0), 8.0, 1.5);
  }
}

namespace
{
// A ball (2D: disk) of 100 on 10, plus white Gaussian noise of deviation `noise` (Box-Muller on
// mt19937: the same numbers on every platform).
std::vector<float> NoisyBall(const ImageGeometry& g, double noise, unsigned seed)
{
  std::mt19937 rng(seed);
  auto unit = [&rng]() { return (static_cast<double>(rng()) + 0.5) / 4294967296.0; };
  const double c[3] = { 0.5 * (g.Dims[0] - 1), 0.5 * (g.Dims[1] - 1), 0.5 * (g.Dims[2] - 1) };
  const double r = 0.3 * std::min(g.Dims[0], g.Dims[1]);
  std::vector<float> f(g.Size());
  for (int k = 0; k < g.Dims[2]; ++k)
    for (int j = 0; j < g.Dims[1]; ++j)
      for (int i = 0; i < g.Dims[0]; ++i)
      {
        const double d = std::sqrt((i - c[0]) * (i - c[0]) + (j - c[1]) * (j - c[1]) + (k - c[2]) * (k - c[2]));
        const double gauss = std::sqrt(-2.0 * std::log(unit())) * std::cos(2.0 * 3.14159265358979323846 * unit());
        f[g.Index(i, j, k)] = static_cast<float>((d <= r ? 100.0 : 10.0) + noise * gauss);
      }
  return f;
}
} // namespace

// The noise estimate: 0 on a clean piecewise-constant image, within 5 % of the truth under noise
// (edges take a few blocks); and the filtered noise's deviation is what the filters give.
TEST(Noise, EstimateOfAClean2DAnd3DBallAndOfItsNoise)
{
  for (int dimension : { 2, 3 })
  {
    ImageGeometry g;
    g.Dims = dimension == 2 ? std::array<int, 3>{ { 200, 180, 1 } } : std::array<int, 3>{ { 60, 56, 50 } };
    EXPECT_EQ(EstimateNoiseSigma(NoisyBall(g, 0.0, 1).data(), g, SerialFor()), 0.0);
    for (double noise : { 2.0, 15.0 })
    {
      const std::vector<float> f = NoisyBall(g, noise, 2);
      EXPECT_NEAR(EstimateNoiseSigma(f.data(), g, SerialFor()), noise, 0.05 * noise) << dimension << "D";
      const ParallelFor split = [](std::int64_t n, std::int64_t, const RangeFunction& body) {
        for (std::int64_t b = 0; b < n; b += 7)
          body(b, std::min(n, b + 7));
      };
      EXPECT_EQ(EstimateNoiseSigma(f.data(), g, split), EstimateNoiseSigma(f.data(), g, SerialFor()));
    }
  }
}

TEST(Noise, FilteredDeviationMatchesGaussianAndCentralDifferences)
{
  const ImageGeometry g = Grid2(400, 400);
  std::vector<float> noise = NoisyBall(g, 1.0, 3);
  for (float& v : noise)
    v -= (v > 50.f ? 100.f : 10.f); // the noise alone
  for (double sigma : { 0.0, 0.7, 2.0 })
  {
    std::vector<float> f(noise.size());
    GaussianSmooth(noise.data(), f.data(), g, sigma, SerialFor());
    double gx = 0.0, hxx = 0.0;
    std::int64_t count = 0;
    for (int j = 10; j < g.Dims[1] - 10; ++j)
      for (int i = 10; i < g.Dims[0] - 10; ++i)
      {
        const float* c = f.data() + g.Index(i, j, 0);
        gx += std::pow(0.5 * (c[1] - c[-1]), 2);
        hxx += std::pow(c[1] - 2.0 * c[0] + c[-1], 2);
        ++count;
      }
    EXPECT_NEAR(std::sqrt(gx / count), FilteredNoiseDeviation(2, sigma, { 0.5, 0.0, -0.5 }),
      0.03 * FilteredNoiseDeviation(2, sigma, { 0.5, 0.0, -0.5 })) << sigma;
    EXPECT_NEAR(std::sqrt(hxx / count), FilteredNoiseDeviation(2, sigma, { 1.0, -2.0, 1.0 }),
      0.03 * FilteredNoiseDeviation(2, sigma, { 1.0, -2.0, 1.0 })) << sigma;
  }
}

// Noise must not set the node count (issue 15: a noisy 512^3 phantom gave 3.3 M nodes): with the
// noise floor a noisy ball (contrast 90, noise 25 and 40) has no more nodes than the clean ball,
// and its Canny nodes lie on the sphere (the border's noisier gradient too), not in the noise; the
// clean ball gets the same nodes as without the floor. Without it the same noise multiplies the
// nodes, most of them Canny nodes in the noise.
TEST(Noise, NodeCountDoesNotExplodeWithNoise)
{
  for (int dimension : { 2, 3 })
  {
    ImageGeometry g;
    g.Dims = dimension == 2 ? std::array<int, 3>{ { 256, 240, 1 } } : std::array<int, 3>{ { 64, 60, 56 } };
    FeatureNodeParameters p, off;
    off.NoiseFloor = false;
    const std::vector<float> clean = NoisyBall(g, 0.0, 4);
    const FeatureNodeResult a = ComputeFeatureNodes(clean.data(), nullptr, g, p, SerialFor(), NoProgress());
    const FeatureNodeResult b = ComputeFeatureNodes(clean.data(), nullptr, g, off, SerialFor(), NoProgress());
    EXPECT_EQ(a.NoiseSigma, 0.0);
    EXPECT_EQ(a.Positions, b.Positions);
    const double nodes = static_cast<double>(a.Positions.size());
    const double c[3] = { 0.5 * (g.Dims[0] - 1), 0.5 * (g.Dims[1] - 1), 0.5 * (g.Dims[2] - 1) };
    const double r = 0.3 * std::min(g.Dims[0], g.Dims[1]);
    for (double noise : { 25.0, 40.0 })
    {
      const std::vector<float> f = NoisyBall(g, noise, 5);
      const FeatureNodeResult floor = ComputeFeatureNodes(f.data(), nullptr, g, p, SerialFor(), NoProgress());
      const FeatureNodeResult thesis = ComputeFeatureNodes(f.data(), nullptr, g, off, SerialFor(), NoProgress());
      EXPECT_NEAR(floor.NoiseSigma, noise, 0.05 * noise);
      EXPECT_LT(floor.Positions.size(), 1.2 * nodes) << dimension << "D, noise " << noise;
      EXPECT_GT(thesis.Positions.size(), 1.5 * nodes) << "the noise no longer tests the floor: " << dimension << "D";
      // Share of a result's Canny nodes within 2 voxels of the sphere.
      auto onSphere = [&](const FeatureNodeResult& result) {
        std::int64_t canny = 0, on = 0;
        for (std::size_t n = 0; n < result.Positions.size(); ++n)
        {
          if (result.Type[n] != NodeType::Canny)
            continue;
          const auto& q = result.Positions[n];
          const double d = std::sqrt((q[0] - c[0]) * (q[0] - c[0]) + (q[1] - c[1]) * (q[1] - c[1]) + (q[2] - c[2]) * (q[2] - c[2]));
          ++canny;
          on += std::fabs(d - r) <= 2.0 ? 1 : 0;
        }
        return canny ? static_cast<double>(on) / canny : 0.0;
      };
      EXPECT_GT(floor.Counts[static_cast<int>(NodeType::Canny)], 0) << dimension << "D, noise " << noise;
      EXPECT_GE(onSphere(floor), 0.75) << dimension << "D, noise " << noise;
      EXPECT_LT(onSphere(thesis), 0.5) << "the noise no longer tests the floor: " << dimension << "D";
    }
  }
}

TEST(Parameters, OutOfOrderThresholdsAreRejected)
{
  FeatureNodeParameters p;
  p.LowThreshold = 0.7;
  p.HighThreshold = 0.6;
  EXPECT_FALSE(ValidateParameters(p).empty());
}

//------------------------------------------------------------------------------------------------
// Fast paths against naive references: each kernel's fast path claims the same sums in the same
// order as the plain definition, so the comparisons are exact.
namespace
{

// Noise with flat rows, a flat slab and a plateau: every shortcut of the kernels gets used.
std::vector<float> TestVolume(const ImageGeometry& g, unsigned seed)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 100.f);
  std::vector<float> f(g.Size());
  for (int k = 0; k < g.Dims[2]; ++k)
    for (int j = 0; j < g.Dims[1]; ++j)
      for (int i = 0; i < g.Dims[0]; ++i)
      {
        float v = u(rng);
        if (j % 5 == 0 || (g.Dims[2] > 2 && k == 1))
          v = 42.f; // flat rows, a flat slice
        else if (std::hypot(i - g.Dims[0] / 2.0, j - g.Dims[1] / 2.0) < 4.0)
          v = 90.f; // a plateau: ties for non-maximum suppression
        f[g.Index(i, j, k)] = v;
      }
  return f;
}

std::vector<ImageGeometry> TestGrids()
{
  ImageGeometry a, b, c;
  a.Dims = { { 37, 29, 1 } };
  b.Dims = { { 23, 19, 17 } };
  c.Dims = { { 2, 9, 5 } }; // rows too short for an interior
  return { a, b, c };
}

int Clamp(int v, int n)
{
  return std::min(n - 1, std::max(0, v));
}

std::vector<float> NaiveGaussian(const std::vector<float>& in, const ImageGeometry& g, double sigma)
{
  const std::vector<float> w = GaussianKernel(sigma);
  const int r = static_cast<int>(w.size() / 2);
  std::vector<float> cur = in, next(in.size());
  for (int axis = 0; axis < (g.Is2D() ? 2 : 3); ++axis)
  {
    for (int k = 0; k < g.Dims[2]; ++k)
      for (int j = 0; j < g.Dims[1]; ++j)
        for (int i = 0; i < g.Dims[0]; ++i)
        {
          float acc = 0.f;
          for (int t = -r; t <= r; ++t)
          {
            int ijk[3] = { i, j, k };
            ijk[axis] = Clamp(ijk[axis] + t, g.Dims[axis]);
            acc += w[t + r] * cur[g.Index(ijk[0], ijk[1], ijk[2])];
          }
          next[g.Index(i, j, k)] = acc;
        }
    std::swap(cur, next);
  }
  return cur;
}

// Central differences, one-sided on the border, zero along a one-voxel axis.
std::array<float, 3> NaiveGradient(const std::vector<float>& f, const ImageGeometry& g, int i, int j, int k)
{
  std::array<float, 3> d{};
  const int c[3] = { i, j, k };
  for (int a = 0; a < 3; ++a)
  {
    if (g.Dims[a] < 2)
      continue;
    int lo[3] = { i, j, k }, hi[3] = { i, j, k };
    lo[a] = std::max(0, c[a] - 1);
    hi[a] = std::min(g.Dims[a] - 1, c[a] + 1);
    const float diff = f[g.Index(hi[0], hi[1], hi[2])] - f[g.Index(lo[0], lo[1], lo[2])];
    d[a] = hi[a] - lo[a] == 2 ? 0.5f * diff : diff;
  }
  return d;
}
} // namespace

TEST(Kernels, GaussianMatchesTheSeparableDefinition)
{
  for (const ImageGeometry& g : TestGrids())
    for (double sigma : { 0.7, 2.0 })
    {
      const std::vector<float> f = TestVolume(g, 11);
      std::vector<float> fast(f.size());
      GaussianSmooth(f.data(), fast.data(), g, sigma, Chunked);
      EXPECT_EQ(fast, NaiveGaussian(f, g, sigma)) << g.Dims[0] << "x" << g.Dims[1] << "x" << g.Dims[2] << " sigma " << sigma;
    }
}

TEST(Kernels, GradientMagnitudeInteriorMatchesBorderDefinition)
{
  for (const ImageGeometry& g : TestGrids())
  {
    const std::vector<float> f = TestVolume(g, 12);
    std::vector<float> fast(f.size());
    GradientMagnitude(f.data(), g, fast.data(), Chunked);
    for (int k = 0; k < g.Dims[2]; ++k)
      for (int j = 0; j < g.Dims[1]; ++j)
        for (int i = 0; i < g.Dims[0]; ++i)
        {
          const auto d = NaiveGradient(f, g, i, j, k);
          ASSERT_EQ(fast[g.Index(i, j, k)], std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])) << i << "," << j << "," << k;
        }
  }
}

TEST(Kernels, CannyMatchesPlainSuppressionAndFloodFill)
{
  for (const ImageGeometry& g : TestGrids())
  {
    std::vector<float> f(g.Size());
    GaussianSmooth(TestVolume(g, 13).data(), f.data(), g, 0.7, SerialFor());
    const double low = 0.1, high = 0.6, percentile = 99.0;
    double gmax = 0.0;
    const std::vector<std::uint8_t> fast = CannyEdges(f.data(), g, low, high, percentile, Chunked, &gmax);
    // Plain: magnitude, suppression with bounds checks everywhere, 8-/26-connected flood fill.
    std::vector<float> mag(g.Size());
    for (int k = 0; k < g.Dims[2]; ++k)
      for (int j = 0; j < g.Dims[1]; ++j)
        for (int i = 0; i < g.Dims[0]; ++i)
        {
          const auto d = NaiveGradient(f, g, i, j, k);
          mag[g.Index(i, j, k)] = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        }
    ASSERT_EQ(gmax, RobustMaximum(mag.data(), g.Size(), percentile, SerialFor()));
    const float lowV = static_cast<float>(low * gmax), highV = static_cast<float>(high * gmax);
    std::vector<std::uint8_t> state(g.Size(), 0);
    for (int k = 0; k < g.Dims[2]; ++k)
      for (int j = 0; j < g.Dims[1]; ++j)
        for (int i = 0; i < g.Dims[0]; ++i)
        {
          const float m = mag[g.Index(i, j, k)];
          if (m < lowV || m <= 0.f)
            continue;
          const auto d = NaiveGradient(f, g, i, j, k);
          const float cut = 0.41421356f * std::max(std::fabs(d[0]), std::max(std::fabs(d[1]), std::fabs(d[2])));
          int s[3];
          for (int a = 0; a < 3; ++a)
            s[a] = std::fabs(d[a]) >= cut ? (d[a] > 0.f) - (d[a] < 0.f) : 0;
          const float ahead = g.Contains(i + s[0], j + s[1], k + s[2]) ? mag[g.Index(i + s[0], j + s[1], k + s[2])] : 0.f;
          const float behind = g.Contains(i - s[0], j - s[1], k - s[2]) ? mag[g.Index(i - s[0], j - s[1], k - s[2])] : 0.f;
          if (m > ahead && m >= behind)
            state[g.Index(i, j, k)] = m >= highV ? 2 : 1;
        }
    std::vector<std::uint8_t> edges(g.Size(), 0);
    std::vector<std::int64_t> queue;
    for (std::int64_t v = 0; v < g.Size(); ++v)
      if (state[v] == 2)
      {
        edges[v] = 1;
        queue.push_back(v);
      }
    while (!queue.empty())
    {
      const std::int64_t v = queue.back();
      queue.pop_back();
      const int k = static_cast<int>(v / g.SliceStride()), j = static_cast<int>(v / g.Dims[0] % g.Dims[1]),
                i = static_cast<int>(v % g.Dims[0]);
      for (int dk = -1; dk <= 1; ++dk)
        for (int dj = -1; dj <= 1; ++dj)
          for (int di = -1; di <= 1; ++di)
            if ((!g.Is2D() || dk == 0) && g.Contains(i + di, j + dj, k + dk))
            {
              const std::int64_t q = g.Index(i + di, j + dj, k + dk);
              if (state[q] && !edges[q])
              {
                edges[q] = 1;
                queue.push_back(q);
              }
            }
    }
    EXPECT_EQ(fast, edges) << g.Dims[0] << "x" << g.Dims[1] << "x" << g.Dims[2];
    EXPECT_GT(std::count(edges.begin(), edges.end(), 1), 3);
  }
}

TEST(Kernels, PCARadiiFromTableMatchPlainMoments)
{
  for (const ImageGeometry& g : TestGrids())
    for (int window : { 0, 9, 13, 15 }) // 0 = default (11 in 2D, 5 in 3D); 15 takes the plain path
    {
      std::mt19937 rng(14);
      std::vector<std::uint8_t> edgeMap(g.Size(), 0);
      std::vector<std::int64_t> points;
      for (std::int64_t v = 0; v < g.Size(); ++v)
        if (rng() % 10 < 3)
        {
          edgeMap[v] = 1;
          points.push_back(v);
        }
      FeatureNodeParameters p;
      p.CovarianceNeighbourhood = window;
      const std::vector<std::uint8_t> fast = EdgeSampleRadii(points, edgeMap, g, p, Chunked);
      const int w = window > 0 ? window : (g.Is2D() ? 11 : 5), h = w / 2;
      for (size_t t = 0; t < points.size(); ++t)
      {
        const std::int64_t v = points[t];
        const int k = static_cast<int>(v / g.SliceStride()), j = static_cast<int>(v / g.Dims[0] % g.Dims[1]),
                  i = static_cast<int>(v % g.Dims[0]);
        // Plain integer moments of the edge points in the box, relative to the centre.
        std::int64_t c = 0, s[3] = { 0, 0, 0 }, q[3][3] = {};
        for (int dk = -h; dk <= h; ++dk)
          for (int dj = -h; dj <= h; ++dj)
            for (int di = -h; di <= h; ++di)
              if (g.Contains(i + di, j + dj, k + dk) && edgeMap[g.Index(i + di, j + dj, k + dk)])
              {
                const std::int64_t x[3] = { di, dj, dk };
                ++c;
                for (int a = 0; a < 3; ++a)
                {
                  s[a] += x[a];
                  for (int b = 0; b < 3; ++b)
                    q[a][b] += x[a] * x[b];
                }
              }
        const std::int64_t moments[9] = { s[0], s[1], s[2], q[0][0], q[1][1], q[2][2], q[0][1], q[0][2], q[1][2] };
        ASSERT_EQ(fast[t], SamplingRadius(c, moments, g.Dimension(), p)) << "window " << w << " point " << i << "," << j << "," << k;
      }
    }
}

TEST(Kernels, HalftoneMatchesErrorDiffusionOnTheWholeVolume)
{
  for (const ImageGeometry& g : TestGrids())
    for (double q : { 0.3, 0.5 })
    {
      std::mt19937 rng(15);
      std::uniform_real_distribution<float> u(0.f, 1.f);
      std::vector<float> rho(g.Size());
      for (std::int64_t v = 0; v < g.Size(); ++v)
        rho[v] = v % 7 == 0 ? 1.f : (v % 11 < 4 ? 0.f : u(rng) * u(rng)); // saturated, empty, varied
      const std::vector<std::int64_t> fast = Halftone(rho.data(), g, q);
      // The definition on a volume-sized error buffer with bounds checks: classic Floyd-Steinberg
      // weights (halved in 3D, the other half to the next slice: centre 6/16, 4-neighbours 2.5/16),
      // a dot worth 2q, error clamped to +-2q, negligible error (< 1e-6) dropped.
      const float threshold = static_cast<float>(q), dot = static_cast<float>(2.0 * q);
      const float w = g.Is2D() ? 1.f : 0.5f;
      std::vector<float> e(g.Size(), 0.f);
      std::vector<std::int64_t> dots;
      auto push = [&](int i, int j, int k, float amount) {
        if (g.Contains(i, j, k))
          e[g.Index(i, j, k)] += amount;
      };
      for (int k = 0; k < g.Dims[2]; ++k)
        for (int j = 0; j < g.Dims[1]; ++j)
          for (int i = 0; i < g.Dims[0]; ++i)
          {
            const std::int64_t v = g.Index(i, j, k);
            const float value = rho[v] + e[v];
            if (std::fabs(value) < 1e-6f)
              continue;
            float err = value;
            if (value >= threshold)
            {
              dots.push_back(v);
              err = value - dot;
            }
            err = std::max(-dot, std::min(dot, err));
            push(i + 1, j, k, err * (w * (7.f / 16.f)));
            push(i - 1, j + 1, k, err * (w * (3.f / 16.f)));
            push(i, j + 1, k, err * (w * (5.f / 16.f)));
            push(i + 1, j + 1, k, err * (w * (1.f / 16.f)));
            if (!g.Is2D())
            {
              const float half = 0.5f * err, side = half * (2.5f / 16.f);
              push(i, j, k + 1, half * (6.f / 16.f));
              push(i - 1, j, k + 1, side);
              push(i + 1, j, k + 1, side);
              push(i, j - 1, k + 1, side);
              push(i, j + 1, k + 1, side);
            }
          }
      EXPECT_EQ(fast, dots) << g.Dims[0] << "x" << g.Dims[1] << "x" << g.Dims[2] << " q " << q;
      EXPECT_GT(dots.size(), 10u);
    }
}

//------------------------------------------------------------------------------------------------
// Guards: what a bad input does is an error or a correct result, never a NaN in the output.
TEST(Guards, ExtremeMagnitudesGiveTheSameNodes)
{
  ImageGeometry g = Grid2(64, 64);
  const std::vector<float> f = Disk(g, 30.5, 28.0, 14.0);
  FeatureNodeParameters p;
  const FeatureNodeResult plain = ComputeFeatureNodes(f.data(), nullptr, g, p, SerialFor(), NoProgress());
  for (int e : { 100, -100, 120 })
  {
    std::vector<float> scaled(f);
    for (float& v : scaled)
      v = std::ldexp(v, e);
    const FeatureNodeResult r = ComputeFeatureNodes(scaled.data(), nullptr, g, p, SerialFor(), NoProgress());
    EXPECT_EQ(r.Positions, plain.Positions) << "scaled by 2^" << e;
    EXPECT_EQ(r.Type, plain.Type);
  }
  // Steps near the float limit (gradients would overflow) still give edges on the disk.
  std::vector<float> huge(f);
  for (float& v : huge)
    v = v > 50.f ? 3e38f : -3e38f;
  const FeatureNodeResult r = ComputeFeatureNodes(huge.data(), nullptr, g, p, SerialFor(), NoProgress());
  EXPECT_GT(r.Counts[int(NodeType::Canny)], 10);
}

//------------------------------------------------------------------------------------------------
// Stage 5: RSP edge enhancement.
namespace
{
// A bright disk (radius r) on a dark background, with mild deterministic texture.
std::vector<float> DiskImage(const ImageGeometry& g, double cx, double cy, double r)
{
  std::vector<float> f(g.Size());
  for (int j = 0; j < g.Dims[1]; ++j)
    for (int i = 0; i < g.Dims[0]; ++i)
      f[g.Index(i, j, 0)] = (std::hypot(i - cx, j - cy) <= r ? 200.f : 40.f) + static_cast<float>((i * 7 + j * 13) % 5);
  return f;
}

// The stage on a 96^2 disk of radius 20 with two object and four background seeds.
RSPResult DiskRSP(const RSPParameters& p, const ParallelFor& parallel = SerialFor())
{
  ImageGeometry g = Grid2(96, 96);
  const std::vector<float> f = DiskImage(g, 48, 48, 20);
  const std::vector<std::int64_t> object{ g.Index(48, 48, 0), g.Index(40, 52, 0) };
  const std::vector<std::int64_t> background{ g.Index(20, 20, 0), g.Index(80, 30, 0), g.Index(48, 80, 0),
    g.Index(15, 60, 0) };
  return RSPEdgeEnhancement(f.data(), g, object, background, p, parallel, NoProgress());
}
} // namespace

TEST(RSPEdgeEnhancement, FastMarchingOnAConstantImageIsEuclidean)
{
  // 2D, a point source: first-order error grows like h log(r); 3D with spacing 2 along x.
  ImageGeometry g = Grid2(81, 81);
  std::vector<float> ones(g.Size(), 1.f);
  std::vector<float> T = FastMarching(ones.data(), g, { g.Index(40, 40, 0) }, 0.0);
  double worst = 0.0;
  for (int j = 0; j < 81; ++j)
    for (int i = 0; i < 81; ++i)
    {
      const double r = std::hypot(i - 40, j - 40), t = T[g.Index(i, j, 0)];
      EXPECT_GE(t, r - 1e-9);
      EXPECT_LE(t - r, 0.35 * (1.0 + std::log(1.0 + r))) << i << " " << j;
      if (r >= 20.0)
        worst = std::max(worst, (t - r) / r);
    }
  EXPECT_LT(worst, 0.05);
  EXPECT_DOUBLE_EQ(T[g.Index(70, 40, 0)], 30.0); // along an axis it is exact
  ImageGeometry g3;
  g3.Dims = { { 21, 31, 31 } };
  g3.Spacing = { { 2, 1, 1 } };
  std::vector<float> ones3(g3.Size(), 1.f);
  std::vector<float> T3 = FastMarching(ones3.data(), g3, { g3.Index(10, 15, 15) }, 0.0);
  EXPECT_DOUBLE_EQ(T3[g3.Index(20, 15, 15)], 20.0);
  EXPECT_DOUBLE_EQ(T3[g3.Index(10, 30, 15)], 15.0);
  const double r = std::sqrt(20.0 * 20.0 + 15.0 * 15.0 + 15.0 * 15.0);
  EXPECT_NEAR(T3[g3.Index(20, 30, 30)], r, 0.12 * r);
  // Marching stops past stopAt: farther voxels stay infinite.
  std::vector<float> Tstop = FastMarching(ones.data(), g, { g.Index(40, 40, 0) }, 10.0);
  EXPECT_TRUE(std::isinf(Tstop[g.Index(70, 40, 0)]));
  EXPECT_DOUBLE_EQ(Tstop[g.Index(50, 40, 0)], 10.0);
}

TEST(RSPEdgeEnhancement, PathsCrossATwoPlateauImageAtTheStep)
{
  ImageGeometry g = Grid2(64, 48);
  std::vector<float> f(g.Size());
  for (int j = 0; j < 48; ++j)
    for (int i = 0; i < 64; ++i)
      f[g.Index(i, j, 0)] = i < 32 ? 20.f : 220.f;
  RSPParameters p;
  p.GradientSigma = 0.0;
  const RSPResult r = RSPEdgeEnhancement(
    f.data(), g, { g.Index(8, 24, 0) }, { g.Index(56, 24, 0) }, p, SerialFor(), NoProgress());
  ASSERT_TRUE(r.Error.empty()) << r.Error;
  EXPECT_EQ(r.Paths, 50 * 100);
  // The brightest column is at the step, and the step's two columns carry far more than any other.
  std::vector<double> column(64, 0.0);
  for (int j = 0; j < 48; ++j)
    for (int i = 0; i < 64; ++i)
      column[i] += r.EdgeConfidence[g.Index(i, j, 0)];
  const int top = static_cast<int>(std::max_element(column.begin(), column.end()) - column.begin());
  EXPECT_TRUE(top == 31 || top == 32) << top;
  double other = 0.0;
  for (int i = 0; i < 64; ++i)
    if (i < 30 || i > 33)
      other = std::max(other, column[i]);
  EXPECT_GT(column[31] + column[32], 5.0 * other);
  // Every path crosses the step exactly where it is: each of the 5000 paths holds a voxel of
  // column 31 and one of column 32.
  EXPECT_GE(column[31], 5000.0);
  EXPECT_GE(column[32], 5000.0);
}

TEST(RSPEdgeEnhancement, SourcesFallInsideTheDiskAndSinksOutside)
{
  ImageGeometry g = Grid2(96, 96);
  RSPParameters p;
  const RSPResult r = DiskRSP(p);
  ASSERT_TRUE(r.Error.empty()) << r.Error;
  ASSERT_EQ(r.SourceVoxels.size(), 50u);
  ASSERT_EQ(r.SinkVoxels.size(), 100u);
  const auto inDisk = [&](std::int64_t v) { return std::hypot(v % 96 - 48.0, v / 96 - 48.0) <= 20.0; };
  const auto sourcesIn = std::count_if(r.SourceVoxels.begin(), r.SourceVoxels.end(), inDisk);
  const auto sinksOut = std::count_if(r.SinkVoxels.begin(), r.SinkVoxels.end(), [&](std::int64_t v) { return !inDisk(v); });
  EXPECT_GE(sourcesIn, 40); // >= 80 %
  EXPECT_GE(sinksOut, 80);
  // The sampler itself: on a map that is the distance from the centre, with T = 20, P(taken) falls
  // linearly with the distance: the density of the draws is r (1 - r / 20), 90 % of it within 16.
  std::vector<float> map(g.Size());
  for (std::int64_t v = 0; v < g.Size(); ++v)
    map[v] = static_cast<float>(std::hypot(v % 96 - 48.0, v / 96 - 48.0));
  const std::vector<std::int64_t> s = RejectionSample(map, 20.0, 200, 7);
  ASSERT_EQ(s.size(), 200u);
  const auto near = std::count_if(s.begin(), s.end(), [&](std::int64_t v) { return map[v] <= 16.f; });
  EXPECT_GE(near, 160);
  EXPECT_EQ(s, RejectionSample(map, 20.0, 200, 7));
  EXPECT_NE(s, RejectionSample(map, 20.0, 200, 8));
}

TEST(RSPEdgeEnhancement, EdgeConfidenceFollowsTheDiskAndTheContourClosesAroundIt)
{
  ImageGeometry g = Grid2(96, 96);
  RSPParameters p;
  const RSPResult r = DiskRSP(p);
  ASSERT_TRUE(r.Error.empty()) << r.Error;
  double nearSum = 0, farSum = 0;
  int nearCount = 0, farCount = 0;
  for (std::int64_t v = 0; v < g.Size(); ++v)
  {
    const double d = std::fabs(std::hypot(v % 96 - 48.0, v / 96 - 48.0) - 20.0);
    if (d <= 1.0)
      nearSum += r.EdgeConfidence[v], ++nearCount;
    else if (d > 5.0)
      farSum += r.EdgeConfidence[v], ++farCount;
  }
  EXPECT_GT(nearSum / nearCount, 5.0 * farSum / farCount);
  // The contour: consecutive voxels (and last to first) are 4-neighbours, no voxel twice.
  ASSERT_GT(r.Contour.size(), 20u);
  std::set<std::int64_t> seen;
  for (std::size_t i = 0; i < r.Contour.size(); ++i)
  {
    const std::int64_t a = r.Contour[i], b = r.Contour[(i + 1) % r.Contour.size()];
    EXPECT_EQ(std::abs(a % 96 - b % 96) + std::abs(a / 96 - b / 96), 1);
    EXPECT_TRUE(seen.insert(a).second);
  }
  std::int64_t both = 0, region = 0, disk = 0;
  for (std::int64_t v = 0; v < g.Size(); ++v)
  {
    const bool in = std::hypot(v % 96 - 48.0, v / 96 - 48.0) <= 20.0;
    both += in && r.Region[v];
    region += r.Region[v];
    disk += in;
  }
  EXPECT_GT(2.0 * both / (region + disk), 0.9);
  // Split-invariant: the same EC for any split of the sources.
  const RSPResult c = DiskRSP(p, Chunked);
  EXPECT_EQ(c.EdgeConfidence, r.EdgeConfidence);
  EXPECT_EQ(c.Contour, r.Contour);
  p.RandomSeed = 3;
  const RSPResult other = DiskRSP(p);
  EXPECT_NE(other.SourceVoxels, r.SourceVoxels);
}

TEST(RSPEdgeEnhancement, BadInputIsNamed)
{
  ImageGeometry g = Grid2(32, 32);
  std::vector<float> flat(g.Size(), 5.f);
  RSPParameters p;
  RSPResult r = RSPEdgeEnhancement(flat.data(), g, { 10 }, { 500 }, p, SerialFor(), NoProgress());
  EXPECT_NE(r.Error.find("constant"), std::string::npos) << r.Error;
  const std::vector<float> f = DiskImage(g, 16, 16, 8);
  r = RSPEdgeEnhancement(f.data(), g, { 10, 20 }, { 20 }, p, SerialFor(), NoProgress());
  EXPECT_NE(r.Error.find("both"), std::string::npos) << r.Error;
  r = RSPEdgeEnhancement(f.data(), g, {}, { 20 }, p, SerialFor(), NoProgress());
  EXPECT_FALSE(r.Error.empty());
  p.Sources = 0;
  EXPECT_FALSE(ValidateParameters(p).empty());
  p = RSPParameters();
  p.EdgeThreshold = 2;
  EXPECT_FALSE(ValidateParameters(p).empty());
  p = RSPParameters();
  p.GradientSigma = -1;
  EXPECT_FALSE(ValidateParameters(p).empty());
}

TEST(ImageFilters, DistanceToMaskIsTheExactEuclideanDistance)
{
  for (const std::array<int, 3> dims : { std::array<int, 3>{ { 37, 23, 1 } }, std::array<int, 3>{ { 13, 11, 9 } } })
  {
    ImageGeometry g;
    g.Dims = dims;
    std::mt19937 rng(3);
    std::vector<std::uint8_t> mask(g.Size(), 0);
    std::vector<std::array<int, 3>> set;
    for (std::int64_t v = 0; v < g.Size(); ++v)
      if (rng() % 40 == 0)
      {
        mask[v] = 1;
        set.push_back({ { static_cast<int>(v % dims[0]), static_cast<int>((v / dims[0]) % dims[1]),
          static_cast<int>(v / (dims[0] * dims[1])) } });
      }
    ASSERT_FALSE(set.empty());
    const std::vector<float> d = DistanceToMask(mask.data(), g, Chunked);
    for (int k = 0; k < dims[2]; ++k)
      for (int j = 0; j < dims[1]; ++j)
        for (int i = 0; i < dims[0]; ++i)
        {
          int best = std::numeric_limits<int>::max();
          for (const auto& s : set)
            best = std::min(best, (s[0] - i) * (s[0] - i) + (s[1] - j) * (s[1] - j) + (s[2] - k) * (s[2] - k));
          EXPECT_FLOAT_EQ(d[g.Index(i, j, k)], static_cast<float>(std::sqrt(static_cast<double>(best))));
        }
  }
  ImageGeometry g = Grid2(5, 4);
  std::vector<std::uint8_t> none(g.Size(), 0);
  EXPECT_TRUE(std::isinf(DistanceToMask(none.data(), g, SerialFor())[7]));
}

TEST(FeatureNodes, SeedAwareNodesAreFineAtTheEdgeMapAndCoarseAwayFromIt)
{
  // Nine bright discs; the edge map is the rim of the centre one only (what RSP would mark).
  ImageGeometry g = Grid2(240, 240);
  std::vector<float> f(g.Size(), 20.f);
  std::vector<std::uint8_t> map(g.Size(), 0);
  for (int j = 0; j < 240; ++j)
    for (int i = 0; i < 240; ++i)
    {
      const double ci = 40 + 80 * (i / 80), cj = 40 + 80 * (j / 80), r = std::hypot(i - ci, j - cj);
      if (r <= 22)
        f[g.Index(i, j, 0)] = 200.f;
      if (i / 80 == 1 && j / 80 == 1 && std::fabs(r - 22) <= 0.5)
        map[g.Index(i, j, 0)] = 1;
    }
  FeatureNodeParameters p;
  const FeatureNodeResult aware = ComputeFeatureNodes(f.data(), map.data(), g, p, SerialFor(), NoProgress());
  p.SeedAware = false;
  const FeatureNodeResult replace = ComputeFeatureNodes(f.data(), map.data(), g, p, SerialFor(), NoProgress());
  const FeatureNodeResult canny = ComputeFeatureNodes(f.data(), nullptr, g, FeatureNodeParameters(), SerialFor(), NoProgress());
  const std::vector<float> d = DistanceToMask(map.data(), g, SerialFor());
  const auto density = [&](const FeatureNodeResult& r, double lo, double hi) {
    double nodes = 0, area = 0;
    for (const auto& x : r.Positions)
    {
      const double dd = d[g.Index(x[0], x[1], 0)];
      nodes += dd >= lo && dd < hi;
    }
    for (float dd : d)
      area += dd >= lo && dd < hi;
    return nodes / area;
  };
  // Near the map about as dense as Canny's recipe (the halftone diffusion differs a little); far
  // from it several times sparser.
  EXPECT_GE(density(aware, 0, 8), 0.85 * density(canny, 0, 8));
  EXPECT_GT(density(aware, 0, 8), 4.0 * density(aware, 60, 1e9));
  EXPECT_GT(density(canny, 60, 1e9), 2.0 * density(aware, 60, 1e9));
  EXPECT_LT(aware.Positions.size(), canny.Positions.size());
  // The other discs' rims are not edges of the seed-aware recipe; the thesis's use keeps only the map.
  EXPECT_EQ(aware.EdgeMap[g.Index(40 + 22, 40, 0)] + aware.EdgeMap[g.Index(40 + 21, 40, 0)], 0);
  EXPECT_EQ(replace.EdgeMap, map);
  std::int64_t mapVoxels = 0, kept = 0;
  for (std::int64_t v = 0; v < g.Size(); ++v)
  {
    mapVoxels += map[v];
    kept += map[v] && aware.EdgeMap[v];
  }
  EXPECT_EQ(kept, mapVoxels);
}
