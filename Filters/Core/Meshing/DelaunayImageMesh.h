// Delaunay triangulation (2D, CGAL) and tetrahedralisation (3D, TetGen or CGAL) of mesh nodes.
// Library failures (TetGen throws, CGAL asserts by exception) come back as an error sentence.
#pragma once

#include "ImageGeometry.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace featuremesh
{
enum class DelaunayBackend
{
  TetGen = 0,
  CGAL = 1
};

struct DelaunayImageMeshParameters
{
  DelaunayBackend Backend = DelaunayBackend::TetGen;
  // TetGen quality refinement (adds nodes): radius-edge bound and minimum dihedral angle (deg).
  bool QualityRefinement = false;
  double RadiusEdgeRatio = 2.0;
  double MinDihedralAngle = 10.0;
  // TetGen's mesh optimisation after refinement (edge and face flips, smoothing of the nodes it
  // added) works on tetrahedra with a larger dihedral angle (deg); 165 is TetGen's own default.
  double MaxDihedralAngle = 165.0;
  // Refinement adds no node on the box faces (TetGen -Y): fewer nodes, where nodes near a face
  // would otherwise split it finely.
  bool PreserveBoundary = false;
};

struct DelaunayResult
{
  // Input points first, in input order, then any points the mesher added.
  std::vector<std::array<double, 3>> Points;
  // 3 (2D) or 4 (3D) point ids per element, positively oriented.
  std::vector<std::int64_t> Cells;
  int VerticesPerCell = 0;
  std::string Error;
};

// Points are (x, y[, z]); 2D uses x and y only. Positive orientation: counter-clockwise triangles,
// tetrahedra with det[b-a, c-a, d-a] > 0.
DelaunayResult Triangulate2D(const std::vector<std::array<double, 3>>& points);
DelaunayResult Tetrahedralize(const std::vector<std::array<double, 3>>& points, const DelaunayImageMeshParameters& options);

// Delaunay refinement of a mesh of the points over their bounding box (the box's faces are the
// domain boundary; every point is kept, at its index): 2D CGAL Delaunay_mesher_2 to a minimum angle
// of `minAngle` degrees (at most 20.7, its termination bound), 3D TetGen to `options`' radius-edge
// ratio and minimum dihedral angle. Added points follow the input points.
DelaunayResult RefineQuality2D(const std::vector<std::array<double, 3>>& points, double minAngle);

// True when the points span an area (dimension 2, xy) or a volume (dimension 3); exact predicates.
bool SpansDimension(const std::vector<std::array<double, 3>>& points, int dimension);

// Number of points that repeat an earlier point exactly.
std::int64_t CountDuplicates(const std::vector<std::array<double, 3>>& points);

// Stage 2 (Delaunay Image Mesh) meshes at most this many nodes: beyond, TetGen needs tens of GB and
// minutes; Feature Nodes places ~0.5 % of the voxels.
constexpr std::int64_t MaximumImageMeshNodes = 20000000;

// Empty when `options` can mesh an image (`planar`: 2D), else a sentence: 3D quality refinement
// needs a radius-edge ratio of at least 1.2 and a dihedral bound in [0, 18] degrees.
std::string ValidateParameters(const DelaunayImageMeshParameters& options, bool planar);

// Stage 2's nodes: `points` (world coordinates) into the image's index space, checked (enough of
// them, inside the image, on its plane in 2D, at most MaximumImageMeshNodes, no duplicates,
// spanning its area or volume) and followed by the box corners they lack, so that the mesh tiles
// the box. Empty when usable, else a sentence.
std::string ImageMeshNodes(const ImageGeometry& geometry, std::vector<std::array<double, 3>>& points);
} // namespace featuremesh
