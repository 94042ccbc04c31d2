// Unit tests of the VTK-free core on synthetic arrays.
#include "BoykovJolly.h"
#include "DelaunayMesh.h"
#include "ElementRasterizer.h"
#include "Canny.h"
#include "EdgeSampling.h"
#include "FeatureNodes.h"
#include "Halftoning.h"
#include "ImageFilters.h"
#include "MeshSmoothing.h"
#include "RSPEdgeEnhancement.h"
#include "ExactPredicates.h"
#include "SimplexMesh.h"
#include "SeedConnectivity.h"
#include "SuperVoxelCut.h"
#include "SurfaceSmoothing.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <thread>
#include <numeric>
#include <random>
#include <set>

using namespace featuremesh;

namespace
{
ImageGeometry Grid2(int nx, int ny)
{
  ImageGeometry g;
  g.Dims = { { nx, ny, 1 } };
  return g;
}
std::vector<float> Disk(const ImageGeometry& g, double cx, double cy, double r)
{
  std::vector<float> f(g.Size());
  for (int j = 0; j < g.Dims[1]; ++j)
    for (int i = 0; i < g.Dims[0]; ++i)
      f[g.Index(i, j, 0)] = std::hypot(i - cx, j - cy) <= r ? 100.f : 10.f;
  return f;
}
} // namespace

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
  // within its (2R+1)-box.
  ImageGeometry g;
  g.Dims = { { 40, 30, 20 } };
  std::mt19937 rng(3);
  for (int largest : { 4, 12 })
  {
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
        blocked |= std::abs(a[0] - b[0]) <= radii[t] && std::abs(a[1] - b[1]) <= radii[t] && std::abs(a[2] - b[2]) <= radii[t];
      }
      if (!blocked)
      {
        want.push_back(t);
      }
    }
    EXPECT_EQ(ThinEdgePoints(pts, radii, g), want) << "radii up to " << largest;
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

// A random point set with the box corners: every voxel centre is owned by exactly one element,
// in 2D and 3D, with both 3D backends.
class Tiling : public ::testing::TestWithParam<int>
{
};
TEST_P(Tiling, EveryCentreHasExactlyOneOwner)
{
  const int mode = GetParam(); // 0: 2D, 1: TetGen, 2: CGAL
  ImageGeometry g;
  g.Dims = mode == 0 ? std::array<int, 3>{ { 40, 30, 1 } } : std::array<int, 3>{ { 14, 12, 10 } };
  std::mt19937 rng(7);
  std::vector<std::array<double, 3>> pts;
  std::vector<int> used(g.Size(), 0);
  for (int c = 0; c < (mode == 0 ? 4 : 8); ++c)
  {
    std::array<double, 3> p = { { (c & 1) ? g.Dims[0] - 1.0 : 0, (c & 2) ? g.Dims[1] - 1.0 : 0,
      (c & 4) ? g.Dims[2] - 1.0 : 0 } };
    used[g.Index(int(p[0]), int(p[1]), int(p[2]))] = 1;
    pts.push_back(p);
  }
  // Lattice-aligned points (many co-circular / co-spherical ties) plus random ones.
  for (int t = 0; t < 150; ++t)
  {
    const int i = rng() % g.Dims[0], j = rng() % g.Dims[1], k = rng() % g.Dims[2];
    if (!used[g.Index(i, j, k)]++)
      pts.push_back({ { double(i), double(j), double(k) } });
  }
  DelaunayOptions o;
  o.Backend = mode == 2 ? DelaunayBackend::CGAL : DelaunayBackend::TetGen;
  const DelaunayResult mesh = mode == 0 ? Triangulate2D(pts) : Tetrahedralize(pts, o);
  ASSERT_TRUE(mesh.Error.empty()) << mesh.Error;
  double measure = 0.0;
  for (size_t c = 0; c < mesh.Cells.size(); c += mesh.VerticesPerCell)
  {
    const double m = ElementMeasure(mesh.Points, mesh.Cells.data() + c, mesh.VerticesPerCell);
    EXPECT_GT(m, 0.0);
    measure += m;
  }
  const double box = (g.Dims[0] - 1.0) * (g.Dims[1] - 1.0) * (mode == 0 ? 1.0 : g.Dims[2] - 1.0);
  EXPECT_NEAR(measure, box, 1e-9 * box);
  const SimplexMesh simplices(g, mesh.Points, mesh.Cells, mesh.VerticesPerCell);
  ElementRasterizer raster(simplices);
  std::vector<int> owners(g.Size(), 0);
  for (std::int64_t e = 0; e < raster.NumberOfElements(); ++e)
    raster.ForEachVoxel(e, [&](std::int64_t v) { owners[v]++; });
  for (std::int64_t v = 0; v < g.Size(); ++v)
    ASSERT_EQ(owners[v], 1) << "voxel " << v;
  // Hull faces cover the box surface: their measure sums to its area/perimeter.
  const FaceAdjacency& adj = simplices.Faces();
  EXPECT_EQ(2 * adj.A.size() + adj.HullElement.size(), mesh.Cells.size());
}
INSTANTIATE_TEST_SUITE_P(Delaunay, Tiling, ::testing::Values(0, 1, 2));

namespace
{
// The CGAL Delaunay mesh of distinct `pts` (index space; triangles for a 2D grid), positively
// oriented, into `mesh`; false (with a failure) when meshing fails.
bool CGALMeshOfNodes(const ImageGeometry& g, std::vector<std::array<double, 3>> pts, SimplexMesh& mesh)
{
  std::sort(pts.begin(), pts.end());
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  DelaunayOptions o;
  o.Backend = DelaunayBackend::CGAL;
  const DelaunayResult d = g.Is2D() ? Triangulate2D(pts) : Tetrahedralize(pts, o);
  EXPECT_TRUE(d.Error.empty()) << d.Error;
  if (!d.Error.empty())
    return false;
  mesh = SimplexMesh(g, d.Points, d.Cells, d.VerticesPerCell);
  mesh.OrientPositively();
  return true;
}
} // namespace

// Nodes off the voxel lattice, as smoothing and refinement leave them: random ones, half-integers
// (faces through centres), and lattice nodes moved by 1e-13..1e-9 (faces a hair from centres, and
// slivers whose normals are far smaller than their rounding). Every centre still has exactly one
// owner: the candidate rows are a superset of the owned centres and Owns decides near faces
// exactly. (A band scaled by |n| gave voxel (5, 11, 5) of seed 3 two owners.)
TEST(Tiling, EveryCentreHasExactlyOneOwnerOffTheLattice)
{
  for (int dimension = 2; dimension <= 3; ++dimension)
  {
    for (int seed = 1; seed <= 12; ++seed)
    {
      ImageGeometry g;
      g.Dims = dimension == 2 ? std::array<int, 3>{ { 37, 29, 1 } } : std::array<int, 3>{ { 15, 13, 11 } };
      std::mt19937 rng(seed);
      std::uniform_real_distribution<double> unit(0.0, 1.0);
      std::vector<std::array<double, 3>> pts;
      for (int c = 0; c < (dimension == 2 ? 4 : 8); ++c)
        pts.push_back({ { (c & 1) ? g.Dims[0] - 1.0 : 0, (c & 2) ? g.Dims[1] - 1.0 : 0, (c & 4) ? g.Dims[2] - 1.0 : 0 } });
      const double hairs[] = { 1e-13, -1e-13, 1e-11, -1e-10, 1e-9 };
      for (int t = 0; t < 160; ++t)
      {
        std::array<double, 3> p{ { 0, 0, 0 } };
        for (int a = 0; a < dimension; ++a)
        {
          // Inside the box, off its faces (the box corners span it).
          const double x = 1.0 + std::floor(unit(rng) * (g.Dims[a] - 2.0));
          switch (t % 4)
          {
            case 0: p[a] = 0.5 + unit(rng) * (g.Dims[a] - 2.0); break;
            case 1: p[a] = std::min(x + 0.5, g.Dims[a] - 1.5); break;
            case 2: p[a] = x + hairs[rng() % 5]; break;
            default: p[a] = x; break;
          }
        }
        pts.push_back(p);
      }
      SimplexMesh simplices;
      ASSERT_TRUE(CGALMeshOfNodes(g, pts, simplices));
      ElementRasterizer raster(simplices);
      std::vector<int> owners(g.Size(), 0);
      for (std::int64_t e = 0; e < raster.NumberOfElements(); ++e)
        raster.ForEachVoxel(e, [&](std::int64_t v) { owners[v]++; });
      for (std::int64_t v = 0; v < g.Size(); ++v)
        ASSERT_EQ(owners[v], 1) << "dimension " << dimension << ", seed " << seed << ", voxel " << v;
    }
  }
}

// Large elements on a coarse grid of lattice nodes: faces parallel to x hold whole rows of centres
// (decided by the tie rule once per row) and long runs lie strictly inside (owned without a test);
// then the same nodes moved by multiples of 1/1024 voxel, as smoothing leaves them. Every centre
// has exactly one owner, and each element's spans come in ascending voxel order.
TEST(Tiling, CoarseElementsSpansCoverEveryCentreOnce)
{
  for (int dimension = 2; dimension <= 3; ++dimension)
  {
    for (int moved = 0; moved <= 1; ++moved)
    {
      ImageGeometry g;
      g.Dims = dimension == 2 ? std::array<int, 3>{ { 61, 47, 1 } } : std::array<int, 3>{ { 31, 26, 21 } };
      std::mt19937 rng(7 + moved);
      std::vector<std::array<double, 3>> pts;
      const int step = 5;
      for (int k = 0; k < g.Dims[2]; k += (dimension == 2 ? 1 : step))
        for (int j = 0; j < g.Dims[1]; j += step)
          for (int i = 0; i < g.Dims[0]; i += step)
          {
            std::array<double, 3> p{ { double(std::min(i, g.Dims[0] - 1)), double(std::min(j, g.Dims[1] - 1)),
              double(std::min(k, g.Dims[2] - 1)) } };
            for (int a = 0; a < dimension && moved; ++a)
              if (p[a] > 0 && p[a] < g.Dims[a] - 1)
                p[a] += static_cast<double>(static_cast<int>(rng() % 1025) - 512) / 1024.0;
            pts.push_back(p);
          }
      for (int c = 0; c < (dimension == 2 ? 4 : 8); ++c)
        pts.push_back({ { (c & 1) ? g.Dims[0] - 1.0 : 0, (c & 2) ? g.Dims[1] - 1.0 : 0, (c & 4) ? g.Dims[2] - 1.0 : 0 } });
      SimplexMesh simplices;
      ASSERT_TRUE(CGALMeshOfNodes(g, pts, simplices));
      ElementRasterizer raster(simplices);
      std::vector<int> owners(g.Size(), 0);
      std::int64_t longest = 0;
      for (std::int64_t e = 0; e < raster.NumberOfElements(); ++e)
      {
        std::int64_t next = -1;
        raster.ForEachSpan(e, [&](std::int64_t first, std::int64_t count) {
          ASSERT_GE(count, 1);
          ASSERT_GE(first, next) << "element " << e;
          next = first + count;
          longest = std::max(longest, count);
          for (std::int64_t v = first; v < first + count; ++v)
            owners[v]++;
        });
      }
      for (std::int64_t v = 0; v < g.Size(); ++v)
        ASSERT_EQ(owners[v], 1) << "dimension " << dimension << ", moved " << moved << ", voxel " << v;
      EXPECT_GE(longest, 3) << "no long interior run: the test does not reach the untested path";
    }
  }
}

TEST(Delaunay, ImageMeshNodesAreCheckedAndTheBoxCornersAdded)
{
  ImageGeometry g;
  g.Dims = { { 6, 5, 1 } };
  g.Spacing = { { 2.0, 1.0, 1.0 } };
  std::vector<std::array<double, 3>> nodes = { { { 0.0, 0.0, 0.0 } }, { { 4.0, 2.0, 0.0 } }, { { 6.0, 1.0, 0.0 } } };
  EXPECT_EQ(ImageMeshNodes(g, nodes), "");
  // World to index (x / 2), then the three corners the nodes lack.
  ASSERT_EQ(nodes.size(), 6u);
  EXPECT_EQ(nodes[1], (std::array<double, 3>{ { 2.0, 2.0, 0.0 } }));
  EXPECT_EQ(nodes[3], (std::array<double, 3>{ { 5.0, 0.0, 0.0 } }));
  EXPECT_EQ(nodes[5], (std::array<double, 3>{ { 5.0, 4.0, 0.0 } }));
  std::vector<std::array<double, 3>> outside = { { { 0.0, 0.0, 0.0 } }, { { 12.0, 2.0, 0.0 } }, { { 6.0, 3.0, 0.0 } } };
  EXPECT_EQ(ImageMeshNodes(g, outside), "1 of 3 nodes lie outside the image bounds.");
  std::vector<std::array<double, 3>> twice = { { { 0.0, 0.0, 0.0 } }, { { 4.0, 2.0, 0.0 } }, { { 4.0, 2.0, 0.0 } } };
  EXPECT_NE(ImageMeshNodes(g, twice).find("duplicate"), std::string::npos);
  std::vector<std::array<double, 3>> line = { { { 0.0, 0.0, 0.0 } }, { { 2.0, 1.0, 0.0 } }, { { 4.0, 2.0, 0.0 } } };
  EXPECT_NE(ImageMeshNodes(g, line).find("collinear"), std::string::npos);
  DelaunayOptions o;
  o.QualityRefinement = true;
  o.MinDihedralAngle = 25.0;
  EXPECT_FALSE(ValidateParameters(o, false).empty());
  EXPECT_TRUE(ValidateParameters(o, true).empty());
}

TEST(Delaunay, DegenerateInputIsAnError)
{
  std::vector<std::array<double, 3>> line = { { { 0, 0, 0 } }, { { 1, 1, 0 } }, { { 2, 2, 0 } } };
  EXPECT_FALSE(Triangulate2D(line).Error.empty());
  std::vector<std::array<double, 3>> plane = { { { 0, 0, 0 } }, { { 1, 0, 0 } }, { { 0, 1, 0 } }, { { 1, 1, 0 } },
    { { 2, 3, 0 } } };
  EXPECT_FALSE(Tetrahedralize(plane, DelaunayOptions()).Error.empty());
  DelaunayOptions cgal;
  cgal.Backend = DelaunayBackend::CGAL;
  EXPECT_FALSE(Tetrahedralize(plane, cgal).Error.empty());
  EXPECT_EQ(CountDuplicates({ { { 0, 0, 0 } }, { { 1, 0, 0 } }, { { 0, 0, 0 } } }), 1);
}

TEST(Statistics, MeanAndCountAreExact)
{
  ImageGeometry g;
  g.Dims = { { 5, 4, 1 } };
  std::vector<std::array<double, 3>> pts = { { { 0, 0, 0 } }, { { 4, 0, 0 } }, { { 4, 3, 0 } }, { { 0, 3, 0 } } };
  const DelaunayResult mesh = Triangulate2D(pts);
  ASSERT_TRUE(mesh.Error.empty());
  std::vector<double> values(g.Size());
  for (std::int64_t v = 0; v < g.Size(); ++v)
    values[v] = static_cast<double>(v);
  const SimplexMesh simplices(g, mesh.Points, mesh.Cells, 3);
  const auto s = ComputeElementStatistics(ElementRasterizer(simplices), values.data(), SerialFor());
  std::int64_t total = 0;
  double sum = 0.0;
  for (size_t e = 0; e < s.PixelCount.size(); ++e)
  {
    total += s.PixelCount[e];
    sum += s.Mean[e] * s.PixelCount[e];
  }
  EXPECT_EQ(total, 20);
  EXPECT_NEAR(sum, 190.0, 1e-9);
}

// A chain of unit nodes with the given values, object seed first, background seed last.
CutProblem SeededChain(const std::vector<double>& values)
{
  CutProblem pr;
  const std::int64_t n = static_cast<std::int64_t>(values.size());
  std::vector<std::int64_t> A, B;
  for (std::int64_t i = 0; i < n; ++i)
  {
    pr.Value.push_back(values[i]);
    pr.Size.push_back(1.0);
    pr.Hard.push_back(i == 0 ? 1 : (i == n - 1 ? 2 : 0));
    if (i > 0)
    {
      A.push_back(i - 1);
      B.push_back(i);
      pr.Contact.push_back(1.0);
    }
  }
  pr.Edges = GraphEdges::Owned(std::move(A), std::move(B));
  return pr;
}

TEST(BoykovJolly, SeparatesTwoPlateausAndHonoursSeeds)
{
  // A chain of 20 nodes: values 10 then 0, a seed at each end.
  std::vector<double> values;
  for (int i = 0; i < 20; ++i)
  {
    values.push_back(i < 8 ? 10.0 : 0.0);
  }
  CutProblem pr = SeededChain(values);
  pr.ObjectSamples = { 10.0, 10.0, 9.5 };
  pr.BackgroundSamples = { 0.0, 0.5, 0.0 };
  const CutResult r = BoykovJollyCut(pr, BoykovJollyParameters());
  ASSERT_TRUE(r.Error.empty());
  for (int i = 0; i < 20; ++i)
    EXPECT_EQ(r.Label[i], i < 8 ? 1 : 0) << i;
  BoykovJollyParameters bad;
  bad.Lambda = -1;
  EXPECT_FALSE(ValidateParameters(bad).empty());
}

TEST(BoykovJolly, AutomaticBinsResolveNarrowDensitiesInAWideRange)
{
  // A CT in miniature: object tissue near 52, background tissue near 44 and air near -1000. With 64
  // bins over the range both tissues share a bin and the background tissue looks like the object;
  // the automatic bins resolve the seeds' densities and tell them apart.
  std::vector<double> values;
  const double wobble[3] = { -1.5, 0.0, 1.5 };
  for (int i = 0; i < 30; ++i)
  {
    values.push_back((i < 10 ? 52.0 : (i < 20 ? 44.0 : -1000.0)) + wobble[i % 3]);
  }
  CutProblem pr = SeededChain(values);
  for (int i = 0; i < 6; ++i)
  {
    pr.ObjectSamples.push_back(52.0 + wobble[i % 3]);
    pr.BackgroundSamples.push_back(44.0 + wobble[i % 3]);
    pr.BackgroundSamples.push_back(-1000.0 + wobble[i % 3]);
  }
  BoykovJollyParameters par;
  par.Lambda = 5.0;
  const CutResult fine = BoykovJollyCut(pr, par);
  ASSERT_TRUE(fine.Error.empty());
  EXPECT_GT(fine.Bins, 64);
  for (int i = 0; i < 30; ++i)
    EXPECT_EQ(fine.Label[i], i < 10 ? 1 : 0) << i;
  par.Bins = 64;
  const CutResult coarse = BoykovJollyCut(pr, par);
  ASSERT_TRUE(coarse.Error.empty());
  EXPECT_EQ(coarse.Label[15], 1);
  // Wide densities keep 64 bins.
  const std::vector<double> wide = { 0.0, 10.0, 20.0, 30.0, 40.0 };
  EXPECT_EQ(AutomaticBins({ { &wide, nullptr } }, 0.0, 40.0, 1.0), 64);
  const std::vector<double> narrow = { 20.0, 20.1, 20.2, 20.3 };
  EXPECT_GT(AutomaticBins({ { &wide, nullptr }, { &narrow, nullptr } }, 0.0, 40.0, 1.0), 64);
  const std::vector<double> spike = { 7.0, 7.0, 7.0 };
  EXPECT_EQ(AutomaticBins({ { &spike, nullptr } }, 0.0, 40.0, 1.0), 64);
}

TEST(BoykovJolly, VoxelRegionTermSumsVoxelCosts)
{
  // Super-nodes of one voxel each: the voxel region term must equal the mean-based one.
  std::vector<double> pixels;
  std::vector<std::int32_t> owner;
  for (int i = 0; i < 30; ++i)
  {
    pixels.push_back((i < 12 ? 10.0 : 0.0) + ((i * 7) % 5) * 0.6);
    owner.push_back(i);
  }
  CutProblem pr = SeededChain(pixels);
  pr.ObjectSamples = { 10.0, 11.0, 12.4 };
  pr.BackgroundSamples = { 0.0, 1.2, 2.4 };
  const CutResult byMean = BoykovJollyCut(pr, BoykovJollyParameters());
  NodeVoxelValues grouped;
  std::string error;
  ASSERT_TRUE(GroupVoxelValues(owner.data(), pixels.data(), 30, 30, grouped, error, SerialFor()));
  pr.NodeVoxels = &grouped;
  const CutResult byVoxel = BoykovJollyCut(pr, BoykovJollyParameters());
  ASSERT_TRUE(byMean.Error.empty() && byVoxel.Error.empty());
  EXPECT_EQ(byMean.Label, byVoxel.Label);
  EXPECT_NEAR(byMean.Flow, byVoxel.Flow, 1e-9 * byMean.Flow);

  // One element holding 3 object-like voxels and 1 background-like voxel, mean in between: the
  // voxel term counts what its voxels are, the mean term what its mean looks like.
  CutProblem two;
  two.Value = { 10.0, 0.0, 7.5 };
  two.Size = { 1.0, 1.0, 4.0 };
  two.Hard = { 1, 2, 0 };
  two.Edges = GraphEdges::Owned({ 0, 1 }, { 2, 2 });
  two.Contact = { 0.01, 0.01 };
  const std::vector<double> v = { 10.0, 0.0, 10.0, 10.0, 10.0, 0.0 };
  const std::vector<std::int32_t> o = { 0, 1, 2, 2, 2, 2 };
  two.ObjectSamples = { 10.0, 9.0, 11.0 };
  two.BackgroundSamples = { 0.0, 1.0, -1.0 };
  NodeVoxelValues twoGrouped;
  ASSERT_TRUE(GroupVoxelValues(o.data(), v.data(), 6, 3, twoGrouped, error, SerialFor()));
  EXPECT_EQ(twoGrouped.Offset, (std::vector<std::int64_t>{ 0, 1, 2, 6 }));
  EXPECT_EQ(std::vector<double>(twoGrouped.Double.get(), twoGrouped.Double.get() + 6), (std::vector<double>{ 10.0, 0.0, 0.0, 10.0, 10.0, 10.0 }));
  NodeVoxelValues twoBounded;
  ASSERT_TRUE(GroupVoxelValues(o.data(), v.data(), 6, 3, twoBounded, error, SerialFor(), NoProgress(), nullptr, 0));
  EXPECT_FALSE(twoBounded.Sorted());
  EXPECT_EQ(twoBounded.Min, (std::vector<float>{ 10.f, 0.f, 0.f }));
  EXPECT_EQ(twoBounded.Max, (std::vector<float>{ 10.f, 0.f, 10.f }));
  EXPECT_EQ(twoBounded.Shared, (std::vector<std::uint8_t>{ 0, 0, 1 })); // voxels 2-5 lie in chunks 2-5 of 8
  two.NodeVoxels = &twoGrouped;
  const std::vector<double> nan = { 1.0, std::nan(""), 2.0, 3.0, 4.0, 5.0 };
  NodeVoxelValues badGrouped;
  EXPECT_FALSE(GroupVoxelValues(o.data(), nan.data(), 6, 3, badGrouped, error, SerialFor()));
  EXPECT_EQ(error.rfind("1 intensities are NaN", 0), 0u) << error;
  const CutResult exact = BoykovJollyCut(two, BoykovJollyParameters());
  ASSERT_TRUE(exact.Error.empty());
  EXPECT_EQ(exact.Label[2], 1);
}

TEST(BoykovJolly, AnOutlierFarBeyondTheRangeCountsInTheLastBin)
{
  // 40 nodes of 5 voxels in [0, 20]; the largest voxel is 25, 1e12 or 1e150, far more bins beyond
  // the range than an int counts: all fall in the last bin (the percentile range and the means stay the same), so the
  // cut is the same, and it finishes; with the values sorted and bounded.
  std::vector<double> mean;
  std::vector<std::int32_t> owner;
  std::vector<double> voxels;
  for (int p = 0; p < 40; ++p)
  {
    double sum = 0.0;
    for (int k = 0; k < 5; ++k)
    {
      voxels.push_back((p < 15 ? 15.0 : 3.0) + (k * 7 + p) % 5);
      owner.push_back(p);
      sum += voxels.back();
    }
    mean.push_back(sum / 5);
  }
  CutProblem pr = SeededChain(mean);
  pr.ObjectSamples = { 15, 16, 17, 19 };
  pr.BackgroundSamples = { 3, 4, 5, 7 };
  std::vector<double> flows;
  std::vector<std::vector<std::uint8_t>> labels;
  for (const double outlier : { 25.0, 1e12, 1e150, 25.0, 1e12, 1e150 })
  {
    voxels[7] = outlier;
    NodeVoxelValues grouped;
    std::string error;
    ASSERT_TRUE(GroupVoxelValues(owner.data(), voxels.data(), static_cast<std::int64_t>(voxels.size()), 40, grouped,
      error, SerialFor(), NoProgress(), nullptr, flows.size() < 3 ? SortedVoxelLimit : 0));
    pr.NodeVoxels = &grouped;
    MaxFlowCache cache;
    const CutResult r = BoykovJollyCut(pr, BoykovJollyParameters(), NoProgress(), &cache);
    ASSERT_TRUE(r.Error.empty()) << r.Error;
    flows.push_back(r.Flow);
    labels.push_back(r.Label);
  }
  for (size_t k = 1; k < flows.size(); ++k)
  {
    EXPECT_EQ(flows[k], flows[0]) << k;
    EXPECT_EQ(labels[k], labels[0]) << k;
  }
}

TEST(BoykovJolly, VoxelRegionTermCountsEveryVoxelInItsBin)
{
  // 50 nodes whose voxels (300 k, more than one pass block, some owned by none) lie scattered
  // through the volume, spanning several bins each. With no boundary term each free node pays the
  // cheaper of its two region costs, so the flow is the sum of those minima: computed here voxel by
  // voxel, it must equal the cut's: sorted or bounded values, a serial or a chunked (any thread
  // split) pass, one or two words of bins per node.
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> node(-1, 49);
  std::normal_distribution<double> noise(0.0, 4.0);
  const std::int64_t voxels = 300000;
  std::vector<std::int32_t> owner(voxels);
  std::vector<float> values(voxels);
  std::vector<double> sum(50, 0.0), count(50, 0.0);
  for (std::int64_t v = 0; v < voxels; ++v)
  {
    owner[v] = node(rng);
    values[v] = static_cast<float>((owner[v] >= 0 && owner[v] < 20 ? 30.0 : 10.0) + noise(rng));
    if (owner[v] >= 0)
    {
      sum[owner[v]] += values[v];
      count[owner[v]] += 1.0;
    }
  }
  std::vector<double> mean(50);
  for (int p = 0; p < 50; ++p)
  {
    mean[p] = sum[p] / count[p];
  }
  CutProblem pr = SeededChain(mean);
  pr.Size = count;
  std::fill(pr.Contact.begin(), pr.Contact.end(), 0.0);
  pr.ObjectSamples = { 28, 30, 33, 31, 26 };
  pr.BackgroundSamples = { 8, 12, 10, 9, 14 };
  const std::vector<std::pair<std::int64_t, int>> forms = { { SortedVoxelLimit, 64 }, { SortedVoxelLimit, 100 }, { 0, 64 }, { 0, 100 } };
  for (const auto& [sortedLimit, bins] : forms)
  {
    NodeVoxelValues viewed;
    std::string error;
    ASSERT_TRUE(GroupVoxelValues(owner.data(), values.data(), voxels, 50, viewed, error, SerialFor(), NoProgress(), nullptr,
      sortedLimit)) << error;
    EXPECT_EQ(viewed.Sorted(), sortedLimit > 0);
    pr.NodeVoxels = &viewed;
    BoykovJollyParameters par;
    par.Bins = bins;
    pr.Parallel = SerialFor();
    const CutResult serial = BoykovJollyCut(pr, par);
    const ParallelFor chunked = [](std::int64_t n, std::int64_t, const RangeFunction& body) {
      for (std::int64_t b = ((n - 1) / 3) * 3; b >= 0; b -= 3)
        body(b, std::min(n, b + 3));
    };
    pr.Parallel = chunked;
    const CutResult split = BoykovJollyCut(pr, par);
    ASSERT_TRUE(serial.Error.empty() && split.Error.empty());
    EXPECT_EQ(split.Flow, serial.Flow);
    EXPECT_EQ(split.Label, serial.Label);

    double low = viewed.Low, high = viewed.High;
    for (const auto* samples : { &pr.ObjectSamples, &pr.BackgroundSamples })
    {
      for (double x : *samples)
      {
        low = std::min(low, x);
        high = std::max(high, x);
      }
    }
    const double width = (high - low) / bins;
    const std::vector<double> object = SmoothedHistogram(pr.ObjectSamples, {}, low, high, bins);
    const std::vector<double> background = SmoothedHistogram(pr.BackgroundSamples, {}, low, high, bins);
    std::vector<std::vector<double>> perBin(50, std::vector<double>(bins, 0.0));
    for (std::int64_t v = 0; v < voxels; ++v)
    {
      if (owner[v] >= 0)
      {
        const double q = (static_cast<double>(values[v]) - low) / width;
        perBin[owner[v]][q < 1.0 ? 0 : (q >= bins - 1 ? bins - 1 : static_cast<int>(q))] += 1.0;
      }
    }
    double flow = 0.0;
    int spanning = 0;
    for (int p = 1; p < 49; ++p)
    {
      double costObject = 0.0, costBackground = 0.0;
      for (int b = 0; b < bins; ++b)
      {
        if (perBin[p][b] > 0.0)
        {
          costObject += perBin[p][b] * -std::log(object[b]);
          costBackground += perBin[p][b] * -std::log(background[b]);
        }
      }
      spanning += std::count_if(perBin[p].begin(), perBin[p].end(), [](double c) { return c > 0.0; }) > 5 ? 1 : 0;
      flow += std::min(par.Lambda * costObject, par.Lambda * costBackground);
    }
    EXPECT_EQ(spanning, 48);
    EXPECT_NEAR(serial.Flow, flow, 1e-12 * flow) << bins << " " << sortedLimit;
  }
}

TEST(BoykovJolly, KeptCutsEqualFreshCuts)
{
  // 60 super-nodes of 1-40 noisy voxels each (spanning several bins), object-like first; a chain of
  // seed edits through one MaxFlowCache, with the values sorted and bounded: a binning seen first
  // (summed from the sorted values, or binned from the voxels), the same binning again (kept as
  // runs), read from the runs, a seed sample beyond the range (a new binning),
  // then a change of the bins and of sigma (new weights). Each cut equals a fresh one: the same
  // labels and flow.
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 3.0);
  std::uniform_int_distribution<int> count(1, 40);
  std::vector<double> mean, voxels;
  std::vector<std::int32_t> owner;
  for (int p = 0; p < 60; ++p)
  {
    const int c = count(rng);
    double sum = 0.0;
    for (int k = 0; k < c; ++k)
    {
      voxels.push_back((p < 25 ? 20.0 : 5.0) + noise(rng));
      owner.push_back(p);
      sum += voxels.back();
    }
    mean.push_back(sum / c);
  }
  for (const std::int64_t sortedLimit : { SortedVoxelLimit, std::int64_t(0) })
  {
    CutProblem pr = SeededChain(mean);
    NodeVoxelValues grouped;
    std::string error;
    ASSERT_TRUE(GroupVoxelValues(owner.data(), voxels.data(), static_cast<std::int64_t>(voxels.size()), 60, grouped,
      error, SerialFor(), NoProgress(), nullptr, sortedLimit));
    pr.NodeVoxels = &grouped;
    BoykovJollyParameters par;
    par.Lambda = 1.0;
    const std::vector<std::vector<double>> objectSamples = { { 20, 22, 18, 25 }, { 20, 22, 18, 25 }, { 21, 19, 23, 17 },
      { 21, 19, 23, 60 }, { 21, 19, 23, 60 }, { 21, 19, 23, 60 }, { 21, 19, 23, 60 }, { 21, 19, 23, 60 } };
    // Edits 0-3 on held (owned) edge lists, which the cache keeps as they are; from 4 on a view of
    // equal lists (compared by value: the kept flow still applies), which the new sigma of edit 6
    // makes the cache copy, and edit 7 reuses.
    const std::vector<std::int64_t> A(pr.Edges.First(), pr.Edges.First() + pr.Edges.Size());
    const std::vector<std::int64_t> B(pr.Edges.Second(), pr.Edges.Second() + pr.Edges.Size());
    MaxFlowCache cache;
    for (size_t edit = 0; edit < objectSamples.size(); ++edit)
    {
      if (edit == 4)
      {
        pr.Edges = GraphEdges(A, B);
      }
      pr.ObjectSamples = objectSamples[edit];
      pr.BackgroundSamples = { 5, 3, 7, 4 + static_cast<double>(edit) };
      par.Bins = edit >= 5 ? 16 : 0;
      par.Sigma = edit >= 6 ? 2.0 : 0.0;
      const CutResult kept = BoykovJollyCut(pr, par, NoProgress(), &cache);
      const CutResult fresh = BoykovJollyCut(pr, par);
      ASSERT_TRUE(kept.Error.empty() && fresh.Error.empty()) << edit;
      EXPECT_EQ(kept.Label, fresh.Label) << edit;
      EXPECT_NEAR(kept.Flow, fresh.Flow, 1e-12 * fresh.Flow) << edit;
      const auto object = std::count(kept.Label.begin(), kept.Label.end(), 1);
      EXPECT_TRUE(object >= 22 && object <= 28) << edit << ": " << object;
    }
  }
}

// A rotated, offset, anisotropic frame: world -> index -> world round trips, voxel centres snap
// back exactly, half a voxel of slack decides membership, a mirror is detected.
TEST(ImageGeometry, OrientedFrameRoundTrips)
{
  ImageGeometry g;
  g.Dims = { { 6, 5, 4 } };
  g.Origin = { { 10.0, -3.0, 2.5 } };
  g.Spacing = { { 0.5, 2.0, 1.25 } };
  g.Direction = { { 0, -1, 0, 1, 0, 0, 0, 0, 1 } }; // 90 degrees about z
  ASSERT_TRUE(g.Validate().empty());
  EXPECT_FALSE(g.IsMirrored());
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 6; ++i)
      {
        const std::array<double, 3> idx = { { double(i), double(j), double(k) } };
        EXPECT_EQ(g.WorldToIndex(g.IndexToWorld(idx)), idx);
        EXPECT_EQ(g.VoxelAt(g.IndexToWorld(idx)), g.Index(i, j, k));
      }
  // Direction column 0 is (0, 1, 0): index x runs along world +y.
  const auto w = g.IndexToWorld({ { 1, 0, 0 } });
  EXPECT_DOUBLE_EQ(w[0], 10.0);
  EXPECT_DOUBLE_EQ(w[1], -2.5);
  EXPECT_EQ(g.VoxelAt(g.IndexToWorld({ { -0.49, 0, 0 } })), g.Index(0, 0, 0));
  EXPECT_EQ(g.VoxelAt(g.IndexToWorld({ { -0.51, 0, 0 } })), -1);
  EXPECT_EQ(g.VoxelAt(g.IndexToWorld({ { 5.4, 4, 3 } })), g.Index(5, 4, 3));
  EXPECT_EQ(g.VoxelAt({ { std::nan(""), 0, 0 } }), -1);
  std::vector<std::int64_t> voxels;
  std::string error;
  EXPECT_FALSE(SeedVoxels({ g.IndexToWorld({ { 1, 1, 1 } }), { { 1e9, 0, 0 } } }, g, "object", voxels, error));
  EXPECT_EQ(error, "1 of 2 object seeds fall outside the image (or are not finite).");
  EXPECT_FALSE(SeedVoxels({}, g, "background", voxels, error));
  ImageGeometry m = g;
  m.Spacing[1] = -2.0;
  EXPECT_TRUE(m.IsMirrored());
  m.Spacing[1] = 0.0;
  EXPECT_FALSE(m.Validate().empty());
  m = g;
  m.Direction = { { 1, 0, 0, 1, 0, 0, 0, 0, 1 } };
  EXPECT_FALSE(m.Validate().empty());
}

namespace
{
// Four triangles around the centre (2, 2) of a 5x5 image: 0 bottom, 1 right, 2 top, 3 left.
SimplexMesh FourTriangles(double sx = 1.0, double sy = 1.0)
{
  ImageGeometry g = Grid2(5, 5);
  g.Spacing = { { sx, sy, 1.0 } };
  std::vector<std::array<double, 3>> p = { { { 0, 0, 0 } }, { { 4, 0, 0 } }, { { 4, 4, 0 } }, { { 0, 4, 0 } },
    { { 2, 2, 0 } } };
  std::vector<std::int64_t> c = { 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4 };
  return SimplexMesh(g, p, c, 3);
}
} // namespace

TEST(SimplexMesh, AdjacencyOfFourTriangles)
{
  const SimplexMesh mesh = FourTriangles();
  ASSERT_TRUE(mesh.Validate().empty());
  const FaceAdjacency& f = mesh.Faces();
  // Interior edges: the four spokes, each between neighbouring triangles; hull: the four sides.
  ASSERT_EQ(f.A.size(), 4u);
  ASSERT_EQ(f.HullElement.size(), 4u);
  for (size_t e = 0; e < f.A.size(); ++e)
  {
    EXPECT_LT(f.A[e], f.B[e]);
    EXPECT_TRUE((f.B[e] - f.A[e]) == 1 || (f.A[e] == 0 && f.B[e] == 3));
    EXPECT_DOUBLE_EQ(f.Measure[e], std::sqrt(8.0));
  }
  const CompressedRows& stars = mesh.Stars();
  EXPECT_EQ(stars.Size(4), 4);
  EXPECT_EQ(std::vector<std::int64_t>(stars.Begin(0), stars.End(0)), (std::vector<std::int64_t>{ 0, 3 }));
  const CompressedRows& around = mesh.VertexNeighbours();
  EXPECT_EQ(std::vector<std::int64_t>(around.Begin(4), around.End(4)), (std::vector<std::int64_t>{ 0, 1, 2, 3 }));
  EXPECT_EQ(std::vector<std::int64_t>(around.Begin(0), around.End(0)), (std::vector<std::int64_t>{ 1, 3, 4 }));
  // Moving points keeps the topology, recomputes measures.
  SimplexMesh moved = mesh;
  auto p = moved.Points();
  p[4] = { { 1, 1, 0 } };
  moved.SetPoints(p);
  EXPECT_DOUBLE_EQ(moved.Faces().Measure[0], std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(mesh.Faces().Measure[0], std::sqrt(8.0));
  EXPECT_EQ(&moved.Stars(), &mesh.Stars());
  // Bad ids are an error, not a crash.
  EXPECT_FALSE(SimplexMesh(mesh.Geometry(), mesh.Points(), { 0, 1, 7 }, 3).Validate().empty());
}

TEST(SuperVoxelCut, BoundedVoxelValuesCutAsSortedOnes)
{
  // A noisy bright ball in a 3D image, meshed off the lattice: the cut with each element's voxel
  // values sorted and with their bounds only (a binning pass over the voxels, seed samples from the
  // elements' boxes in the owner map) gives the same labels and flow, for two seed sets.
  ImageGeometry g;
  g.Dims = { { 30, 28, 26 } };
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.f, 8.f);
  std::vector<float> image(g.Size());
  for (int k = 0; k < g.Dims[2]; ++k)
    for (int j = 0; j < g.Dims[1]; ++j)
      for (int i = 0; i < g.Dims[0]; ++i)
        image[g.Index(i, j, k)] = ((i - 14) * (i - 14) + (j - 13) * (j - 13) + (k - 12) * (k - 12) < 64 ? 100.f : 40.f) + noise(rng);
  std::vector<std::array<double, 3>> pts;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n = 0; n < 700; ++n)
    pts.push_back({ { u(rng) * 29, u(rng) * 27, u(rng) * 25 } });
  for (int c = 0; c < 8; ++c)
    pts.push_back({ { (c & 1) ? 29.0 : 0, (c & 2) ? 27.0 : 0, (c & 4) ? 25.0 : 0 } });
  SimplexMesh mesh;
  ASSERT_TRUE(CGALMeshOfNodes(g, pts, mesh));
  const ElementStatistics stats = ComputeElementStatistics(ElementRasterizer(mesh), image.data(), SerialFor());
  const std::vector<double> count(stats.PixelCount.begin(), stats.PixelCount.end());
  SuperVoxelCutData sorted, bounded;
  std::string error;
  ASSERT_TRUE(PrepareSuperVoxelCut(mesh, image.data(), sorted, error, SerialFor()));
  ASSERT_TRUE(PrepareSuperVoxelCut(mesh, image.data(), bounded, error, SerialFor(), NoProgress(), nullptr, 0));
  ASSERT_TRUE(sorted.Voxels.Sorted() && !bounded.Voxels.Sorted());
  const VoxelValueFunction value = [&](std::int64_t v) { return static_cast<double>(image[v]); };
  const std::vector<std::vector<std::int64_t>> objectSeeds = { { g.Index(14, 13, 12) }, { g.Index(12, 13, 12), g.Index(17, 14, 11) } };
  for (const auto& object : objectSeeds)
  {
    const std::vector<std::int64_t> background = { g.Index(2, 2, 2), g.Index(27, 25, 23) };
    SuperVoxelCutParameters par;
    par.Connectivity = Connectivity::Off;
    const SuperVoxelCutResult a = SuperVoxelCut(mesh, sorted, stats.Mean, count, object, background, value, par, SerialFor());
    const SuperVoxelCutResult b = SuperVoxelCut(mesh, bounded, stats.Mean, count, object, background, value, par, SerialFor());
    ASSERT_TRUE(a.Error.empty() && b.Error.empty()) << a.Error << b.Error;
    EXPECT_EQ(a.Cut.Label, b.Cut.Label);
    EXPECT_EQ(a.Cut.Flow, b.Cut.Flow);
    const auto objectElements = std::count(a.Cut.Label.begin(), a.Cut.Label.end(), 1);
    EXPECT_GT(objectElements, 20);
    EXPECT_LT(objectElements, static_cast<long>(a.Cut.Label.size()) / 2);
  }
}

TEST(SuperVoxelCut, ContactAndHardConstraintsOnFourTriangles)
{
  // Anisotropic pixels: a spoke of length sqrt(2^2 0.5^2 + 2^2 1.5^2) counts in units of the mean
  // pixel edge (1.0).
  const SimplexMesh mesh = FourTriangles(0.5, 1.5);
  const std::vector<double> contact = ContactInVoxelFaces(mesh, true);
  for (double c : contact)
    EXPECT_DOUBLE_EQ(c, std::sqrt(1.0 + 9.0) / 1.0);
  for (double c : ContactInVoxelFaces(mesh, false))
    EXPECT_EQ(c, 1.0);

  SuperVoxelCutData data;
  std::string prepareError;
  ASSERT_TRUE(PrepareSuperVoxelCut(mesh, static_cast<const double*>(nullptr), data, prepareError, SerialFor()));
  const VoxelOwnerMap& owner = data.Owner;
  const ImageGeometry& g = mesh.Geometry();
  std::vector<std::uint8_t> hard(4, 0);
  std::string error;
  // Voxel (2, 0) lies in the bottom triangle, (4, 2) in the right one.
  ASSERT_TRUE(SeedConstraints(owner, { g.Index(2, 0, 0) }, { g.Index(4, 2, 0) }, "element", hard, error));
  EXPECT_EQ(hard, (std::vector<std::uint8_t>{ 1, 2, 0, 0 }));
  hard.assign(4, 0);
  EXPECT_FALSE(SeedConstraints(owner, { g.Index(2, 0, 0) }, { g.Index(1, 0, 0) }, "element", hard, error));
  EXPECT_EQ(error, "element 0 holds both an object and a background seed; move one of them.");

  // Bright bottom and left, dark right and top; seeds force bottom and right even when the
  // intensities disagree (the background seed sits in a bright element).
  const std::vector<double> mean = { 100, 10, 10, 100 }, count = { 9, 9, 9, 9 };
  SuperVoxelCutParameters par;
  const SuperVoxelCutResult r =
    SuperVoxelCut(mesh, data, mean, count, { g.Index(2, 0, 0) }, { g.Index(4, 2, 0) }, VoxelValueFunction(), par, SerialFor());
  ASSERT_TRUE(r.Error.empty()) << r.Error;
  EXPECT_EQ(r.Cut.Label[0], LabelObject);
  EXPECT_EQ(r.Cut.Label[1], LabelBackground);
  EXPECT_EQ(r.Cut.Label[3], LabelObject);
  std::vector<std::uint8_t> voxels(owner.size());
  VoxelLabels(owner, r.Cut.Label, voxels.data(), SerialFor());
  EXPECT_EQ(voxels[g.Index(2, 0, 0)], LabelObject);
  EXPECT_EQ(voxels[g.Index(4, 2, 0)], LabelBackground);
}

// The label boundary of a tetrahedral mesh is closed (every edge in two faces, with opposite
// directions) and outward (it encloses the labelled volume, positively); a mirrored frame flips
// the faces so that they stay outward in world coordinates.
TEST(SimplexMesh, LabelBoundaryIsClosedAndOutward)
{
  ImageGeometry g;
  g.Dims = { { 5, 5, 5 } };
  g.Spacing = { { 1.0, 2.0, 0.5 } };
  std::vector<std::array<double, 3>> pts;
  for (int k = 0; k < 5; k += 2)
    for (int j = 0; j < 5; j += 2)
      for (int i = 0; i < 5; i += 2)
        pts.push_back({ { double(i) + (i == 2 && j == 2 ? 0.5 : 0.0), double(j), double(k) } });
  const DelaunayResult d = Tetrahedralize(pts, DelaunayOptions());
  ASSERT_TRUE(d.Error.empty());
  const SimplexMesh mesh(g, d.Points, d.Cells, 4);
  const std::vector<std::array<double, 3>> frame = mesh.FramePoints();
  std::vector<std::uint8_t> label(mesh.NumberOfElements());
  double labelled = 0.0;
  for (std::int64_t e = 0; e < mesh.NumberOfElements(); ++e)
  {
    double cx = 0.0;
    for (int v = 0; v < 4; ++v)
      cx += mesh.Points()[mesh.Cell(e)[v]][0] / 4;
    label[e] = cx < 2.2 ? 1 : 0;
    labelled += label[e] ? ElementMeasure(frame, mesh.Cell(e), 4) : 0.0;
  }
  for (const bool mirrored : { false, true })
  {
    ImageGeometry h = g;
    h.Direction = mirrored ? std::array<double, 9>{ { -1, 0, 0, 0, 1, 0, 0, 0, 1 } } : g.Direction;
    const SimplexMesh m(h, mesh.Points(), mesh.Cells(), 4);
    const std::vector<std::int64_t> faces = LabelBoundaryFaces(m, label);
    ASSERT_EQ(faces.size() % 3, 0u);
    // The cut's path, from the face adjacency, gives the same faces in the same order.
    std::int64_t hashedInterface = -1, adjacentInterface = -2;
    LabelBoundaryFaces(m, label, &hashedInterface);
    EXPECT_EQ(LabelBoundaryFaces(m, m.Faces(), label, &adjacentInterface), faces);
    EXPECT_EQ(adjacentInterface, hashedInterface);
    EXPECT_GT(hashedInterface, 0);
    std::map<std::pair<std::int64_t, std::int64_t>, int> edges;
    double enclosed = 0.0;
    const std::vector<std::array<double, 3>> world = m.WorldPoints();
    for (size_t f = 0; f < faces.size(); f += 3)
    {
      for (int k = 0; k < 3; ++k)
        edges[{ faces[f + k], faces[f + (k + 1) % 3] }]++;
      const auto &a = world[faces[f]], &b = world[faces[f + 1]], &c = world[faces[f + 2]];
      enclosed += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                    a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0;
    }
    for (const auto& e : edges)
    {
      EXPECT_EQ(e.second, 1);
      EXPECT_EQ(edges.count({ e.first.second, e.first.first }), 1u) << "open edge";
    }
    EXPECT_GT(labelled, 0.0);
    EXPECT_NEAR(enclosed, labelled, 1e-9 * labelled) << (mirrored ? "mirrored" : "identity");
  }
}

//------------------------------------------------------------------------------------------------
// Fast paths against naive references: each kernel's fast path claims the same sums in the same
// order as the plain definition, so the comparisons are exact.
namespace
{
// Small chunks in reverse order: stands in for threads, and for any split of the loops.
const ParallelFor Chunked = [](std::int64_t n, std::int64_t, const RangeFunction& body) {
  for (std::int64_t b = ((n - 1) / 3) * 3; b >= 0; b -= 3)
    body(b, std::min(n, b + 3));
};

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

TEST(Guards, EnergyInputsAreCheckedAndSeedsAlwaysHold)
{
  CutProblem pr = SeededChain({ 5, 5, 5, 5, 0, 0, 0, 0 });
  pr.ObjectSamples = { 5.0 };
  pr.BackgroundSamples = { 0.0 };
  // A tiny sigma with equal neighbours once gave 0 * inf = NaN capacities.
  BoykovJollyParameters tiny;
  tiny.Sigma = 1e-300;
  CutResult r = BoykovJollyCut(pr, tiny);
  ASSERT_TRUE(r.Error.empty()) << r.Error;
  EXPECT_TRUE(std::isfinite(r.Flow));
  EXPECT_EQ(r.Label.front(), 1);
  EXPECT_EQ(r.Label.back(), 0);
  // Non-finite or too large intensities, negative sizes and contacts are errors.
  CutProblem bad = pr;
  bad.Value[2] = std::nan("");
  EXPECT_NE(BoykovJollyCut(bad, BoykovJollyParameters()).Error.find("NaN"), std::string::npos);
  bad = pr;
  bad.Value[2] = 1e300;
  EXPECT_FALSE(BoykovJollyCut(bad, BoykovJollyParameters()).Error.empty());
  bad = pr;
  bad.Size[1] = -1;
  EXPECT_FALSE(BoykovJollyCut(bad, BoykovJollyParameters()).Error.empty());
  bad = pr;
  bad.Contact[0] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(BoykovJollyCut(bad, BoykovJollyParameters()).Error.empty());
  bad = pr;
  std::vector<std::int64_t> A(pr.Edges.First(), pr.Edges.First() + pr.Edges.Size());
  std::vector<std::int64_t> B(pr.Edges.Second(), pr.Edges.Second() + pr.Edges.Size());
  B[0] = 99;
  bad.Edges = GraphEdges::Owned(A, B);
  EXPECT_FALSE(BoykovJollyCut(bad, BoykovJollyParameters()).Error.empty());
  B.pop_back();
  bad.Edges = GraphEdges(A, B);
  EXPECT_FALSE(BoykovJollyCut(bad, BoykovJollyParameters()).Error.empty());
  BoykovJollyParameters huge;
  huge.Lambda = 1e300;
  EXPECT_FALSE(ValidateParameters(huge).empty());
  // An abort before the flow comes back as Aborted, with no labels.
  int calls = 0;
  const CutResult aborted = BoykovJollyCut(pr, BoykovJollyParameters(), [&](double) { return ++calls < 2; });
  EXPECT_TRUE(aborted.Aborted);
  EXPECT_TRUE(aborted.Label.empty());
}

TEST(Guards, HeartbeatReportsAbortsAndRethrows)
{
  int beats = 0;
  int value = 0;
  EXPECT_TRUE(RunWithHeartbeat<int>(
    [] {
      std::this_thread::sleep_for(std::chrono::milliseconds(120));
      return 7;
    },
    [&](double t) {
      EXPECT_GE(t, 0.0);
      EXPECT_LT(t, 1.0);
      ++beats;
      return true;
    },
    value, std::chrono::milliseconds(20)));
  EXPECT_EQ(value, 7);
  EXPECT_GE(beats, 2);
  // Abort: returns at the next beat, long before the task ends.
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(RunWithHeartbeat<int>(
    [] {
      std::this_thread::sleep_for(std::chrono::milliseconds(1500));
      return 1;
    },
    [](double) { return false; }, value, std::chrono::milliseconds(20)));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 0.5);
  EXPECT_THROW(RunWithHeartbeat<int>([]() -> int { throw std::bad_alloc(); }, NoProgress(), value), std::bad_alloc);
}

// TetGen quality refinement needs the box as its domain: it adds nodes, raises the smallest
// dihedral angle, and the mesh still tiles the box exactly once per voxel.
TEST(Delaunay, QualityRefinementRaisesTheMinimumDihedralAngle)
{
  ImageGeometry g;
  g.Dims = { { 21, 17, 13 } };
  g.Spacing = { { 1.0, 1.5, 2.0 } };
  std::mt19937 rng(3);
  std::vector<std::array<double, 3>> index;
  std::vector<int> used(g.Size(), 0);
  auto add = [&](int i, int j, int k) {
    if (!used[g.Index(i, j, k)]++)
      index.push_back({ { double(i), double(j), double(k) } });
  };
  for (int c = 0; c < 8; ++c)
    add((c & 1) ? 20 : 0, (c & 2) ? 16 : 0, (c & 4) ? 12 : 0);
  for (int t = 0; t < 30; ++t) // nodes on the faces, as Feature Nodes places boundary nodes
    add(rng() % 21, rng() % 17, (t % 2) ? 12 : 0), add(0, rng() % 17, rng() % 13), add(rng() % 21, 16, rng() % 13);
  for (int t = 0; t < 150; ++t)
    add(1 + rng() % 19, 1 + rng() % 15, 1 + rng() % 11);
  std::vector<std::array<double, 3>> frame;
  for (const auto& p : index)
    frame.push_back(g.IndexToFrame(p));
  DelaunayOptions plain, refined;
  refined.QualityRefinement = true;
  const DelaunayResult a = Tetrahedralize(frame, plain), b = Tetrahedralize(frame, refined);
  ASSERT_TRUE(a.Error.empty()) << a.Error;
  ASSERT_TRUE(b.Error.empty()) << b.Error;
  EXPECT_GT(b.Points.size(), a.Points.size());
  auto smallest = [&](const DelaunayResult& d) {
    std::vector<std::array<double, 3>> idx;
    for (const auto& p : d.Points)
      idx.push_back(g.FrameToIndex(p));
    const SimplexMesh mesh(g, idx, d.Cells, 4);
    std::vector<double> angle, ratio;
    ElementQuality(mesh, angle, ratio, SerialFor());
    const auto s = ComputeElementStatistics(ElementRasterizer(mesh), std::vector<double>(g.Size(), 1.0).data(), SerialFor());
    EXPECT_EQ(std::accumulate(s.PixelCount.begin(), s.PixelCount.end(), std::int64_t(0)), g.Size());
    return *std::min_element(angle.begin(), angle.end());
  };
  const double before = smallest(a), after = smallest(b);
  EXPECT_GT(after, before);
  EXPECT_GT(after, 5.0);
}

TEST(GraphEdges, GridEdgesAreTheFaceNeighboursInVoxelOrderAndBlocksSplitThem)
{
  for (const std::array<int, 3>& d : std::vector<std::array<int, 3>>{
         { { 5, 4, 3 } }, { { 7, 6, 1 } }, { { 1, 3, 4 } }, { { 2, 1, 1 } }, { { 6000, 3, 2 } }, { { 3, 2000, 3 } } })
  {
    // The list the voxel cut used to store: each voxel in raster order with its +x, +y, +z neighbour.
    std::vector<std::int64_t> A, B;
    const std::int64_t sy = d[0], sz = static_cast<std::int64_t>(d[0]) * d[1];
    for (int k = 0; k < d[2]; ++k)
      for (int j = 0; j < d[1]; ++j)
        for (int i = 0; i < d[0]; ++i)
        {
          const std::int64_t v = i + sy * j + sz * k;
          for (const auto& step : { std::make_pair(i + 1 < d[0], std::int64_t(1)), std::make_pair(j + 1 < d[1], sy),
                 std::make_pair(k + 1 < d[2], sz) })
          {
            if (step.first)
            {
              A.push_back(v);
              B.push_back(v + step.second);
            }
          }
        }
    const GraphEdges grid = GraphEdges::Grid(d[0], d[1], d[2]);
    ASSERT_EQ(grid.Size(), static_cast<std::int64_t>(A.size())) << d[0] << " " << d[1] << " " << d[2];
    std::int64_t seen = 0;
    for (std::int64_t k = 0; k < grid.Blocks(); ++k)
    {
      EXPECT_EQ(grid.BlockStart(k), seen);
      grid.ForEach(k, k + 1, [&](std::int64_t e, std::int64_t a, std::int64_t b) {
        EXPECT_EQ(e, seen);
        EXPECT_EQ(a, A[e]);
        EXPECT_EQ(b, B[e]);
        ++seen;
      });
    }
    EXPECT_EQ(seen, grid.Size());
    EXPECT_EQ(grid.BlockStart(grid.Blocks()), grid.Size());
    EXPECT_TRUE(grid.Same(GraphEdges::Grid(d[0], d[1], d[2])));
    const GraphEdges held = GraphEdges::Owned(A, B), copy = held;
    EXPECT_TRUE(held.Held() && copy.Same(held) && !GraphEdges(A, B).Held());
    EXPECT_FALSE(grid.Same(GraphEdges(A, B)));
    EXPECT_TRUE(GraphEdges(A, B).Same(GraphEdges::Owned(A, B)));
  }
}

TEST(SeedConnectivity, ComponentsAreNumberedInNodeOrder)
{
  // A chain 0-1-2-3-4-5 with labels 1 1 0 1 0 0, edges listed backwards.
  const std::vector<std::uint8_t> label = { 1, 1, 0, 1, 0, 0 };
  const std::vector<std::int64_t> A = { 4, 3, 2, 1, 0 }, B = { 5, 4, 3, 2, 1 };
  std::int64_t count = 0;
  const std::vector<std::int64_t> id = LabelComponents(label, GraphEdges(A, B), count);
  EXPECT_EQ(count, 4);
  EXPECT_EQ(id, (std::vector<std::int64_t>{ 0, 0, 1, 2, 3, 3 }));
  EXPECT_EQ(ObjectComponentSizes(label, GraphEdges(A, B), { 1, 2, 4, 8, 16, 32 }), (std::vector<double>{ 8, 3 }));
}

TEST(SeedConnectivity, VoxelCutKeepsWhatTheSeedsReachAndFillsHoles)
{
  // Two bright disks; the right one has a dark hole. One object seed, in the left disk.
  ImageGeometry g;
  g.Dims = { { 64, 32, 1 } };
  std::vector<double> values(g.Size());
  auto inside = [](int i, int j, int ci, double r) { return (i - ci) * (i - ci) + (j - 16) * (j - 16) <= r * r; };
  for (int j = 0; j < 32; ++j)
    for (int i = 0; i < 64; ++i)
      values[g.Index(i, j, 0)] = (inside(i, j, 16, 9) || (inside(i, j, 48, 9) && !inside(i, j, 48, 3))) ? 100.0 : 0.0;
  const std::vector<std::int64_t> object = { g.Index(16, 16, 0) }, background = { g.Index(1, 1, 0) };
  auto cut = [&](Connectivity mode) {
    VoxelCutParameters p;
    p.Connectivity = mode;
    p.Lambda = 1.0;
    const CutResult r = VoxelCut(values, g, object, background, p);
    EXPECT_TRUE(r.Error.empty()) << r.Error;
    return r;
  };
  const CutResult off = cut(Connectivity::Off), fill = cut(Connectivity::FillHoles),
                  seeded = cut(Connectivity::SeededObject);
  const std::int64_t left = g.Index(16, 20, 0), ring = g.Index(48, 22, 0), hole = g.Index(48, 16, 0);
  EXPECT_EQ(off.Label[left], 1);
  EXPECT_EQ(off.Label[ring], 1);
  EXPECT_EQ(off.Label[hole], 0);
  EXPECT_EQ(off.ObjectComponentVoxels.size(), 2u);
  EXPECT_EQ(off.ConnectivityChanged, 0);
  EXPECT_EQ(fill.Label[ring], 1);
  EXPECT_EQ(fill.Label[hole], 1);
  EXPECT_EQ(fill.ConnectivityChanged, 29); // the hole: the lattice points within radius 3
  EXPECT_EQ(seeded.Label[left], 1);
  EXPECT_EQ(seeded.Label[ring], 0);
  EXPECT_EQ(seeded.Label[hole], 0);
  ASSERT_EQ(seeded.ObjectComponentVoxels.size(), 1u);
  EXPECT_EQ(seeded.ObjectComponentVoxels[0], off.ObjectComponentVoxels[0]);
  EXPECT_EQ(seeded.Label[background[0]], 0);
}

namespace
{
// Two bright disks of one intensity on a dark background, noise-free; object seeds in the left disk.
struct TwoDisks
{
  ImageGeometry G;
  std::vector<float> Image;
  std::vector<std::int64_t> Object, Background;
  std::int64_t Left, Right;
  TwoDisks()
  {
    G.Dims = { { 72, 36, 1 } };
    Image.resize(G.Size());
    for (int j = 0; j < 36; ++j)
      for (int i = 0; i < 72; ++i)
        Image[G.Index(i, j, 0)] = (std::hypot(i - 18, j - 18) <= 10 || std::hypot(i - 54, j - 18) <= 10) ? 100.f : 10.f;
    Object = { G.Index(18, 18, 0), G.Index(15, 20, 0) };
    Background = { G.Index(2, 2, 0), G.Index(36, 18, 0), G.Index(69, 33, 0) };
    Left = G.Index(20, 14, 0);
    Right = G.Index(54, 18, 0);
  }
};

// A flat image with a little noise (the same intensities inside and out) crossed by a faint ring
// of radius 20: the seed histograms cannot tell object from background, and the boundary term alone
// prefers a small cut around the object seed to the ring's long one.
struct RingImage
{
  ImageGeometry G;
  std::vector<float> Image;
  std::vector<std::int64_t> Object, Background;
  RingImage()
  {
    const int n = 64;
    const double c = n / 2;
    G.Dims = { { n, n, 1 } };
    Image.resize(G.Size());
    std::mt19937 rng(7);
    std::normal_distribution<float> noise(0.f, 1.f);
    const float low = 40.f;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
      {
        const double r = std::hypot(i - c, j - c);
        Image[G.Index(i, j, 0)] = (r >= 20 && r <= 22 ? low : 60.f) + noise(rng);
      }
    Object = { G.Index(n / 2, n / 2, 0) };
    Background = { G.Index(2, 2, 0), G.Index(n - 3, n - 3, 0), G.Index(2, n - 3, 0), G.Index(n - 3, 2, 0) };
  }
  double Radius(std::int64_t v) const { return std::hypot(v % G.Dims[0] - G.Dims[0] / 2, v / G.Dims[0] - G.Dims[0] / 2); }
  bool Inside(std::int64_t v) const { return Radius(v) < 19.5; }
  bool Outside(std::int64_t v) const { return Radius(v) > 22.5; }
};

// A 2D mesh of the image's box on a lattice of spacing 2 (so elements are super-pixels of ~2 pixels),
// with its statistics and prepared cut data.
struct LatticeMesh
{
  SimplexMesh Mesh;
  ElementStatistics Stats;
  std::vector<double> Count;
  SuperVoxelCutData Data;
  bool Make(const ImageGeometry& g, const std::vector<float>& image)
  {
    std::vector<std::array<double, 3>> pts;
    for (int j = 0; j < g.Dims[1]; j += 2)
      for (int i = 0; i < g.Dims[0]; i += 2)
        pts.push_back({ { double(i), double(j), 0.0 } });
    for (int j = 0; j < g.Dims[1]; ++j)
      pts.push_back({ { double(g.Dims[0] - 1), double(j), 0.0 } });
    for (int i = 0; i < g.Dims[0]; ++i)
      pts.push_back({ { double(i), double(g.Dims[1] - 1), 0.0 } });
    if (!CGALMeshOfNodes(g, pts, this->Mesh))
      return false;
    this->Stats = ComputeElementStatistics(ElementRasterizer(this->Mesh), image.data(), SerialFor());
    this->Count.assign(this->Stats.PixelCount.begin(), this->Stats.PixelCount.end());
    std::string error;
    return PrepareSuperVoxelCut(this->Mesh, image.data(), this->Data, error, SerialFor());
  }
  // The cut's labels on the pixel grid.
  std::vector<std::uint8_t> Cut(const std::vector<float>& image, const std::vector<std::int64_t>& object,
    const std::vector<std::int64_t>& background, const SuperVoxelCutParameters& par)
  {
    const VoxelValueFunction value = [&](std::int64_t v) { return static_cast<double>(image[v]); };
    const SuperVoxelCutResult r =
      SuperVoxelCut(this->Mesh, this->Data, this->Stats.Mean, this->Count, object, background, value, par, SerialFor());
    EXPECT_TRUE(r.Error.empty()) << r.Error;
    std::vector<std::uint8_t> pixels(this->Mesh.Geometry().Size(), 0);
    if (r.Error.empty())
      VoxelLabels(this->Data.Owner, r.Cut.Label, pixels.data(), SerialFor());
    return pixels;
  }
};
} // namespace

TEST(Task, ObjectKeepsTheSeededDiskAndClassKeepsBoth)
{
  // Both disks look alike: by the histograms either is object. Task Object asks for the one the
  // seeds lie in, Task Class for every object like it; both cuts, default connectivity (From Task).
  const TwoDisks d;
  const std::vector<double> values(d.Image.begin(), d.Image.end());
  LatticeMesh m;
  ASSERT_TRUE(m.Make(d.G, d.Image));
  for (Task task : { Task::Object, Task::Class })
  {
    VoxelCutParameters vp;
    vp.Task = task;
    const CutResult voxel = VoxelCut(values, d.G, d.Object, d.Background, vp);
    ASSERT_TRUE(voxel.Error.empty()) << voxel.Error;
    SuperVoxelCutParameters sp;
    sp.Task = task;
    const std::vector<std::uint8_t> super = m.Cut(d.Image, d.Object, d.Background, sp);
    for (const auto* label : { &voxel.Label, &super })
    {
      EXPECT_EQ((*label)[d.Left], 1);
      EXPECT_EQ((*label)[d.Right], task == Task::Class ? 1 : 0);
    }
    EXPECT_EQ(voxel.ObjectComponentVoxels.size(), task == Task::Class ? 2u : 1u);
  }
}

TEST(Task, TheGeodesicTermFindsWhatTheHistogramsCannot)
{
  // Inside and outside the ring have the same intensities: without the spatial term the object
  // shrinks to its seed; with it the object is the ring's inside, on the voxel grid and on the
  // elements. Connectivity off: the term alone decides.
  const RingImage ring;
  const std::vector<double> values(ring.Image.begin(), ring.Image.end());
  LatticeMesh m;
  ASSERT_TRUE(m.Make(ring.G, ring.Image));
  auto score = [&](const std::vector<std::uint8_t>& label) {
    std::int64_t inside = 0, insideObject = 0, outsideObject = 0;
    for (std::int64_t v = 0; v < ring.G.Size(); ++v)
    {
      inside += ring.Inside(v);
      insideObject += ring.Inside(v) && label[v];
      outsideObject += ring.Outside(v) && label[v];
    }
    return std::make_pair(static_cast<double>(insideObject) / inside, outsideObject);
  };
  for (double weight : { 0.0, SeedGeodesicParameters().Weight })
  {
    VoxelCutParameters vp;
    vp.Connectivity = Connectivity::Off;
    vp.Geodesic.Weight = weight;
    const CutResult voxel = VoxelCut(values, ring.G, ring.Object, ring.Background, vp);
    ASSERT_TRUE(voxel.Error.empty()) << voxel.Error;
    SuperVoxelCutParameters sp;
    sp.Connectivity = Connectivity::Off;
    sp.Geodesic.Weight = weight;
    const std::vector<std::uint8_t> super = m.Cut(ring.Image, ring.Object, ring.Background, sp);
    for (const auto* label : { &voxel.Label, &super })
    {
      const auto [filled, leaked] = score(*label);
      if (weight > 0)
      {
        EXPECT_GT(filled, 0.97) << (label == &super ? "elements" : "voxels");
        // Elements of the 2-pixel lattice may straddle the ring's outer edge by a pixel.
        EXPECT_LE(leaked, label == &super ? 8 : 0) << (label == &super ? "elements" : "voxels");
      }
      else
      {
        EXPECT_LT(filled, 0.05) << (label == &super ? "elements" : "voxels");

      }
    }
  }
}

TEST(SeedGeodesics, KeptDistancesEqualFreshOnes)
{
  // A noisy 40 x 30 grid as explicit edges with random steps; a chain of seed edits through one
  // cache: seeds added, removed, moved, both kinds at once, nothing changed. Every cut's costs
  // equal those computed afresh (up to the rounding of equal-length paths summed in another order).
  ImageGeometry g = Grid2(40, 30);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> value(g.Size());
  for (int j = 0; j < 30; ++j)
    for (int i = 0; i < 40; ++i)
      value[g.Index(i, j, 0)] = (std::hypot(i - 15, j - 15) < 9 ? 50.0 : 10.0) + 5.0 * u(rng);
  std::vector<std::int64_t> a, b;
  std::vector<double> step;
  GraphEdges::Grid(40, 30, 1).ForEach([&](std::int64_t, std::int64_t p, std::int64_t q) {
    a.push_back(p);
    b.push_back(q);
    step.push_back(0.5 + u(rng));
  });
  const GraphEdges edges(a, b);
  GeodesicGraph graph;
  graph.Edges = &edges;
  graph.Value = value.data();
  graph.Nodes = g.Size();
  graph.Step = &step;
  const std::vector<std::vector<std::int64_t>> object = { { g.Index(15, 15, 0) }, { g.Index(15, 15, 0), g.Index(12, 18, 0) },
    { g.Index(12, 18, 0) }, { g.Index(13, 18, 0) }, { g.Index(13, 18, 0), g.Index(18, 12, 0) }, { g.Index(13, 18, 0), g.Index(18, 12, 0) },
    { g.Index(16, 16, 0) } };
  const std::vector<std::vector<std::int64_t>> background = { { g.Index(1, 1, 0) }, { g.Index(1, 1, 0) },
    { g.Index(1, 1, 0), g.Index(38, 28, 0) }, { g.Index(38, 28, 0) }, { g.Index(2, 1, 0), g.Index(30, 5, 0) },
    { g.Index(2, 1, 0), g.Index(30, 5, 0) }, { g.Index(39, 29, 0), g.Index(0, 29, 0) } };
  SeedGeodesicCache cache;
  SeedGeodesicParameters p;
  for (std::size_t edit = 0; edit < object.size(); ++edit)
  {
    std::vector<std::uint8_t> hard(g.Size(), 0);
    for (std::int64_t v : object[edit])
      hard[v] = 1;
    for (std::int64_t v : background[edit])
      hard[v] = 2;
    std::vector<double> keptObject, keptBackground, freshObject, freshBackground;
    ASSERT_TRUE(SeedGeodesicCosts(graph, hard, 40.0, p, SerialFor(), keptObject, keptBackground, NoProgress(), &cache));
    ASSERT_TRUE(SeedGeodesicCosts(graph, hard, 40.0, p, SerialFor(), freshObject, freshBackground));
    ASSERT_EQ(keptObject.size(), freshObject.size());
    for (std::size_t v = 0; v < freshObject.size(); ++v)
    {
      ASSERT_NEAR(keptObject[v], freshObject[v], 1e-9) << "edit " << edit << " node " << v;
      ASSERT_NEAR(keptBackground[v], freshBackground[v], 1e-9) << "edit " << edit << " node " << v;
    }
    for (int kind : { 1, 2 })
    {
      const std::vector<double> d = GeodesicDistances(graph, hard, static_cast<std::uint8_t>(kind), 40.0, p.LengthWeight);
      for (std::int64_t v : kind == 1 ? object[edit] : background[edit])
        EXPECT_EQ(d[v], 0.0);
    }
  }
}

TEST(SeedGeodesics, DistancesAddTheStepsAndTheLength)
{
  // A chain 0 - 1 - 2 - 3 of values 0, 0, 10, 10 (range 10): each step costs |dI| / 10 plus the
  // length weight per voxel of step; the spatial costs favour the seed's side.
  const std::vector<std::int64_t> a = { 0, 1, 2 }, b = { 1, 2, 3 };
  const GraphEdges edges(a, b);
  const std::vector<double> value = { 0, 0, 10, 10 }, step = { 1, 2, 1 };
  GeodesicGraph graph;
  graph.Edges = &edges;
  graph.Value = value.data();
  graph.Nodes = 4;
  graph.Step = &step;
  const std::vector<std::uint8_t> hard = { 1, 0, 0, 2 };
  const std::vector<double> d = GeodesicDistances(graph, hard, 1, 10.0, 0.1);
  ASSERT_EQ(d.size(), 4u);
  EXPECT_DOUBLE_EQ(d[0], 0.0);
  EXPECT_DOUBLE_EQ(d[1], 0.1);
  EXPECT_DOUBLE_EQ(d[2], 0.1 + 1.0 + 0.2);
  EXPECT_DOUBLE_EQ(d[3], 1.3 + 0.1);
  std::vector<double> costObject, costBackground;
  SeedGeodesicParameters p;
  ASSERT_TRUE(SeedGeodesicCosts(graph, hard, 10.0, p, SerialFor(), costObject, costBackground));
  ASSERT_EQ(costObject.size(), 4u);
  EXPECT_LT(costObject[1], costBackground[1]);
  EXPECT_GT(costObject[2], costBackground[2]);
  // Without a background seed there is no term.
  ASSERT_TRUE(SeedGeodesicCosts(graph, { 1, 0, 0, 0 }, 10.0, p, SerialFor(), costObject, costBackground));
  EXPECT_TRUE(costObject.empty());
  p.Weight = -1;
  EXPECT_FALSE(ValidateParameters(p).empty());
}

// ---- Stage 3: image mesh smoothing ----
namespace
{
// A 4 x 4 square of fixed nodes (2,2)-(6,6) on a 10 x 10 grid and one free node at (3,3): four
// triangles, areas 2 (bottom), 6 (right), 6 (top), 2 (left).
SimplexMesh FreeNodeInSquare()
{
  std::vector<std::array<double, 3>> pts = { { { 2, 2, 0 } }, { { 6, 2, 0 } }, { { 6, 6, 0 } }, { { 2, 6, 0 } },
    { { 3, 3, 0 } } };
  std::vector<std::int64_t> cells = { 4, 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0 };
  return SimplexMesh(Grid2(10, 10), pts, cells, 3);
}

// A mesh tiling the box of `g` from jittered-lattice nodes (corners included) and a few clustered
// ones, with every third interior node fixed; Delaunay (CGAL) in index space.
SimplexMesh JitteredMesh(const ImageGeometry& g, std::vector<std::uint8_t>& fixed, unsigned seed)
{
  std::mt19937 rng(seed);
  std::vector<std::array<double, 3>> pts;
  std::set<std::array<int, 3>> used;
  const int dim = g.Dimension();
  for (int c = 0; c < (1 << dim); ++c)
  {
    std::array<int, 3> q = { { (c & 1) ? g.Dims[0] - 1 : 0, (c & 2) ? g.Dims[1] - 1 : 0, (c & 4) ? g.Dims[2] - 1 : 0 } };
    used.insert(q);
  }
  for (int t = 0; t < (dim == 2 ? 120 : 220); ++t)
  {
    std::array<int, 3> q = { { int(rng() % g.Dims[0]), int(rng() % g.Dims[1]), dim == 2 ? 0 : int(rng() % g.Dims[2]) } };
    used.insert(q);
    // A close neighbour now and then: short edges, bad elements.
    if (t % 7 == 0)
    {
      q[0] = std::min(q[0] + 1, g.Dims[0] - 1);
      used.insert(q);
    }
  }
  for (const auto& q : used)
  {
    pts.push_back({ { double(q[0]), double(q[1]), double(q[2]) } });
  }
  DelaunayOptions o;
  o.Backend = DelaunayBackend::CGAL;
  const DelaunayResult d = dim == 2 ? Triangulate2D(pts) : Tetrahedralize(pts, o);
  EXPECT_TRUE(d.Error.empty()) << d.Error;
  fixed.assign(pts.size(), 0);
  for (size_t i = 0; i < pts.size(); i += 3)
  {
    fixed[i] = 1;
  }
  return SimplexMesh(g, d.Points, d.Cells, d.VerticesPerCell);
}

double MinimumAngle(const SimplexMesh& mesh)
{
  std::vector<double> angle, ratio;
  ElementQuality(mesh, angle, ratio, SerialFor());
  return *std::min_element(angle.begin(), angle.end());
}
} // namespace

TEST(MeshSmoothing, TargetsOfOneFreeNodeMatchTheFormulas)
{
  const SimplexMesh mesh = FreeNodeInSquare();
  const std::int64_t star[4] = { 0, 1, 2, 3 };
  const double uniform[4] = { 1, 1, 1, 1 }, heavyRight[4] = { 1, 2, 1, 1 };
  // Centroids (11/3, 7/3), (5, 11/3), (11/3, 5), (7/3, 11/3); circumcentres (4, 1), (5, 4), (4, 5),
  // (1, 4); weights area x density.
  auto expect = [&](const double* density, SmoothingMethod method, double x, double y) {
    const auto t = SmoothingTarget(mesh, mesh.Points(), star, 4, density, method);
    EXPECT_NEAR(t[0], x, 1e-12);
    EXPECT_NEAR(t[1], y, 1e-12);
    EXPECT_EQ(t[2], 0.0);
  };
  expect(uniform, SmoothingMethod::CVT, 4.0, 4.0);
  expect(uniform, SmoothingMethod::ODT, 4.0, 4.0);
  expect(heavyRight, SmoothingMethod::CVT, 94.0 / 22.0, 86.0 / 22.0);
  expect(heavyRight, SmoothingMethod::ODT, 94.0 / 22.0, 88.0 / 22.0);

  // Anisotropic spacing: measures and centres in frame units, the target back in index units.
  ImageGeometry g = Grid2(10, 10);
  g.Spacing = { { 2.0, 1.0, 1.0 } };
  const SimplexMesh stretched(g, mesh.Points(), mesh.Cells(), 3);
  const auto t = SmoothingTarget(stretched, stretched.Points(), star, 4, heavyRight, SmoothingMethod::CVT);
  EXPECT_NEAR(t[0], 94.0 / 22.0, 1e-12); // centroids scale with the frame; the weights' ratios do not change
  EXPECT_NEAR(t[1], 86.0 / 22.0, 1e-12);
}

TEST(MeshSmoothing, DensityGrowsWithTheGradientAndIsOneWhenFlat)
{
  const SimplexMesh mesh = FreeNodeInSquare();
  std::vector<float> gradient(100, 0.f);
  EXPECT_EQ(ElementDensity(mesh, mesh.Points(), 0, gradient.data(), 0.0, 1.0), 1.0);
  std::fill(gradient.begin(), gradient.end(), 2.f);
  // Constant g = mean: rho = 1 + w.
  EXPECT_NEAR(ElementDensity(mesh, mesh.Points(), 1, gradient.data(), 2.0, 3.0), 4.0, 1e-12);
  // g = x: the samples average the centroid's and the sub-triangles' x, which is the centroid's x.
  for (int j = 0; j < 10; ++j)
    for (int i = 0; i < 10; ++i)
      gradient[j * 10 + i] = float(i);
  EXPECT_NEAR(ElementDensity(mesh, mesh.Points(), 1, gradient.data(), 1.0, 1.0), 1.0 + 5.0, 1e-12);
}

TEST(MeshSmoothing, FixedNodesStayBoxNodesSlideAndTheMeshStaysValid)
{
  for (int dim : { 2, 3 })
  {
    ImageGeometry g;
    g.Dims = dim == 2 ? std::array<int, 3>{ { 48, 40, 1 } } : std::array<int, 3>{ { 18, 16, 14 } };
    std::vector<std::uint8_t> fixed;
    const SimplexMesh mesh = JitteredMesh(g, fixed, 11);
    std::vector<float> image(g.Size());
    for (int k = 0; k < g.Dims[2]; ++k)
      for (int j = 0; j < g.Dims[1]; ++j)
        for (int i = 0; i < g.Dims[0]; ++i)
          image[g.Index(i, j, k)] = std::hypot(i - 20.0, j - 17.0) < 9.0 ? 200.f : 20.f;
    MeshSmoothingParameters p;
    const MeshSmoothingResult r = SmoothImageMesh(mesh, fixed, image.data(), p, SerialFor());
    ASSERT_TRUE(r.Error.empty()) << r.Error;
    ASSERT_FALSE(r.Aborted);
    EXPECT_EQ(r.IterationsRun, p.Iterations);
    EXPECT_GT(r.Moves, 0);
    const SimplexMesh& out = r.Mesh;
    ASSERT_EQ(out.NumberOfPoints(), mesh.NumberOfPoints() + r.AddedNodes);
    const auto& P0 = mesh.Points();
    const auto& P1 = out.Points();
    std::int64_t snapped = 0;
    for (std::int64_t i = 0; i < mesh.NumberOfPoints(); ++i)
    {
      // 3D: a node within 1.5 voxels of the box moves onto it before refinement (SnappedNodes).
      bool nearBox = false;
      for (int a = 0; a < 3 && dim == 3; ++a)
      {
        const double d = std::min(P0[i][a], g.Dims[a] - 1.0 - P0[i][a]);
        nearBox = nearBox || (d > 0.0 && d <= 1.5);
      }
      snapped += fixed[i] && nearBox && P1[i] != P0[i] ? 1 : 0; // only the snap moves them
      for (int a = 0; a < 3; ++a)
      {
        const bool onFace = P0[i][a] == 0.0 || P0[i][a] == g.Dims[a] - 1.0;
        if ((fixed[i] && !nearBox) || onFace)
          ASSERT_EQ(P1[i][a], P0[i][a]) << "node " << i << " axis " << a;
        if (fixed[i] && nearBox && P1[i][a] != P0[i][a])
          ASSERT_TRUE(P1[i][a] == 0.0 || P1[i][a] == g.Dims[a] - 1.0) << "a fixed node moves only onto the box: node " << i;
        // Moved positions sit on the 1/1024-voxel lattice inside the box.
        ASSERT_EQ(P1[i][a] * 1024.0, std::round(P1[i][a] * 1024.0));
        ASSERT_GE(P1[i][a], 0.0);
        ASSERT_LE(P1[i][a], g.Dims[a] - 1.0);
      }
    }
    // Every element positively oriented (exactly), measures tile the box, every centre one owner.
    double measure = 0.0;
    for (std::int64_t e = 0; e < out.NumberOfElements(); ++e)
    {
      const std::int64_t* c = out.Cell(e);
      const int sign = dim == 2 ? Orientation2(P1[c[0]], P1[c[1]], P1[c[2]]) : Orientation3(P1[c[0]], P1[c[1]], P1[c[2]], P1[c[3]]);
      ASSERT_EQ(sign, 1) << "element " << e;
      measure += ElementMeasure(P1, c, out.VerticesPerCell());
    }
    const double box = (g.Dims[0] - 1.0) * (g.Dims[1] - 1.0) * (dim == 2 ? 1.0 : g.Dims[2] - 1.0);
    EXPECT_NEAR(measure, box, 1e-9 * box);
    ElementRasterizer raster(out);
    std::vector<int> owners(g.Size(), 0);
    for (std::int64_t e = 0; e < raster.NumberOfElements(); ++e)
      raster.ForEachVoxel(e, [&](std::int64_t v) { owners[v]++; });
    for (std::int64_t v = 0; v < g.Size(); ++v)
      ASSERT_EQ(owners[v], 1) << "voxel " << v;
    EXPECT_GT(MinimumAngle(out), MinimumAngle(mesh)) << dim << "D";
    EXPECT_LE(snapped, r.SnappedNodes);
    EXPECT_EQ(r.SnappedNodes > 0, dim == 3);
    // The same result split into any chunks (the threads' stand-in), and again.
    const MeshSmoothingResult again = SmoothImageMesh(mesh, fixed, image.data(), p, Chunked);
    EXPECT_EQ(again.Mesh.Points(), out.Points());
    EXPECT_EQ(again.Mesh.Cells(), out.Cells());
  }
}

TEST(MeshSmoothing, RefinementReachesTheAngleBounds)
{
  for (int dim : { 2, 3 })
  {
    ImageGeometry g;
    g.Dims = dim == 2 ? std::array<int, 3>{ { 48, 40, 1 } } : std::array<int, 3>{ { 18, 16, 14 } };
    std::vector<std::uint8_t> fixed;
    const SimplexMesh mesh = JitteredMesh(g, fixed, 5);
    std::fill(fixed.begin(), fixed.end(), 1); // nothing moves: refinement alone
    const std::vector<float> image(g.Size(), 1.f);
    MeshSmoothingParameters p;
    p.SliverRemoval = false;
    const MeshSmoothingResult r = SmoothImageMesh(mesh, fixed, image.data(), p, SerialFor());
    ASSERT_TRUE(r.Error.empty()) << r.Error;
    EXPECT_EQ(r.Moves, 0);
    EXPECT_GT(r.AddedNodes, 0);
    const double bound = dim == 2 ? p.MinAngle : p.MinDihedralAngle;
    EXPECT_LT(MinimumAngle(mesh), bound);
    // 3D keeps the box faces as they are (no node added on them), which can leave a few elements
    // at a face below the bound; 2D splits the box's sides as it needs.
    if (dim == 2)
      EXPECT_GE(MinimumAngle(r.Mesh), bound - 1e-9);
    else
      EXPECT_GT(MinimumAngle(r.Mesh), MinimumAngle(mesh));
  }
}

TEST(MeshSmoothing, BadParametersAreNamed)
{
  MeshSmoothingParameters p;
  EXPECT_TRUE(ValidateParameters(p).empty());
  p.Iterations = -1;
  EXPECT_NE(ValidateParameters(p).find("iterations"), std::string::npos);
  p = MeshSmoothingParameters();
  p.MinAngle = 25;
  EXPECT_NE(ValidateParameters(p).find("minimum angle"), std::string::npos);
  p = MeshSmoothingParameters();
  p.Sigma = 0;
  EXPECT_NE(ValidateParameters(p).find("sigma"), std::string::npos);
  p = MeshSmoothingParameters();
  p.FixedNodeSlack = -1;
  EXPECT_NE(ValidateParameters(p).find("slack"), std::string::npos);
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

namespace
{
// Voxel staircases: the cells of an n^d lattice (squares split in two triangles, cubes in the six
// Kuhn tetrahedra), labelled 1 when the cell's centre lies in the ball of radius `radius` round
// `centre`. The ball crosses the box face x = 0.
struct Staircase
{
  SimplexMesh Mesh;
  std::vector<std::uint8_t> Label;
};

Staircase StaircaseBall(int dim, int n, const std::array<double, 3>& centre, double radius)
{
  ImageGeometry g;
  g.Dims = { { n + 1, n + 1, dim == 3 ? n + 1 : 1 } };
  g.Spacing = { { 1.0, 1.5, 0.75 } }; // anisotropic: the smoothing works in world units
  std::vector<std::array<double, 3>> pts;
  for (int k = 0; k < g.Dims[2]; ++k)
    for (int j = 0; j < g.Dims[1]; ++j)
      for (int i = 0; i < g.Dims[0]; ++i)
        pts.push_back({ { double(i), double(j), double(k) } });
  std::vector<std::int64_t> cells;
  std::vector<std::uint8_t> label;
  const int perms[6][3] = { { 0, 1, 2 }, { 0, 2, 1 }, { 1, 0, 2 }, { 1, 2, 0 }, { 2, 0, 1 }, { 2, 1, 0 } };
  for (int k = 0; k < (dim == 3 ? n : 1); ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
      {
        const std::array<double, 3> c = { { (i + 0.5) * g.Spacing[0], (j + 0.5) * g.Spacing[1], dim == 3 ? (k + 0.5) * g.Spacing[2] : 0.0 } };
        const double r = std::hypot(c[0] - centre[0], c[1] - centre[1], c[2] - centre[2]);
        auto id = [&](int di, int dj, int dk) { return g.Index(i + di, j + dj, k + dk); };
        if (dim == 2)
        {
          const std::int64_t tri[6] = { id(0, 0, 0), id(1, 0, 0), id(1, 1, 0), id(0, 0, 0), id(1, 1, 0), id(0, 1, 0) };
          cells.insert(cells.end(), tri, tri + 6);
          label.insert(label.end(), 2, r < radius);
          continue;
        }
        for (const auto& p : perms)
        {
          std::array<int, 3> at = { { 0, 0, 0 } };
          cells.push_back(id(0, 0, 0));
          for (int s = 0; s < 3; ++s)
          {
            at[p[s]] = 1;
            cells.push_back(id(at[0], at[1], at[2]));
          }
          label.push_back(r < radius);
        }
      }
  Staircase s{ SimplexMesh(g, pts, cells, dim == 3 ? 4 : 3), label };
  s.Mesh.OrientPositively();
  return s;
}

// Mean distance (world units) of the boundary nodes off the box to the true sphere.
double MeanDistanceToSphere(const SimplexMesh& mesh, const std::vector<std::array<double, 3>>& points,
  const std::vector<std::int64_t>& faces, const std::array<double, 3>& centre, double radius)
{
  std::set<std::int64_t> nodes(faces.begin(), faces.end());
  double sum = 0;
  int count = 0;
  for (const std::int64_t v : nodes)
  {
    if (mesh.Points()[v][0] == 0.0)
    {
      continue;
    }
    const auto f = mesh.Geometry().IndexToFrame(points[v]);
    sum += std::fabs(std::hypot(f[0] - centre[0], f[1] - centre[1], f[2] - centre[2]) - radius);
    ++count;
  }
  return sum / count;
}
} // namespace

TEST(SurfaceSmoothing, StaircaseBallComesCloserToTheSphereAndTheMeshStaysValid)
{
  for (const int dim : { 2, 3 })
  {
    const std::array<double, 3> centre = { { 3.0, 13.0, dim == 3 ? 9.0 : 0.0 } };
    const double radius = 8.0;
    const Staircase s = StaircaseBall(dim, dim == 3 ? 18 : 24, centre, radius);
    ASSERT_TRUE(s.Mesh.Validate().empty());
    std::vector<double> before, ratio;
    ElementQuality(s.Mesh, before, ratio, SerialFor());
    const std::vector<std::int64_t> faces = LabelBoundaryFaces(s.Mesh, s.Label);
    const double staircase = MeanDistanceToSphere(s.Mesh, s.Mesh.Points(), faces, centre, radius);
    for (const auto method : { SurfaceSmoothingMethod::Laplacian, SurfaceSmoothingMethod::Taubin })
    {
      SCOPED_TRACE(std::to_string(dim) + "D, method " + std::to_string(int(method)));
      SurfaceSmoothingParameters p;
      p.Method = method;
      p.Iterations = method == SurfaceSmoothingMethod::Taubin ? 10 : 3;
      const SurfaceSmoothingResult r = SmoothSegmentationSurface(s.Mesh, s.Label, p, SerialFor());
      ASSERT_TRUE(r.Error.empty()) << r.Error;
      EXPECT_EQ(r.Faces, faces);
      EXPECT_GT(r.InterfaceFaces, 0);
      EXPECT_LT(r.InterfaceFaces * (dim), std::int64_t(faces.size()));
      EXPECT_EQ(r.PinchedNodes, 0);
      EXPECT_EQ(r.BoundaryPoints, r.Points);
      const double smoothed = MeanDistanceToSphere(s.Mesh, r.Points, faces, centre, radius);
      EXPECT_LT(smoothed, 0.8 * staircase) << staircase << " -> " << smoothed;
      // The mesh follows most of the smoothing: nodes whose star would flatten stop short, by less than
      // a fifth of the smoothing's own displacement on average (the positions without the volume mesh).
      EXPECT_LT(r.ShortNodes, r.BoundaryNodes / 4);
      SurfaceSmoothingParameters alone = p;
      alone.VolumeMesh = false;
      const SurfaceSmoothingResult targets = SmoothSegmentationSurface(s.Mesh, s.Label, alone, SerialFor());
      double shortfall = 0, displacement = 0;
      for (const std::int64_t v : std::set<std::int64_t>(faces.begin(), faces.end()))
      {
        const auto& g = s.Mesh.Geometry();
        const auto t = g.IndexToFrame(targets.BoundaryPoints[v]), a = g.IndexToFrame(r.Points[v]), o = g.IndexToFrame(s.Mesh.Points()[v]);
        shortfall += std::hypot(t[0] - a[0], t[1] - a[1], t[2] - a[2]);
        displacement += std::hypot(t[0] - o[0], t[1] - o[1], t[2] - o[2]);
      }
      EXPECT_LT(shortfall, 0.2 * displacement);
      EXPECT_NEAR(r.ReachedFraction, 1.0 - shortfall / displacement, 1e-9);
      SimplexMesh moved = s.Mesh;
      moved.SetPoints(r.Points);
      std::vector<double> after;
      ElementQuality(moved, after, ratio, SerialFor());
      const double floor = dim == 2 ? p.MinAngle : p.MinDihedralAngle;
      for (std::int64_t e = 0; e < moved.NumberOfElements(); ++e)
      {
        ASSERT_GT(ElementMeasure(r.Points, moved.Cell(e), moved.VerticesPerCell()), 0.0) << e;
        ASSERT_GE(after[e], std::min(floor, before[e]) - 1e-9) << e;
      }
      for (std::int64_t v = 0; v < moved.NumberOfPoints(); ++v)
      {
        for (int a = 0; a < dim; ++a)
        {
          const double was = s.Mesh.Points()[v][a];
          if (was == 0.0 || was == s.Mesh.Geometry().Dims[a] - 1.0)
          {
            ASSERT_EQ(r.Points[v][a], was) << v;
          }
        }
      }
      // Laplacian shrinks; Taubin keeps the measure within 1 %.
      const double change = r.ObjectMeasureAfter / r.ObjectMeasureBefore - 1.0;
      if (method == SurfaceSmoothingMethod::Taubin)
      {
        EXPECT_LT(std::fabs(change), 0.01);
      }
      else
      {
        EXPECT_LT(change, 0.0);
      }
      std::cout << dim << "D method " << int(method) << ": distance " << staircase << " -> " << smoothed
                << ", measure change " << change << ", short " << r.ShortNodes << "/" << r.BoundaryNodes
                << ", relaxed " << r.RelaxedNodes << ", max shortfall " << r.MaxShortfall << "\n";
    }
  }
}

TEST(SurfaceSmoothing, BadInputIsNamed)
{
  const Staircase s = StaircaseBall(2, 8, { { 4, 4, 0 } }, 3.0);
  SurfaceSmoothingParameters p;
  p.Relaxation = 0;
  EXPECT_FALSE(SmoothSegmentationSurface(s.Mesh, s.Label, p, SerialFor()).Error.empty());
  std::vector<std::uint8_t> bad = s.Label; // labels 2..255 are further objects (TestMultiLabel.cxx)
  bad.pop_back();
  EXPECT_FALSE(SmoothSegmentationSurface(s.Mesh, bad, SurfaceSmoothingParameters(), SerialFor()).Error.empty());
  // No object: nothing moves.
  const SurfaceSmoothingResult none =
    SmoothSegmentationSurface(s.Mesh, std::vector<std::uint8_t>(s.Label.size(), 0), SurfaceSmoothingParameters(), SerialFor());
  EXPECT_TRUE(none.Error.empty());
  EXPECT_TRUE(none.Faces.empty());
  EXPECT_EQ(none.Points, s.Mesh.Points());
}
