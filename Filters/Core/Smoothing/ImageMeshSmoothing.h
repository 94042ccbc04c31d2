// Stage 3: image-weighted smoothing of an image mesh. Each iteration moves every free node once
// (multicolour Gauss-Seidel: nodes greedily coloured in id order so that one colour shares no
// element, colours in order, a colour's nodes in parallel; the result does not depend on the thread
// count) to its CVT or ODT position under a feature density, then restores the Delaunay property;
// Delaunay refinement then adds nodes where the angle bounds are still missed, and tetrahedral
// meshes finish with sliver flips and perturbation.
//
// Density (thesis 2.3): rho(T) = 1 + FeatureWeight * g(T) / mean(g), g(T) the gradient magnitude of
// the Gaussian-smoothed image averaged over T's centroid and the centroids of the sub-simplices
// that join it to T's faces (4 samples for a triangle, 5 for a tetrahedron). The 1 keeps flat
// regions (g = 0, e.g. the air around a brain) meshable; mean(g) makes the weight unit-free.
//
// Which nodes move: Fixed nodes never; a free node on the image box's surface slides in that face
// or edge only (box corners never move), so the mesh keeps tiling the box. A move that would
// invert an element, or lower the smallest angle of the node's star, is halved (twice) and then
// rejected. Moved positions are rounded to 1/1024 voxel in index space; the rasteriser's exact
// predicates keep voxel ownership exact off the lattice.
#pragma once

#include "Parallel.h"
#include "SimplexMesh.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace featuremesh
{
enum class SmoothingMethod
{
  CVT = 0, // thesis eq. 10: density-weighted mean of the star's centroids
  ODT = 1  // thesis eq. 12: density-weighted mean of the star's circumcentres
};

struct ImageMeshSmoothingParameters
{
  SmoothingMethod Method = SmoothingMethod::ODT;
  // Three sweeps: the thesis's five give the same angles after refinement, an oracle Dice within
  // 0.004 and 6-8 % fewer elements in 3D, for 0.5-0.6 s more on BraTS (docs/smoothing.md).
  int Iterations = 3;
  // Gaussian sigma (voxels) of the smoothing before the gradient magnitude.
  double Sigma = 1.0;
  // Weight of the gradient in the density; 0 gives plain (unweighted) CVT / ODT.
  double FeatureWeight = 1.0;
  // Fixed nodes (Canny) may slide up to this many voxels along their edge (normal to the smoothed
  // image's gradient); 0 keeps them where they are.
  double FixedNodeSlack = 0.0;
  // Restore the Delaunay property after each sweep (2D: Lawson edge flips; 3D: re-tetrahedralise).
  bool Flips = true;
  // After the sweeps, add nodes where elements stay below the angle bounds (Delaunay refinement:
  // 2D CGAL to MinAngle, at most 20.7 degrees; 3D TetGen to MinDihedralAngle and a radius-edge
  // ratio of 2). Added nodes are free.
  bool QualityRefinement = true;
  double MinAngle = 20.0;
  // 9: with DihedralFloor's last resort the shared 3D meshes keep 10 degrees with at most 15 %
  // added nodes; refining to 10.5 added up to 19 % (docs/smoothing.md).
  double MinDihedralAngle = 9.0;
  double RadiusEdgeRatio = 2.0;
  // 3D: TetGen's mesh optimisation (flips) works on tetrahedra whose largest dihedral angle exceeds
  // this (deg). 150 instead of TetGen's 165 takes the 1st percentile of the smallest dihedral
  // angle from 16 to 20 degrees on the shared 3D cases (docs/smoothing.md).
  double MaxDihedralAngle = 150.0;
  // 3D: after the last sweep, tetrahedra whose minimum dihedral angle is below SliverAngle
  // (degrees): 2-3 and 3-2 flips that raise it where no vertex may move (SliverFlips.h), else
  // perturbation of their free vertices.
  bool SliverRemoval = true;
  double SliverAngle = 20.0;
  // 3D with refinement and sliver removal: the smallest dihedral angle the mesh keeps (degrees).
  // Up to 64 tetrahedra under it get their vertices moved, fixed ones included
  // (PerturbSliverVertices); more, and refinement and sliver removal run again with TetGen's own
  // optimisation target.
  double DihedralFloor = 10.0;
};

// Empty when the parameters are usable, else a sentence naming the bad one.
std::string ValidateParameters(const ImageMeshSmoothingParameters& parameters);

// Density rho of an element of `mesh` (see above) with its vertices at `points` (index space), from
// a gradient-magnitude image on the mesh's grid; `meanGradient` is mean(g) over the image (0: rho = 1).
double ElementDensity(const SimplexMesh& mesh, const std::vector<std::array<double, 3>>& points, std::int64_t element,
  const float* gradient, double meanGradient, double featureWeight);

// Where CVT or ODT moves a vertex: sum over its star of rho * |T| * c_T / sum of rho * |T|, with c_T
// the centroid (CVT) or the circumcentre clamped into the image box (ODT); measures and centres in
// frame coordinates, the result in index space. `density` has one value per element of `star`.
std::array<double, 3> SmoothingTarget(const SimplexMesh& mesh, const std::vector<std::array<double, 3>>& points,
  const std::int64_t* star, std::int64_t starSize, const double* density, SmoothingMethod method);

struct ImageMeshSmoothingResult
{
  SimplexMesh Mesh;
  int IterationsRun = 0;
  std::int64_t Moves = 0;      // accepted moves over all sweeps
  std::int64_t Flips = 0;      // 2D edge flips (3D: tetrahedra changed by re-tetrahedralising)
  std::int64_t SliverFlips = 0; // 3D sliver-removal 2-3 and 3-2 flips
  std::int64_t Perturbed = 0;  // 3D sliver-removal moves
  std::int64_t AddedNodes = 0; // by quality refinement; they follow the input's points
  std::int64_t SnappedNodes = 0; // 3D: moved onto the image box before refinement
  int RefinementRuns = 0;        // 1, or 2 when TetGen's optimisation undercut the bound (then at 165 deg)
  // Seconds: sweeps (with the density image and the flips / re-tetrahedralisation), refinement, slivers.
  double SweepSeconds = 0, RefinementSeconds = 0, SliverSeconds = 0;
  bool Aborted = false;
  std::string Error;
};

// Smooths `mesh` (index space, elements positively oriented, tiling the image box) on the image
// `values` (one per voxel). `fixed` has one flag per mesh point.
ImageMeshSmoothingResult SmoothImageMesh(const SimplexMesh& mesh, const std::vector<std::uint8_t>& fixed, const float* values,
  const ImageMeshSmoothingParameters& parameters, const ParallelFor& parallel,
  const ProgressFunction& progress = NoProgress());

// Stage 3's last resort after refinement, flips and perturbation: the vertices of the tetrahedra
// whose smallest dihedral angle is under `degrees` take perturbation's short steps, fixed ones
// included (nodes on the image box's faces within them), up to three rounds. False, with `mesh`
// as it was, when more than `most` tetrahedra are under it; else whether all now reach it.
// `moved` counts the moves.
bool PerturbSliverVertices(SimplexMesh& mesh, double degrees, std::int64_t most, std::int64_t& moved);
} // namespace featuremesh
