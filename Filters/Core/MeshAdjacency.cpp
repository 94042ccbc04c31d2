#include "MeshAdjacency.h"

#include <algorithm>
#include <cmath>

namespace featuremesh
{
namespace
{
double FaceMeasure(const std::vector<std::array<double, 3>>& P, const std::int64_t* f, int n)
{
  const auto& a = P[f[0]];
  const auto& b = P[f[1]];
  const double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
  if (n == 2)
  {
    return std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  }
  const auto& c = P[f[2]];
  const double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
  const double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2], z = u[0] * v[1] - u[1] * v[0];
  return 0.5 * std::sqrt(x * x + y * y + z * z);
}
} // namespace

void OutwardFace(const std::vector<std::array<double, 3>>& P, const std::int64_t* cell, int vpc, int f,
  std::int64_t* face)
{
  if (vpc == 3)
  {
    // Counter-clockwise triangle: edge (f+1 -> f+2) has the triangle on its left.
    face[0] = cell[(f + 1) % 3];
    face[1] = cell[(f + 2) % 3];
    return;
  }
  face[0] = cell[(f + 1) % 4];
  face[1] = cell[(f + 2) % 4];
  face[2] = cell[(f + 3) % 4];
  const auto& a = P[face[0]];
  const auto& b = P[face[1]];
  const auto& c = P[face[2]];
  const auto& o = P[cell[f]];
  const double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
  const double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
  const double n[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0] };
  if (n[0] * (o[0] - a[0]) + n[1] * (o[1] - a[1]) + n[2] * (o[2] - a[2]) > 0)
  {
    std::swap(face[1], face[2]);
  }
}

MeshAdjacency BuildAdjacency(
  const std::vector<std::array<double, 3>>& P, const std::vector<std::int64_t>& cells, int vpc)
{
  MeshAdjacency adj;
  const std::int64_t m = static_cast<std::int64_t>(cells.size()) / vpc;
  const int fv = vpc - 1; // vertices per face
  const std::int64_t nFaces = m * vpc;
  struct Face
  {
    std::int64_t v[3];
    std::int64_t element;
    int local;
  };
  std::vector<Face> faces(nFaces);
  std::vector<std::int64_t> bucketStart(P.size() + 1, 0);
  for (std::int64_t e = 0; e < m; ++e)
  {
    for (int f = 0; f < vpc; ++f)
    {
      Face& face = faces[e * vpc + f];
      int k = 0;
      for (int v = 0; v < vpc; ++v)
      {
        if (v != f)
        {
          face.v[k++] = cells[e * vpc + v];
        }
      }
      if (fv == 2)
      {
        face.v[2] = -1;
      }
      std::sort(face.v, face.v + fv);
      face.element = e;
      face.local = f;
      bucketStart[face.v[0] + 1]++;
    }
  }
  for (size_t i = 1; i < bucketStart.size(); ++i)
  {
    bucketStart[i] += bucketStart[i - 1];
  }
  std::vector<std::int64_t> order(nFaces);
  {
    std::vector<std::int64_t> fill(bucketStart.begin(), bucketStart.end() - 1);
    for (std::int64_t i = 0; i < nFaces; ++i)
    {
      order[fill[faces[i].v[0]]++] = i;
    }
  }
  for (size_t b = 0; b + 1 < bucketStart.size(); ++b)
  {
    auto first = order.begin() + bucketStart[b], last = order.begin() + bucketStart[b + 1];
    std::sort(first, last, [&](std::int64_t x, std::int64_t y) {
      const Face &p = faces[x], &q = faces[y];
      return std::make_pair(p.v[1], p.v[2]) < std::make_pair(q.v[1], q.v[2]) ||
        (std::make_pair(p.v[1], p.v[2]) == std::make_pair(q.v[1], q.v[2]) && x < y);
    });
    for (auto it = first; it != last;)
    {
      const Face& p = faces[*it];
      if (it + 1 != last && faces[*(it + 1)].v[1] == p.v[1] && faces[*(it + 1)].v[2] == p.v[2])
      {
        const Face& q = faces[*(it + 1)];
        const bool pFirst = p.element < q.element;
        adj.A.push_back(pFirst ? p.element : q.element);
        adj.B.push_back(pFirst ? q.element : p.element);
        adj.LocalA.push_back(static_cast<std::uint8_t>(pFirst ? p.local : q.local));
        adj.LocalB.push_back(static_cast<std::uint8_t>(pFirst ? q.local : p.local));
        adj.Measure.push_back(FaceMeasure(P, p.v, fv));
        it += 2;
      }
      else
      {
        adj.HullElement.push_back(p.element);
        adj.HullFace.push_back(static_cast<std::uint8_t>(p.local));
        ++it;
      }
    }
  }
  return adj;
}
} // namespace featuremesh
