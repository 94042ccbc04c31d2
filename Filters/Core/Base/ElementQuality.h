// The shape quality of triangles and tetrahedra: angles and radius ratios in frame (world) units,
// the measure stages 2, 3 and 6 report and bound (dihedral angles computed here: VTK 9.2's
// vtkMeshQuality depends on the vertex order).
#pragma once

#include "Parallel.h"
#include "SimplexMesh.h"

#include <array>
#include <cmath>
#include <vector>

namespace featuremesh
{
// Quality in frame (world) units: minimum angle (triangles) or minimum dihedral angle (tetrahedra)
// in degrees, and the radius ratio normalised to 1 for the equilateral element (2r/R, 3r/R).
void ElementQuality(const SimplexMesh& mesh, std::vector<double>& minAngle, std::vector<double>& radiusRatio,
  const ParallelFor& parallel);

// Minimum angle (triangle) or minimum dihedral angle (tetrahedron) in degrees of the element with
// vertices v[0..vpc) (any orientation; 0 for a flat one).
double SimplexMinAngle(const std::array<double, 3>* const* v, int verticesPerCell);

// A cheap stand-in for SimplexMinAngle, monotone in it (no inverse cosine): minus the largest cosine
// of the element's angles (triangle) or dihedral angles (tetrahedron); -cos(angle) at the angle.
double SimplexAngleScore(const std::array<double, 3>* const* v, int verticesPerCell);

// The SimplexAngleScore of an element whose smallest angle is `degrees`: a threshold on scores.
inline double AngleScoreAt(double degrees)
{
  return -std::cos(degrees * 3.14159265358979323846 / 180.0);
}
} // namespace featuremesh
