// Unit tests of the Meshing library (Delaunay meshes and their refinement, stage 2's nodes).
#include "DelaunayImageMesh.h"
#include "ElementRasterizer.h"
#include "ExactPredicates.h"
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
  DelaunayImageMeshParameters o;
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
  EXPECT_FALSE(Tetrahedralize(plane, DelaunayImageMeshParameters()).Error.empty());
  DelaunayImageMeshParameters cgal;
  cgal.Backend = DelaunayBackend::CGAL;
  EXPECT_FALSE(Tetrahedralize(plane, cgal).Error.empty());
  EXPECT_EQ(CountDuplicates({ { { 0, 0, 0 } }, { { 1, 0, 0 } }, { { 0, 0, 0 } } }), 1);
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
  DelaunayImageMeshParameters plain, refined;
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
