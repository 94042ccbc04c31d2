// Unit tests of the Smoothing library (stage 3's image mesh smoothing, stage 6's surface smoothing).
#include "ImageMeshSmoothing.h"
#include "SegmentationSurfaceSmoothing.h"
#include "SliverFlips.h"
#include "ElementRasterizer.h"
#include "DelaunayImageMesh.h"
#include "TestHelpers.h"

#include <gtest/gtest.h>

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
  DelaunayImageMeshParameters o;
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

TEST(ImageMeshSmoothing, TargetsOfOneFreeNodeMatchTheFormulas)
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

TEST(ImageMeshSmoothing, DensityGrowsWithTheGradientAndIsOneWhenFlat)
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

TEST(ImageMeshSmoothing, FixedNodesStayBoxNodesSlideAndTheMeshStaysValid)
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
    ImageMeshSmoothingParameters p;
    const ImageMeshSmoothingResult r = SmoothImageMesh(mesh, fixed, image.data(), p, SerialFor());
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
    const ImageMeshSmoothingResult again = SmoothImageMesh(mesh, fixed, image.data(), p, Chunked);
    EXPECT_EQ(again.Mesh.Points(), out.Points());
    EXPECT_EQ(again.Mesh.Cells(), out.Cells());
  }
}

TEST(ImageMeshSmoothing, RefinementReachesTheAngleBounds)
{
  for (int dim : { 2, 3 })
  {
    ImageGeometry g;
    g.Dims = dim == 2 ? std::array<int, 3>{ { 48, 40, 1 } } : std::array<int, 3>{ { 18, 16, 14 } };
    std::vector<std::uint8_t> fixed;
    const SimplexMesh mesh = JitteredMesh(g, fixed, 5);
    std::fill(fixed.begin(), fixed.end(), 1); // nothing moves: refinement alone
    const std::vector<float> image(g.Size(), 1.f);
    ImageMeshSmoothingParameters p;
    p.SliverRemoval = false;
    const ImageMeshSmoothingResult r = SmoothImageMesh(mesh, fixed, image.data(), p, SerialFor());
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

namespace
{
// Signed volume of tetrahedron c of `cells`, index space.
double TetVolume(const std::vector<std::array<double, 3>>& p, const std::vector<std::int64_t>& cells, size_t c)
{
  return ElementMeasure(p, &cells[4 * c], 4);
}

// The faces with one tetrahedron (the boundary), as sorted vertex triples.
std::set<std::array<std::int64_t, 3>> BoundaryFaces(const std::vector<std::int64_t>& cells)
{
  std::map<std::array<std::int64_t, 3>, int> count;
  for (size_t c = 0; c < cells.size() / 4; ++c)
  {
    for (int k = 0; k < 4; ++k)
    {
      std::array<std::int64_t, 3> f = { { cells[4 * c + (k + 1) % 4], cells[4 * c + (k + 2) % 4], cells[4 * c + (k + 3) % 4] } };
      std::sort(f.begin(), f.end());
      ++count[f];
    }
  }
  std::set<std::array<std::int64_t, 3>> out;
  for (const auto& [f, n] : count)
  {
    EXPECT_LE(n, 2);
    if (n == 1)
      out.insert(f);
  }
  return out;
}

double MinimumDihedral(const ImageGeometry& g, const std::vector<std::array<double, 3>>& p, const std::vector<std::int64_t>& cells)
{
  return MinimumAngle(SimplexMesh(g, p, cells, 4));
}
} // namespace

TEST(SliverFlips, TwoThreeFlipReplacesAFlatTetrahedron)
{
  // A flat tetrahedron on the triangle 0-1-2 (apex 3 just above it) and a tall one below (apex 4):
  // the edge 3-4 crosses the triangle, and the three tetrahedra around it are better.
  ImageGeometry g;
  g.Dims = { { 4, 4, 4 } };
  const std::vector<std::array<double, 3>> p = { { { 0, 0, 1 } }, { { 3, 0, 1 } }, { { 0, 3, 1 } }, { { 1, 1, 1.2 } },
    { { 1, 1, -1 } } };
  std::vector<std::int64_t> cells = { 0, 1, 2, 3, 1, 0, 2, 4 };
  ASSERT_GT(TetVolume(p, cells, 0), 0.0);
  ASSERT_GT(TetVolume(p, cells, 1), 0.0);
  const double before = MinimumDihedral(g, p, cells), volume = TetVolume(p, cells, 0) + TetVolume(p, cells, 1);
  const auto boundary = BoundaryFaces(cells);
  // A sliver with a vertex that may move is left to perturbation.
  const std::vector<std::uint8_t> apexMoves = { 0, 0, 0, 1, 0 }, noneMove(5, 0);
  EXPECT_EQ(FlipSlivers(g, p, cells, 20.0, 4, &apexMoves), 0);
  EXPECT_EQ(FlipSlivers(g, p, cells, 20.0, 4, &noneMove), 1);
  ASSERT_EQ(cells.size(), 12u);
  double after = 0.0;
  for (size_t c = 0; c < 3; ++c)
  {
    EXPECT_GT(TetVolume(p, cells, c), 0.0) << c;
    after += TetVolume(p, cells, c);
  }
  EXPECT_NEAR(after, volume, 1e-12);
  EXPECT_EQ(BoundaryFaces(cells), boundary);
  EXPECT_GT(MinimumDihedral(g, p, cells), before);
  // Nothing to improve any more: a second call leaves the cells alone.
  const auto flipped = cells;
  FlipSlivers(g, p, cells, 20.0);
  EXPECT_EQ(cells, flipped);
}

TEST(ImageMeshSmoothing, TheLastResortMovesTheFixedVerticesOfASliver)
{
  // The box's corners and four nearly cocircular nodes, all fixed: their Delaunay tetrahedron is
  // a sliver no free vertex can mend. The last resort moves them (the corners stay) until every
  // tetrahedron reaches 10 degrees, keeps every element positive and the box tiled.
  ImageGeometry g;
  g.Dims = { { 11, 11, 11 } };
  std::vector<std::array<double, 3>> pts = { { { 4, 4, 5 } }, { { 6, 4, 5.125 } }, { { 6, 6, 5 } }, { { 4, 6, 5.125 } } };
  for (int c = 0; c < 8; ++c)
    pts.push_back({ { c & 1 ? 10.0 : 0.0, c & 2 ? 10.0 : 0.0, c & 4 ? 10.0 : 0.0 } });
  SimplexMesh mesh;
  ASSERT_TRUE(CGALMeshOfNodes(g, pts, mesh));
  ASSERT_LT(MinimumAngle(mesh), 10.0);
  const SimplexMesh before = mesh;
  std::int64_t moved = 0;
  // More slivers than allowed: the mesh is left as it was.
  EXPECT_FALSE(PerturbSliverVertices(mesh, 10.0, 0, moved));
  EXPECT_EQ(moved, 0);
  EXPECT_EQ(mesh.Points(), before.Points());
  EXPECT_TRUE(PerturbSliverVertices(mesh, 10.0, 64, moved));
  EXPECT_GT(moved, 0);
  EXPECT_GE(MinimumAngle(mesh), 10.0);
  EXPECT_EQ(mesh.Cells(), before.Cells());
  double volume = 0.0;
  for (std::int64_t e = 0; e < mesh.NumberOfElements(); ++e)
  {
    const std::array<double, 3>* v[4];
    for (int k = 0; k < 4; ++k)
      v[k] = &mesh.Points()[mesh.Cell(e)[k]];
    EXPECT_GT(SimplexMeasure(v, 4), 0.0) << e;
    volume += SimplexMeasure(v, 4);
  }
  EXPECT_NEAR(volume, 1000.0, 1e-9);
  for (std::size_t i = 0; i < pts.size(); ++i)
    for (int a = 0; a < 3; ++a)
      if (before.Points()[i][a] == 0.0 || before.Points()[i][a] == 10.0)
        EXPECT_EQ(mesh.Points()[i][a], before.Points()[i][a]) << i;
}

TEST(SliverFlips, ThreeTwoFlipRemovesAnEdge)
{
  // Three tetrahedra around the edge 3-4, which crosses the triangle 0-1-2 near its side 0-1: the
  // tetrahedron on that side is flat, the two on the triangle are not.
  ImageGeometry g;
  g.Dims = { { 6, 6, 6 } };
  const std::vector<std::array<double, 3>> p = { { { 0, 0, 2.5 } }, { { 3, 0, 2.5 } }, { { 1.5, 2.6, 2.5 } },
    { { 1.5, 0.1, 4.5 } }, { { 1.5, 0.1, 0.5 } } };
  std::vector<std::int64_t> cells;
  for (int i = 0; i < 3; ++i)
  {
    cells.insert(cells.end(), { i, (i + 1) % 3, 3, 4 });
    if (TetVolume(p, cells, i) < 0)
      std::swap(cells[4 * i], cells[4 * i + 1]);
  }
  const double before = MinimumDihedral(g, p, cells);
  const auto boundary = BoundaryFaces(cells);
  EXPECT_EQ(FlipSlivers(g, p, cells, 20.0), 1);
  ASSERT_EQ(cells.size(), 8u);
  EXPECT_GT(TetVolume(p, cells, 0), 0.0);
  EXPECT_GT(TetVolume(p, cells, 1), 0.0);
  EXPECT_EQ(BoundaryFaces(cells), boundary);
  EXPECT_GT(MinimumDihedral(g, p, cells), before);
}

TEST(SliverFlips, AJitteredMeshStaysATilingOfTheBoxAndImproves)
{
  ImageGeometry g;
  g.Dims = { { 18, 16, 14 } };
  g.Spacing = { { 1.0, 1.5, 0.8 } };
  std::vector<std::uint8_t> fixed;
  const SimplexMesh mesh = JitteredMesh(g, fixed, 5);
  std::vector<std::int64_t> cells = mesh.Cells();
  const auto& p = mesh.Points();
  const auto boundary = BoundaryFaces(cells);
  const double before = MinimumAngle(mesh);
  const std::int64_t flips = FlipSlivers(g, p, cells, 20.0);
  EXPECT_GT(flips, 0);
  double volume = 0.0;
  for (size_t c = 0; c < cells.size() / 4; ++c)
  {
    ASSERT_GT(TetVolume(p, cells, c), 0.0) << c;
    volume += TetVolume(p, cells, c);
  }
  EXPECT_NEAR(volume, 17.0 * 15.0 * 13.0, 1e-9);
  EXPECT_EQ(BoundaryFaces(cells), boundary);
  EXPECT_GE(MinimumDihedral(g, p, cells), before);
  // Every voxel centre still has exactly one owner.
  const SimplexMesh flipped(g, p, cells, 4);
  ElementRasterizer raster(flipped);
  std::vector<int> owners(g.Size(), 0);
  for (std::int64_t e = 0; e < flipped.NumberOfElements(); ++e)
  {
    raster.ForEachVoxel(e, [&](std::int64_t v) { ++owners[v]; });
  }
  EXPECT_TRUE(std::all_of(owners.begin(), owners.end(), [](int n) { return n == 1; }));
}

TEST(ImageMeshSmoothing, BadParametersAreNamed)
{
  ImageMeshSmoothingParameters p;
  EXPECT_TRUE(ValidateParameters(p).empty());
  p.Iterations = -1;
  EXPECT_NE(ValidateParameters(p).find("iterations"), std::string::npos);
  p = ImageMeshSmoothingParameters();
  p.MinAngle = 25;
  EXPECT_NE(ValidateParameters(p).find("minimum angle"), std::string::npos);
  p = ImageMeshSmoothingParameters();
  p.Sigma = 0;
  EXPECT_NE(ValidateParameters(p).find("sigma"), std::string::npos);
  p = ImageMeshSmoothingParameters();
  p.FixedNodeSlack = -1;
  EXPECT_NE(ValidateParameters(p).find("slack"), std::string::npos);
  p = ImageMeshSmoothingParameters();
  p.MaxDihedralAngle = 100;
  EXPECT_NE(ValidateParameters(p).find("maximum dihedral"), std::string::npos);
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

TEST(SegmentationSurfaceSmoothing, StaircaseBallComesCloserToTheSphereAndTheMeshStaysValid)
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
      SegmentationSurfaceSmoothingParameters p;
      p.Method = method;
      p.Iterations = method == SurfaceSmoothingMethod::Taubin ? 10 : 3;
      const SegmentationSurfaceSmoothingResult r = SmoothSegmentationSurface(s.Mesh, s.Label, p, SerialFor());
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
      SegmentationSurfaceSmoothingParameters alone = p;
      alone.VolumeMesh = false;
      const SegmentationSurfaceSmoothingResult targets = SmoothSegmentationSurface(s.Mesh, s.Label, alone, SerialFor());
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

TEST(SegmentationSurfaceSmoothing, BadInputIsNamed)
{
  const Staircase s = StaircaseBall(2, 8, { { 4, 4, 0 } }, 3.0);
  SegmentationSurfaceSmoothingParameters p;
  p.Relaxation = 0;
  EXPECT_FALSE(SmoothSegmentationSurface(s.Mesh, s.Label, p, SerialFor()).Error.empty());
  std::vector<std::uint8_t> bad = s.Label; // labels 2..255 are further objects (TestMultiLabel.cxx)
  bad.pop_back();
  EXPECT_FALSE(SmoothSegmentationSurface(s.Mesh, bad, SegmentationSurfaceSmoothingParameters(), SerialFor()).Error.empty());
  // No object: nothing moves.
  const SegmentationSurfaceSmoothingResult none =
    SmoothSegmentationSurface(s.Mesh, std::vector<std::uint8_t>(s.Label.size(), 0), SegmentationSurfaceSmoothingParameters(), SerialFor());
  EXPECT_TRUE(none.Error.empty());
  EXPECT_TRUE(none.Faces.empty());
  EXPECT_EQ(none.Points, s.Mesh.Points());
}
