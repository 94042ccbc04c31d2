// Unit tests of the Base library (frame, simplex mesh, exact ownership) and the heartbeat.
#include "DelaunayImageMesh.h"
#include "ElementRasterizer.h"
#include "ImageGeometry.h"
#include "SimplexMesh.h"
#include "Vector3.h"
#include "Parallel.h"
#include "Percentile.h"
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
  DelaunayImageMeshParameters o;
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
  // The adjacency against a map of every element face by its sorted vertices: interior faces in
  // the order of those vertices, each with its two elements (the smaller first), their local faces
  // and its measure; the hull faces are the rest.
  const int vpc = mesh.VerticesPerCell;
  std::map<std::array<std::int64_t, 3>, std::vector<std::pair<std::int64_t, int>>> byVertices;
  for (std::int64_t e = 0; e < simplices.NumberOfElements(); ++e)
    for (int f = 0; f < vpc; ++f)
    {
      std::array<std::int64_t, 3> key{ { -1, -1, -1 } };
      int k = 0;
      for (int j = 0; j < vpc; ++j)
        if (j != f)
          key[k++] = simplices.Cell(e)[j];
      std::sort(key.begin(), key.begin() + vpc - 1);
      byVertices[key].emplace_back(e, f);
    }
  std::size_t interior = 0, hull = 0;
  const std::vector<std::array<double, 3>> frame = simplices.FramePoints();
  for (const auto& [key, sides] : byVertices)
  {
    ASSERT_LE(sides.size(), 2u);
    if (sides.size() == 1)
    {
      ASSERT_LT(hull, adj.HullElement.size());
      EXPECT_EQ(adj.HullElement[hull], sides[0].first);
      EXPECT_EQ(adj.HullFace[hull++], sides[0].second);
      continue;
    }
    ASSERT_LT(interior, adj.A.size());
    EXPECT_EQ(adj.A[interior], sides[0].first);
    EXPECT_EQ(adj.B[interior], sides[1].first);
    EXPECT_EQ(adj.LocalA[interior], sides[0].second);
    EXPECT_EQ(adj.LocalB[interior], sides[1].second);
    const vector3::V3 u = vector3::Sub(frame[key[1]], frame[key[0]]);
    const double measure = vpc == 3 ? vector3::Norm(u) : 0.5 * vector3::Norm(vector3::Cross(u, vector3::Sub(frame[key[2]], frame[key[0]])));
    EXPECT_NEAR(adj.Measure[interior++], measure, 1e-12 * (1.0 + measure));
  }
  EXPECT_EQ(interior, adj.A.size());
  EXPECT_EQ(hull, adj.HullElement.size());
}
INSTANTIATE_TEST_SUITE_P(Delaunay, Tiling, ::testing::Values(0, 1, 2));


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

// The histogram range's two percentiles from one partially sorted sample equal each rank's value
// in a full sort, with ties and a second channel; every 2nd tuple is sampled past 1 M tuples.
TEST(Statistics, StridedRangeIsTheSortedSamplesRanks)
{
  std::mt19937 rng(7);
  for (const std::int64_t n : { std::int64_t(1), std::int64_t(2), std::int64_t(1000), std::int64_t(96845), std::int64_t(2000001) })
  {
    std::vector<float> values(2 * n);
    for (float& v : values)
    {
      v = rng() % 5 == 0 ? 0.f : static_cast<float>(rng() % 256);
    }
    for (int c = 0; c < 2; ++c)
    {
      std::vector<double> sample;
      for (std::int64_t i = 0; i < n; i += std::max<std::int64_t>(1, n / 1000000))
      {
        sample.push_back(values[2 * i + c]);
      }
      std::sort(sample.begin(), sample.end());
      const auto at = [&](double q) { return sample[static_cast<std::size_t>(q / 100.0 * (sample.size() - 1) + 0.5)]; };
      const std::array<double, 2> range = StridedRange(values.data(), n, 2, c);
      EXPECT_EQ(range[0], at(0.5)) << n << " tuples, channel " << c;
      EXPECT_EQ(range[1], at(99.5)) << n << " tuples, channel " << c;
    }
  }
  EXPECT_EQ(StridedRange(static_cast<const float*>(nullptr), 0)[1], 0.0);
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

// Stages 2 and 3 write their elements in SpatialElementOrder: the same elements, renumbered so that
// face neighbours are near in the numbering (the mesher's numbering scatters them).
TEST(SimplexMesh, SortElementsSpatiallyKeepsTheElementsAndGathersNeighbours)
{
  ImageGeometry g;
  g.Dims = { { 40, 36, 32 } };
  std::mt19937 rng(11);
  std::vector<std::array<double, 3>> pts;
  for (int c = 0; c < 8; ++c)
    pts.push_back({ { (c & 1) ? g.Dims[0] - 1.0 : 0, (c & 2) ? g.Dims[1] - 1.0 : 0, (c & 4) ? g.Dims[2] - 1.0 : 0 } });
  for (int t = 0; t < 4000; ++t)
    pts.push_back({ { double(rng() % g.Dims[0]), double(rng() % g.Dims[1]), double(rng() % g.Dims[2]) } });
  std::sort(pts.begin(), pts.end());
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  const DelaunayResult delaunay = Tetrahedralize(pts, DelaunayImageMeshParameters());
  ASSERT_TRUE(delaunay.Error.empty()) << delaunay.Error;
  const SimplexMesh mesher(g, delaunay.Points, delaunay.Cells, delaunay.VerticesPerCell);
  SimplexMesh sorted = mesher;
  const FaceAdjacency& before = mesher.Faces(); // cached, then dropped by the sort
  sorted.SortElementsSpatially();
  ASSERT_EQ(sorted.NumberOfElements(), mesher.NumberOfElements());
  const auto rows = [](const SimplexMesh& m) {
    std::vector<std::array<std::int64_t, 4>> r(m.NumberOfElements());
    for (std::int64_t e = 0; e < m.NumberOfElements(); ++e)
      std::copy_n(m.Cell(e), 4, r[e].begin());
    std::sort(r.begin(), r.end());
    return r;
  };
  EXPECT_EQ(rows(sorted), rows(mesher)); // the same elements, each with its vertex order
  const std::vector<std::int64_t> order = SpatialElementOrder(sorted);
  for (std::int64_t e = 0; e < sorted.NumberOfElements(); ++e)
    ASSERT_EQ(order[e], e) << "sorting twice changes nothing";
  const auto medianGap = [](const FaceAdjacency& f) {
    std::vector<std::int64_t> gap(f.A.size());
    for (size_t i = 0; i < gap.size(); ++i)
      gap[i] = f.B[i] - f.A[i];
    std::nth_element(gap.begin(), gap.begin() + gap.size() / 2, gap.end());
    return gap[gap.size() / 2];
  };
  const FaceAdjacency& after = sorted.Faces();
  EXPECT_EQ(after.A.size(), before.A.size());
  EXPECT_LT(medianGap(after), 16) << "face neighbours near in the numbering";
  EXPECT_GT(medianGap(before), 4 * medianGap(after)) << "the mesher's numbering, for comparison";
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
  const DelaunayResult d = Tetrahedralize(pts, DelaunayImageMeshParameters());
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
