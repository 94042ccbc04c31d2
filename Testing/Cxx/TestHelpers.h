// What the Core unit tests share: one test binary (FeatureMeshCoreTests), a file per Core library.
#pragma once

#include "DelaunayImageMesh.h"
#include "ElementQuality.h"
#include "ImageGeometry.h"
#include "Parallel.h"
#include "SimplexMesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace featuremesh_test
{
using namespace featuremesh;

// A 2D image frame of nx x ny voxels, unit spacing.
inline ImageGeometry Grid2(int nx, int ny)
{
  ImageGeometry g;
  g.Dims = { { nx, ny, 1 } };
  return g;
}

// A disk of 100 in a background of 10.
inline std::vector<float> Disk(const ImageGeometry& g, double cx, double cy, double r)
{
  std::vector<float> f(g.Size());
  for (int j = 0; j < g.Dims[1]; ++j)
    for (int i = 0; i < g.Dims[0]; ++i)
      f[g.Index(i, j, 0)] = std::hypot(i - cx, j - cy) <= r ? 100.f : 10.f;
  return f;
}

// The CGAL Delaunay mesh of distinct `pts` (index space; triangles for a 2D grid), positively
// oriented, into `mesh`; false (with a failure) when meshing fails.
// Nodes on every second voxel centre of a 2D grid, plus its last column and last row: a lattice
// mesh's nodes (the last corner appears twice).
inline std::vector<std::array<double, 3>> LatticeNodes(const ImageGeometry& g)
{
  std::vector<std::array<double, 3>> pts;
  for (int j = 0; j < g.Dims[1]; j += 2)
    for (int i = 0; i < g.Dims[0]; i += 2)
      pts.push_back({ { double(i), double(j), 0.0 } });
  for (int j = 0; j < g.Dims[1]; ++j)
    pts.push_back({ { double(g.Dims[0] - 1), double(j), 0.0 } });
  for (int i = 0; i < g.Dims[0]; ++i)
    pts.push_back({ { double(i), double(g.Dims[1] - 1), 0.0 } });
  return pts;
}

inline bool CGALMeshOfNodes(const ImageGeometry& g, std::vector<std::array<double, 3>> pts, SimplexMesh& mesh)
{
  std::sort(pts.begin(), pts.end());
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  DelaunayImageMeshParameters o;
  o.Backend = DelaunayBackend::CGAL;
  const DelaunayResult d = g.Is2D() ? Triangulate2D(pts) : Tetrahedralize(pts, o);
  EXPECT_TRUE(d.Error.empty()) << d.Error;
  if (!d.Error.empty())
    return false;
  mesh = SimplexMesh(g, d.Points, d.Cells, d.VerticesPerCell);
  mesh.OrientPositively();
  return true;
}

// Four triangles around the centre (2, 2) of a 5x5 image: 0 bottom, 1 right, 2 top, 3 left.
inline SimplexMesh FourTriangles(double sx = 1.0, double sy = 1.0)
{
  ImageGeometry g = Grid2(5, 5);
  g.Spacing = { { sx, sy, 1.0 } };
  std::vector<std::array<double, 3>> p = { { { 0, 0, 0 } }, { { 4, 0, 0 } }, { { 4, 4, 0 } }, { { 0, 4, 0 } },
    { { 2, 2, 0 } } };
  std::vector<std::int64_t> c = { 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4 };
  return SimplexMesh(g, p, c, 3);
}

// Small chunks in reverse order: stands in for threads, and for any split of the loops.
inline const ParallelFor Chunked = [](std::int64_t n, std::int64_t, const RangeFunction& body) {
  for (std::int64_t b = ((n - 1) / 3) * 3; b >= 0; b -= 3)
    body(b, std::min(n, b + 3));
};
} // namespace featuremesh_test
