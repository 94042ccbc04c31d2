// Exact assignment of voxel centres to the triangles / tetrahedra of a mesh that tiles the image box,
// and the per-element measures built on it (statistics; quality is ElementQuality.h).
//
// Tie rule: a centre p on a shared edge/face belongs to the element that contains
// p + e(c - p) + e^2 t, e -> 0, with c the box centre and t a lexicographic direction. The first
// term pulls centres on the box surface inside, the second breaks the remaining ties, so every
// centre belongs to exactly one element. Node coordinates on voxel centres are integers in index
// space, so every test is exact in double arithmetic; for nodes off the lattice (refinement,
// smoothing) the two sides of a face still agree bit for bit, because each face's plane is formed
// from its vertex ids in a fixed order.
#pragma once

#include "ExactPredicates.h"
#include "Parallel.h"
#include "SimplexMesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
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

  // Calls visit(firstVoxelIndex, count) for runs of consecutive voxel centres along x owned by the
  // element, in raster order: together, every owned centre once.
  template <typename SpanVisitor>
  void ForEachSpan(std::int64_t e, SpanVisitor&& visit) const;

  // Calls visit(voxelIndex) for every voxel centre owned by the element, in raster order.
  template <typename Visitor>
  void ForEachVoxel(std::int64_t e, Visitor&& visit) const
  {
    this->ForEachSpan(e, [&](std::int64_t first, std::int64_t count) {
      for (std::int64_t v = first; v < first + count; ++v)
      {
        visit(v);
      }
    });
  }

  // The elements in SpatialElementOrder (SimplexMesh.h): a pass over them in this order reads and
  // writes neighbouring voxels, where mesher order jumps across the image and waits on memory. What
  // a pass gives each element does not depend on the order.
  const std::vector<std::int64_t>& SpatialOrder() const { return this->Order; }

private:
  // A face: its plane (n, d) with the element on the positive side, and, for elements with a node
  // off the voxel lattice, its vertices in ascending id order and the sign that orients them.
  struct Face
  {
    double Plane[4];
    const std::array<double, 3>* Vertex[3];
    double Sign;
    // Off the lattice: lambda's rounding per unit of coordinate, far above it (1e-9 of the size of
    // the products forming the normal: a near-degenerate face has a normal far smaller than its
    // rounding error, so |n| would not do).
    double Band;
  };
  // The element's face planes (each from its vertex ids in ascending order, positive towards the
  // opposite vertex) and its bounding box in index space; true when a vertex is off the lattice.
  bool ElementFaces(const std::int64_t* cell, Face* face, double* lo, double* hi) const;
  // A tetrahedron's rows in slice k: [jLo, jHi] narrowed to the y-range of its cross-section (where
  // its edges cross z = k), widened far beyond the rounding; false when the slice misses it.
  bool SliceRows(const std::int64_t* cell, int k, int& jLo, int& jHi) const;
  bool Owns(const Face* face, int faces, bool offLattice, double x, double y, double z) const;
  bool ExactTie(const Face& face, int faces) const;
  bool LatticeTie(const double* n, int faces, double x, double y, double z) const;

  const SimplexMesh* M;
  double TwiceCentre[3];
  // Lattice elements' row bounds are exact (every dimension below 4096 voxels).
  bool ExactBounds = false;
  std::vector<std::int64_t> Order;
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
// `values` has one value per voxel of the mesh's image, in the image's own type (every arithmetic type;
// sums in double). `owner` (optional, one per voxel) receives what VoxelOwners gives, from the same pass.
template <typename T>
ElementStatistics ComputeElementStatistics(const ElementRasterizer& raster, const T* values,
  const ParallelFor& parallel, const ProgressFunction& progress = NoProgress(), std::int32_t* owner = nullptr);

// The element owning each voxel (-1 none): a map of its own (VoxelOwners) or a view of one its
// holder keeps alive (stage 2's array: no 36 MB copy on BraTS). Move-only: a view stays valid.
class VoxelOwnerMap
{
public:
  VoxelOwnerMap() = default;
  VoxelOwnerMap(VoxelOwnerMap&&) = default;
  VoxelOwnerMap& operator=(VoxelOwnerMap&&) = default;
  VoxelOwnerMap(const VoxelOwnerMap&) = delete;
  VoxelOwnerMap& operator=(const VoxelOwnerMap&) = delete;

  void Own(std::vector<std::int32_t> owner)
  {
    this->Keep.reset();
    this->Owned = std::move(owner);
    this->P = this->Owned.data();
    this->N = static_cast<std::int64_t>(this->Owned.size());
  }
  void View(const std::int32_t* owner, std::int64_t voxels, std::shared_ptr<const void> keep)
  {
    std::vector<std::int32_t>().swap(this->Owned);
    this->Keep = std::move(keep);
    this->P = owner;
    this->N = voxels;
  }
  const std::int32_t* data() const { return this->P; }
  std::int64_t size() const { return this->N; }
  bool empty() const { return this->N == 0; }
  const std::int32_t* begin() const { return this->P; }
  const std::int32_t* end() const { return this->P + this->N; }
  std::int32_t operator[](std::int64_t v) const { return this->P[v]; }

private:
  std::vector<std::int32_t> Owned;
  std::shared_ptr<const void> Keep;
  const std::int32_t* P = nullptr;
  std::int64_t N = 0;
};

// Calls f(v) for each voxel v that `owner` gives element e, from the box of e's vertices (index
// space): an owned voxel's centre lies in its element.
template <typename F>
void ForEachVoxelOf(const SimplexMesh& mesh, const VoxelOwnerMap& owner, std::int64_t e, F&& f)
{
  const ImageGeometry& g = mesh.Geometry();
  const std::int64_t* cell = mesh.Cell(e);
  std::array<int, 3> low{ { 0, 0, 0 } }, high{ { 0, 0, 0 } };
  for (int d = 0; d < 3; ++d)
  {
    double lo = mesh.Points()[cell[0]][d], hi = lo;
    for (int j = 1; j < mesh.VerticesPerCell(); ++j)
    {
      lo = std::min(lo, mesh.Points()[cell[j]][d]);
      hi = std::max(hi, mesh.Points()[cell[j]][d]);
    }
    low[d] = std::max(0, static_cast<int>(std::ceil(lo)));
    high[d] = std::min(g.Dims[d] - 1, static_cast<int>(std::floor(hi)));
  }
  for (int z = low[2]; z <= high[2]; ++z)
  {
    for (int y = low[1]; y <= high[1]; ++y)
    {
      for (int x = low[0]; x <= high[0]; ++x)
      {
        const std::int64_t v = g.Index(x, y, z);
        if (owner[v] == e)
        {
          f(v);
        }
      }
    }
  }
}

// Owner element of every voxel (-1 where none, which only happens when the mesh does not tile the box).
// Empty when progress asked to abort. Element ids are 32-bit: 4 bytes per voxel.
std::vector<std::int32_t> VoxelOwners(const ElementRasterizer& raster, const ParallelFor& parallel,
  const ProgressFunction& progress = NoProgress());


// Trilinear (bilinear in 2D) interpolation of voxel values at a continuous index (T any arithmetic type).
template <typename T>
double InterpolateAt(const T* values, const ImageGeometry& grid, const double index[3]);

//------------------------------------------------------------------------------------------------
// Inline: called once per candidate voxel centre.
inline bool ElementRasterizer::Owns(const Face* face, int faces, bool offLattice, double x, double y, double z) const
{
  for (int f = 0; f < faces; ++f)
  {
    const double* n = face[f].Plane;
    double lambda = n[0] * x + n[1] * y + n[2] * z + n[3];
    if (offLattice && std::fabs(lambda) < face[f].Band * (1.0 + std::fabs(x) + std::fabs(y) + std::fabs(z)))
    {
      // Off the lattice the plane is rounded: a centre on or a hair from the face is decided by
      // the exact sign (on the lattice every test above is exact integer arithmetic).
      const std::array<double, 3> c = { { x, y, z } };
      const Face& F = face[f];
      lambda = F.Sign * (faces == 3 ? Orientation2(*F.Vertex[0], *F.Vertex[1], c)
                                    : Orientation3(*F.Vertex[0], *F.Vertex[1], *F.Vertex[2], c));
    }
    if (lambda > 0)
    {
      continue;
    }
    if (lambda < 0)
    {
      return false;
    }
    // On the face plane: decide by the pull towards the box centre, then lexicographically.
    if (offLattice ? !this->ExactTie(face[f], faces) : !this->LatticeTie(n, faces, x, y, z))
    {
      return false;
    }
  }
  return true;
}

// The tie rule for a lattice element's centre on face plane n (exact integer arithmetic).
inline bool ElementRasterizer::LatticeTie(const double* n, int faces, double x, double y, double z) const
{
  const double toCentre = n[0] * (this->TwiceCentre[0] - 2 * x) + n[1] * (this->TwiceCentre[1] - 2 * y) +
    (faces == 3 ? 0.0 : n[2] * (this->TwiceCentre[2] - 2 * z));
  if (toCentre != 0)
  {
    return toCentre > 0;
  }
  return n[0] > 0 || (n[0] == 0 && (n[1] > 0 || (n[1] == 0 && n[2] > 0)));
}

// The tie rule with exact signs, for a centre exactly on a face of an element off the lattice: on
// the plane, n.(c - p) has the sign of the box centre c's orientation; then the signs of n's
// components, which are orientations of the face projected on the yz, zx and xy planes.
inline bool ElementRasterizer::ExactTie(const Face& F, int faces) const
{
  const std::array<double, 3> centre = { { 0.5 * this->TwiceCentre[0], 0.5 * this->TwiceCentre[1],
    faces == 3 ? 0.0 : 0.5 * this->TwiceCentre[2] } };
  const auto& a = *F.Vertex[0];
  const auto& b = *F.Vertex[1];
  int side = faces == 3 ? Orientation2(a, b, centre) : Orientation3(a, b, *F.Vertex[2], centre);
  if (side == 0)
  {
    if (faces == 3)
    {
      // n = (-(b_y - a_y), b_x - a_x).
      side = a[1] > b[1] ? 1 : (a[1] < b[1] ? -1 : (b[0] > a[0] ? 1 : (b[0] < a[0] ? -1 : 0)));
    }
    else
    {
      const auto& c = *F.Vertex[2];
      auto project = [](const std::array<double, 3>& q, int s, int t) { return std::array<double, 3>{ { q[s], q[t], 0.0 } }; };
      side = Orientation2(project(a, 1, 2), project(b, 1, 2), project(c, 1, 2));
      side = side ? side : Orientation2(project(a, 2, 0), project(b, 2, 0), project(c, 2, 0));
      side = side ? side : Orientation2(project(a, 0, 1), project(b, 0, 1), project(c, 0, 1));
    }
  }
  return F.Sign * side > 0;
}

inline bool ElementRasterizer::ElementFaces(const std::int64_t* cell, Face* face, double* lo, double* hi) const
{
  const auto& P = this->M->Points();
  const int faces = this->M->VerticesPerCell();
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = 1e300;
    hi[a] = -1e300;
  }
  bool offLattice = false;
  for (int v = 0; v < faces; ++v)
  {
    const auto& q = P[cell[v]];
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::min(lo[a], q[a]);
      hi[a] = std::max(hi[a], q[a]);
      offLattice = offLattice || q[a] != std::floor(q[a]);
    }
  }
  // Plane per face: lambda(p) = n.p + d, positive on the side of the opposite vertex, from its
  // vertex ids in ascending order, so that the two elements sharing a face compute the same numbers
  // and exactly opposite signs: every centre has one owner even for nodes off the voxel lattice (on
  // it, all of this is exact integer arithmetic anyway).
  for (int f = 0; f < faces; ++f)
  {
    std::int64_t ids[3];
    int k = 0;
    for (int v = 0; v < faces; ++v)
    {
      if (v != f)
      {
        ids[k++] = cell[v];
      }
    }
    std::sort(ids, ids + faces - 1);
    const auto& p = P[ids[0]];
    const auto& q = P[ids[1]];
    double n[3], d, size;
    if (faces == 3)
    {
      n[0] = -(q[1] - p[1]);
      n[1] = q[0] - p[0];
      n[2] = 0.0;
      d = -(n[0] * p[0] + n[1] * p[1]);
      size = std::fabs(n[0]) + std::fabs(n[1]);
    }
    else
    {
      const auto& r = P[ids[2]];
      const double u[3] = { q[0] - p[0], q[1] - p[1], q[2] - p[2] };
      const double w[3] = { r[0] - p[0], r[1] - p[1], r[2] - p[2] };
      n[0] = u[1] * w[2] - u[2] * w[1];
      n[1] = u[2] * w[0] - u[0] * w[2];
      n[2] = u[0] * w[1] - u[1] * w[0];
      d = -(n[0] * p[0] + n[1] * p[1] + n[2] * p[2]);
      size = std::fabs(u[1] * w[2]) + std::fabs(u[2] * w[1]) + std::fabs(u[2] * w[0]) + std::fabs(u[0] * w[2]) +
        std::fabs(u[0] * w[1]) + std::fabs(u[1] * w[0]);
    }
    // Positive on the side of the opposite vertex (exactly, off the lattice: slivers are flat).
    const auto& o = P[cell[f]];
    const double sign = offLattice
      ? (faces == 3 ? Orientation2(p, q, o) : Orientation3(p, q, P[ids[2]], o)) < 0 ? -1.0 : 1.0
      : (n[0] * o[0] + n[1] * o[1] + n[2] * o[2] + d < 0 ? -1.0 : 1.0);
    face[f].Plane[0] = sign * n[0];
    face[f].Plane[1] = sign * n[1];
    face[f].Plane[2] = sign * n[2];
    face[f].Plane[3] = sign * d;
    face[f].Sign = sign;
    face[f].Band = 1e-9 * size;
    for (int v = 0; v < faces - 1; ++v)
    {
      face[f].Vertex[v] = &P[ids[v]];
    }
  }
  return offLattice;
}

inline bool ElementRasterizer::SliceRows(const std::int64_t* cell, int k, int& jLo, int& jHi) const
{
  const auto& P = this->M->Points();
  double yLo = 1e300, yHi = -1e300;
  for (int a = 0; a < 4; ++a)
  {
    const auto& p = P[cell[a]];
    if (p[2] == k)
    {
      yLo = std::min(yLo, p[1]);
      yHi = std::max(yHi, p[1]);
    }
    for (int b = a + 1; b < 4; ++b)
    {
      const auto& q = P[cell[b]];
      if ((p[2] < k && q[2] > k) || (p[2] > k && q[2] < k))
      {
        const double y = p[1] + (k - p[2]) / (q[2] - p[2]) * (q[1] - p[1]);
        yLo = std::min(yLo, y);
        yHi = std::max(yHi, y);
      }
    }
  }
  if (!(yLo <= yHi))
  {
    return false;
  }
  jLo = std::max(jLo, static_cast<int>(std::ceil(yLo - 1e-6)));
  jHi = std::min(jHi, static_cast<int>(std::floor(yHi + 1e-6)));
  return true;
}

template <typename SpanVisitor>
void ElementRasterizer::ForEachSpan(std::int64_t e, SpanVisitor&& visit) const
{
  const std::int64_t* cell = this->M->Cell(e);
  const auto& G = this->M->Geometry();
  const int faces = this->M->VerticesPerCell();
  Face face[4];
  double lo[3], hi[3];
  const bool offLattice = this->ElementFaces(cell, face, lo, hi);
  const int i0 = std::max(0, static_cast<int>(std::ceil(lo[0]))), i1 = std::min(G.Dims[0] - 1, static_cast<int>(std::floor(hi[0])));
  const int j0 = std::max(0, static_cast<int>(std::ceil(lo[1]))), j1 = std::min(G.Dims[1] - 1, static_cast<int>(std::floor(hi[1])));
  const int k0 = faces == 3 ? 0 : std::max(0, static_cast<int>(std::ceil(lo[2])));
  const int k1 = faces == 3 ? 0 : std::min(G.Dims[2] - 1, static_cast<int>(std::floor(hi[2])));
  // Row bounds are products with 1/a (a: a face's x coefficient), their rounding (a few ulps of
  // bounds within the box) far below Margin voxels: the candidates only grow by it and the interior
  // only shrinks, and Owns decides every candidate outside the interior exactly.
  constexpr double Margin = 1e-7;
  double inverse[4];
  for (int f = 0; f < faces; ++f)
  {
    inverse[f] = face[f].Plane[0] != 0.0 ? 1.0 / face[f].Plane[0] : 0.0;
  }
  // On the lattice without exact bounds (a dimension of 4096 or more) b may be rounded: no interior.
  const bool exactRows = offLattice || this->ExactBounds;
  const int widen = this->ExactBounds || offLattice ? 0 : 1;
  for (int k = k0; k <= k1; ++k)
  {
    int jLo = j0, jHi = j1;
    if (faces == 4 && !this->SliceRows(cell, k, jLo, jHi))
    {
      continue;
    }
    for (int j = jLo; j <= jHi; ++j)
    {
      // Candidate x-interval from the face planes; within it, centres strictly inside every face
      // by more than 3 slacks are owned without a test (below): (inLo, inHi). Off the lattice b
      // carries rounding, which a plane nearly parallel to x (tiny a) magnifies: the slack moves
      // each bound out by at least 1e-9 (1 + Dims[0]) voxels (Band >= 1e-9 |a|), beyond that
      // rounding, and covers the band Owns decides exactly.
      double xlo = i0, xhi = i1;
      double inLo = -1e300, inHi = 1e300;
      bool empty = false, interior = exactRows;
      for (int f = 0; f < faces && !empty; ++f)
      {
        const double* n = face[f].Plane;
        const double a = n[0];
        const double b = n[1] * j + n[2] * k + n[3];
        const double slack = offLattice ? face[f].Band * (1.0 + G.Dims[0] + j + k) : 0.0;
        if (a > 0)
        {
          xlo = std::max(xlo, (-b - slack) * inverse[f]);
          inLo = std::max(inLo, (-b + 3 * slack) * inverse[f]);
        }
        else if (a < 0)
        {
          xhi = std::min(xhi, (-b - slack) * inverse[f]);
          inHi = std::min(inHi, (-b + 3 * slack) * inverse[f]);
        }
        else if (b < -slack)
        {
          empty = true;
        }
        else if (b == 0.0 && !offLattice)
        {
          // The row lies in the face's plane: the tie rule, which x does not enter (n[0] = 0),
          // decides it whole.
          empty = !this->LatticeTie(n, faces, 0.0, j, k);
        }
        else
        {
          interior = interior && b > 3 * slack;
        }
      }
      if (empty || xlo - Margin > xhi + Margin + widen)
      {
        continue;
      }
      const int s = std::max(i0, static_cast<int>(std::ceil(xlo - Margin)) - widen);
      const int t = std::min(i1, static_cast<int>(std::floor(xhi + Margin)) + widen);
      // Strictly inside: i > inLo and i < inHi. On the lattice (exact b) every lambda there is a
      // positive integer, which Owns computes exactly. Off it, lambda exceeds 3 slacks less the
      // rounding of b (far below a slack): above the band, so Owns takes the rounded sign, positive.
      int u = t + 1, w = t;
      if (interior && inLo + Margin < t && inHi - Margin > s)
      {
        u = inLo + Margin < s ? s : static_cast<int>(std::floor(inLo + Margin)) + 1;
        w = inHi - Margin > t ? t : static_cast<int>(std::ceil(inHi - Margin)) - 1;
        if (u > w)
        {
          u = t + 1, w = t;
        }
      }
      const std::int64_t row = G.Index(0, j, k);
      for (int i = s; i < u; ++i)
      {
        if (this->Owns(face, faces, offLattice, i, j, k))
        {
          visit(row + i, std::int64_t(1));
        }
      }
      if (u <= w)
      {
        visit(row + u, static_cast<std::int64_t>(w - u + 1));
      }
      for (int i = std::max(s, w + 1); i <= t; ++i)
      {
        if (this->Owns(face, faces, offLattice, i, j, k))
        {
          visit(row + i, std::int64_t(1));
        }
      }
    }
  }
}
} // namespace featuremesh
