// Stage 6: smoothing of a segmentation's boundary on its labelled mesh, and the labelled mesh that
// carries the smoothed interface.
//
// The boundary is LabelBoundaryFaces (SimplexMesh.h): the faces between object and background
// elements and the object's hull faces, a closed surface (3D) or closed polylines (2D) on the mesh's
// points. Its nodes move by Laplacian smoothing (thesis 4.4: 3 iterations, relaxation 0.5) or by
// Taubin's lambda|mu smoothing, which does not shrink. Uniform weights over the boundary
// neighbours, in frame coordinates (index x |spacing|), Jacobi updates. A node on the image box
// moves only within its box face or edge; box corners never move. Where the interface meets the box
// a node averages its interface neighbours only (the object's faces on the box would pull the rim
// inwards). A node where the boundary is not
// a manifold (3D: an edge of more or fewer than two faces, or a vertex whose faces form several
// fans; 2D: a vertex of other than two edges) is a pinch between two parts of the object and stays
// (with several labels: unless it lies on a junction curve, see SmoothSegmentationSurface).
//
// The labelled mesh then follows: every boundary node moves towards its smoothed position in
// steps, the nodes within `RelaxationRings` of the boundary carry a share of the move that fades
// with the ring (a discrete harmonic extension), and a move is taken only when no element of the
// node's star inverts or falls below its quality floor: min(its angle before, MinAngle (2D) /
// MinDihedralAngle (3D)). Nodes that still stop short get room from quality-raising moves of their
// neighbours. The boundary output is then the labelled mesh's own boundary, so the two coincide;
// `ShortNodes` says how many boundary nodes did not reach their smoothed position.
#pragma once

#include "Parallel.h"
#include "SimplexMesh.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace featuremesh
{
enum class SurfaceSmoothingMethod
{
  Laplacian = 0, // thesis 4.4
  Taubin = 1     // lambda then mu per iteration: no shrinkage
};

struct SegmentationSurfaceSmoothingParameters
{
  // Taubin, 10 iterations: as smooth as the thesis's Laplacian 3 (thesis 4.4, relaxation 0.5)
  // without its shrinkage (docs/surface.md).
  SurfaceSmoothingMethod Method = SurfaceSmoothingMethod::Taubin;
  int Iterations = 10;
  double Relaxation = 0.5;
  // Taubin's pass-band frequency k_PB: mu = 1 / (k_PB - 1 / Relaxation).
  double PassBand = 0.1;
  // Move the labelled mesh's nodes with the boundary (output 1); off leaves the mesh as it was and
  // the boundary at its smoothed positions.
  bool VolumeMesh = true;
  // Quality floors of the labelled mesh (degrees), each element's own angle when lower before.
  double MinAngle = 15.0;
  double MinDihedralAngle = 8.0;
  // Rings of nodes around the boundary that move with it.
  int RelaxationRings = 2;
};

// Empty when usable, else a sentence naming the bad parameter.
std::string ValidateParameters(const SegmentationSurfaceSmoothingParameters& parameters);

struct SegmentationSurfaceSmoothingResult
{
  // Index-space points of the labelled mesh (moved when VolumeMesh, else as before) and the
  // boundary's positions: equal to Points on the boundary nodes when VolumeMesh.
  std::vector<std::array<double, 3>> Points;
  std::vector<std::array<double, 3>> BoundaryPoints;
  // LabelBoundaryFaces of the labels: vpc - 1 ids per face, interface faces first, then hull faces.
  std::vector<std::int64_t> Faces;
  std::int64_t InterfaceFaces = 0;
  std::int64_t BoundaryNodes = 0, PinchedNodes = 0, ShortNodes = 0, RelaxedNodes = 0;
  std::int64_t NonManifoldEdges = 0; // 3D: boundary edges with other than two faces
  // Distance (frame units) between each boundary node and its smoothed position (0 off the
  // boundary), and the largest.
  std::vector<double> Shortfall;
  double MaxShortfall = 0.0;
  // 1 - (summed shortfall) / (summed smoothing displacement): how much of the smoothing the mesh took.
  double ReachedFraction = 1.0;
  // Object measure (area 2D, volume 3D; world units) before and after.
  double ObjectMeasureBefore = 0.0, ObjectMeasureAfter = 0.0;
  double SurfaceSeconds = 0.0, VolumeSeconds = 0.0;
  bool Aborted = false;
  std::string Error;
};

// Smooths the boundary between the labels of `mesh` (one label per element, 0 background, 1..255
// objects) and, with VolumeMesh, moves the mesh with it. With several object labels every interface
// between two labels is smoothed; where three labels meet (a junction curve) a node moves along the
// curve only (the mean of its two curve neighbours), and where more meet, or a curve ends or
// branches (a junction point), it stays: the vertex classification of vtkWindowedSincPolyDataFilter's
// feature edges. ObjectMeasure is then the elements' measure summed over labels 1..k.
SegmentationSurfaceSmoothingResult SmoothSegmentationSurface(const SimplexMesh& mesh, const std::vector<std::uint8_t>& label,
  const SegmentationSurfaceSmoothingParameters& parameters, const ParallelFor& parallel,
  const ProgressFunction& progress = NoProgress());
} // namespace featuremesh
