// Exact assignment of voxel centres to the triangles / tetrahedra of a mesh that tiles the image box,
// and the per-element measures built on it (statistics, quality).
//
// Tie rule: a centre p on a shared edge/face belongs to the element that contains
// p + e(c - p) + e^2 t, e -> 0, with c the box centre and t a lexicographic direction. The first
// term pulls centres on the box surface inside, the second breaks the remaining ties, so every
// centre belongs to exactly one element. Node coordinates on voxel centres are integers in index
// space, so every test is exact in double arithmetic (added, off-lattice nodes are rounded).
#pragma once

#include "Parallel.h"
#include "SimplexMesh.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace featuremesh
{
class ElementRasterizer
{
public:
  // The mesh must outlive the rasteriser; its points are in index space (z = 0 in 2D), its
  // elements positively oriented.
  explicit ElementRasterizer(const SimplexMesh& mesh);

  const SimplexMesh& Mesh() const { return *this->M; }
  std::int64_t NumberOfElements() const { return this->M->NumberOfElements(); }

  // Calls visit(voxelIndex) for every voxel centre owned by the element, in raster order.
  template <typename Visitor>
  void ForEachVoxel(std::int64_t e, Visitor&& visit) const;

private:
  bool Owns(const double* plane, int faces, double x, double y, double z) const;

  const SimplexMesh* M;
  double TwiceCentre[3];
};

// Voxel value statistics per element: exact over owned centres; elements owning none take the
// value interpolated at their centroid and are flagged.
struct ElementStatistics
{
  bool Aborted = false;
  std::vector<std::int64_t> PixelCount;
  std::vector<double> Mean;
  std::vector<double> StdDev;
  std::vector<std::uint8_t> Interpolated;
};
// `values` has one value per voxel of the mesh's image.
ElementStatistics ComputeElementStatistics(const ElementRasterizer& raster, const double* values,
  const ParallelFor& parallel, const ProgressFunction& progress = NoProgress());

// Owner element of every voxel (-1 where none, which only happens when the mesh does not tile the box).
// Empty when progress asked to abort.
std::vector<std::int64_t> VoxelOwners(const ElementRasterizer& raster, const ParallelFor& parallel,
  const ProgressFunction& progress = NoProgress());

// Quality in frame (world) units: minimum angle (triangles) or minimum dihedral angle (tetrahedra)
// in degrees, and the radius ratio normalised to 1 for the equilateral element (2r/R, 3r/R).
void ElementQuality(const SimplexMesh& mesh, std::vector<double>& minAngle, std::vector<double>& radiusRatio,
  const ParallelFor& parallel);

// Trilinear (bilinear in 2D) interpolation of voxel values at a continuous index.
double InterpolateAt(const double* values, const ImageGeometry& grid, const double index[3]);

//------------------------------------------------------------------------------------------------
// Inline: called once per candidate voxel centre.
inline bool ElementRasterizer::Owns(const double* plane, int faces, double x, double y, double z) const
{
  for (int f = 0; f < faces; ++f)
  {
    const double* n = plane + 4 * f;
    const double lambda = n[0] * x + n[1] * y + n[2] * z + n[3];
    if (lambda > 0)
    {
      continue;
    }
    if (lambda < 0)
    {
      return false;
    }
    // On the face plane: decide by the pull towards the box centre, then lexicographically.
    const double toCentre = n[0] * (this->TwiceCentre[0] - 2 * x) + n[1] * (this->TwiceCentre[1] - 2 * y) +
      (faces == 3 ? 0.0 : n[2] * (this->TwiceCentre[2] - 2 * z));
    if (toCentre < 0)
    {
      return false;
    }
    if (toCentre == 0)
    {
      const bool positive = n[0] > 0 || (n[0] == 0 && (n[1] > 0 || (n[1] == 0 && n[2] > 0)));
      if (!positive)
      {
        return false;
      }
    }
  }
  return true;
}

template <typename Visitor>
void ElementRasterizer::ForEachVoxel(std::int64_t e, Visitor&& visit) const
{
  const std::int64_t* cell = this->M->Cell(e);
  const auto& P = this->M->Points();
  const auto& G = this->M->Geometry();
  const int faces = this->M->VerticesPerCell();
  // Plane per face: lambda(p) = n.p + d, positive on the side of the opposite vertex.
  double plane[4][4];
  double lo[3] = { 1e300, 1e300, 1e300 }, hi[3] = { -1e300, -1e300, -1e300 };
  for (int v = 0; v < faces; ++v)
  {
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::min(lo[a], P[cell[v]][a]);
      hi[a] = std::max(hi[a], P[cell[v]][a]);
    }
  }
  for (int f = 0; f < faces; ++f)
  {
    double n[3];
    if (faces == 3)
    {
      const auto& p = P[cell[(f + 1) % 3]];
      const auto& q = P[cell[(f + 2) % 3]];
      // Inward normal of a counter-clockwise edge p->q.
      n[0] = -(q[1] - p[1]);
      n[1] = q[0] - p[0];
      n[2] = 0.0;
      plane[f][3] = -(n[0] * p[0] + n[1] * p[1]);
    }
    else
    {
      const auto& p = P[cell[(f + 1) % 4]];
      const auto& q = P[cell[(f + 2) % 4]];
      const auto& r = P[cell[(f + 3) % 4]];
      const double u[3] = { q[0] - p[0], q[1] - p[1], q[2] - p[2] };
      const double w[3] = { r[0] - p[0], r[1] - p[1], r[2] - p[2] };
      n[0] = u[1] * w[2] - u[2] * w[1];
      n[1] = u[2] * w[0] - u[0] * w[2];
      n[2] = u[0] * w[1] - u[1] * w[0];
      const auto& o = P[cell[f]];
      double d = -(n[0] * p[0] + n[1] * p[1] + n[2] * p[2]);
      if (n[0] * o[0] + n[1] * o[1] + n[2] * o[2] + d < 0)
      {
        n[0] = -n[0];
        n[1] = -n[1];
        n[2] = -n[2];
        d = -d;
      }
      plane[f][3] = d;
    }
    plane[f][0] = n[0];
    plane[f][1] = n[1];
    plane[f][2] = n[2];
  }
  const int i0 = std::max(0, static_cast<int>(std::ceil(lo[0]))), i1 = std::min(G.Dims[0] - 1, static_cast<int>(std::floor(hi[0])));
  const int j0 = std::max(0, static_cast<int>(std::ceil(lo[1]))), j1 = std::min(G.Dims[1] - 1, static_cast<int>(std::floor(hi[1])));
  const int k0 = faces == 3 ? 0 : std::max(0, static_cast<int>(std::ceil(lo[2])));
  const int k1 = faces == 3 ? 0 : std::min(G.Dims[2] - 1, static_cast<int>(std::floor(hi[2])));
  for (int k = k0; k <= k1; ++k)
  {
    for (int j = j0; j <= j1; ++j)
    {
      // Candidate x-interval from the face planes, widened by one voxel; the exact test decides.
      double xlo = i0, xhi = i1;
      bool empty = false;
      for (int f = 0; f < faces && !empty; ++f)
      {
        const double a = plane[f][0];
        const double b = plane[f][1] * j + plane[f][2] * k + plane[f][3];
        if (a > 0)
        {
          xlo = std::max(xlo, -b / a);
        }
        else if (a < 0)
        {
          xhi = std::min(xhi, -b / a);
        }
        else if (b < 0)
        {
          empty = true;
        }
      }
      if (empty || xlo > xhi + 1.0)
      {
        continue;
      }
      const int s = std::max(i0, static_cast<int>(std::ceil(xlo)) - 1);
      const int t = std::min(i1, static_cast<int>(std::floor(xhi)) + 1);
      std::int64_t idx = G.Index(s, j, k);
      for (int i = s; i <= t; ++i, ++idx)
      {
        if (this->Owns(&plane[0][0], faces, i, j, k))
        {
          visit(idx);
        }
      }
    }
  }
}
} // namespace featuremesh
