#include "ElementQuality.h"
#include "Vector3.h"

#include <algorithm>
#include <cmath>

namespace featuremesh
{
namespace
{
using namespace vector3;
constexpr double Degrees = 180.0 / 3.14159265358979323846;
} // namespace

double SimplexAngleScore(const V3* const* v, int vpc)
{
  double largest = -1.0;
  if (vpc == 3)
  {
    for (int k = 0; k < 3; ++k)
    {
      const V3 u = Sub(*v[(k + 1) % 3], *v[k]), w = Sub(*v[(k + 2) % 3], *v[k]);
      largest = std::max(largest, (u[0] * w[0] + u[1] * w[1]) / std::sqrt((u[0] * u[0] + u[1] * u[1]) * (w[0] * w[0] + w[1] * w[1])));
    }
    return -largest;
  }
  V3 n[4];
  double length[4];
  for (int f = 0; f < 4; ++f)
  {
    n[f] = Cross(Sub(*v[(f + 2) % 4], *v[(f + 1) % 4]), Sub(*v[(f + 3) % 4], *v[(f + 1) % 4]));
    length[f] = std::sqrt(Dot(n[f], n[f]));
    if (Dot(n[f], Sub(*v[f], *v[(f + 1) % 4])) > 0)
    {
      length[f] = -length[f];
    }
  }
  for (int k = 0; k < 4; ++k)
  {
    for (int l = k + 1; l < 4; ++l)
    {
      largest = std::max(largest, -Dot(n[k], n[l]) / (length[k] * length[l]));
    }
  }
  return -largest;
}

double SimplexMinAngle(const V3* const* v, int vpc)
{
  double smallest = 180.0;
  if (vpc == 3)
  {
    for (int k = 0; k < 3; ++k)
    {
      const V3 u = Sub(*v[(k + 1) % 3], *v[k]), w = Sub(*v[(k + 2) % 3], *v[k]);
      smallest = std::min(smallest, std::atan2(Norm(Cross(u, w)), Dot(u, w)) * Degrees);
    }
    return smallest;
  }
  // Face normals, each pointing away from its opposite vertex; face f is opposite vertex f.
  V3 n[4];
  for (int f = 0; f < 4; ++f)
  {
    n[f] = Cross(Sub(*v[(f + 2) % 4], *v[(f + 1) % 4]), Sub(*v[(f + 3) % 4], *v[(f + 1) % 4]));
    if (Dot(n[f], Sub(*v[f], *v[(f + 1) % 4])) > 0)
    {
      n[f] = { { -n[f][0], -n[f][1], -n[f][2] } };
    }
  }
  for (int k = 0; k < 4; ++k)
  {
    for (int l = k + 1; l < 4; ++l)
    {
      // Dihedral angle at the edge shared by faces k and l: pi minus the normals' angle.
      const double norms = Norm(n[k]) * Norm(n[l]);
      const double cosine = norms > 0 ? -Dot(n[k], n[l]) / norms : 1.0;
      smallest = std::min(smallest, std::acos(std::max(-1.0, std::min(1.0, cosine))) * Degrees);
    }
  }
  return smallest;
}

void ElementQuality(const SimplexMesh& mesh, std::vector<double>& minAngle, std::vector<double>& radiusRatio,
  const ParallelFor& parallel)
{
  const std::vector<std::array<double, 3>> P = mesh.FramePoints();
  const int vpc = mesh.VerticesPerCell();
  const std::int64_t m = mesh.NumberOfElements();
  minAngle.assign(m, 0.0);
  radiusRatio.assign(m, 0.0);
  parallel(m, 4096, [&](std::int64_t b, std::int64_t e) {
    for (std::int64_t c = b; c < e; ++c)
    {
      const std::int64_t* id = mesh.Cell(c);
      if (vpc == 3)
      {
        const V3 &a = P[id[0]], &bb = P[id[1]], &d = P[id[2]];
        const double la = Norm(Sub(bb, d)), lb = Norm(Sub(a, d)), lc = Norm(Sub(a, bb));
        const double area = 0.5 * Norm(Cross(Sub(bb, a), Sub(d, a)));
        const V3* v[3] = { &a, &bb, &d };
        minAngle[c] = SimplexMinAngle(v, 3);
        const double s = 0.5 * (la + lb + lc);
        const double r = area / s, R = la * lb * lc / (4.0 * area);
        radiusRatio[c] = area > 0 ? 2.0 * r / R : 0.0;
      }
      else
      {
        const V3* v[4] = { &P[id[0]], &P[id[1]], &P[id[2]], &P[id[3]] };
        double faceArea = 0.0;
        for (int f = 0; f < 4; ++f)
        {
          faceArea += 0.5 * Norm(Cross(Sub(*v[(f + 2) % 4], *v[(f + 1) % 4]), Sub(*v[(f + 3) % 4], *v[(f + 1) % 4])));
        }
        minAngle[c] = SimplexMinAngle(v, 4);
        const V3 a = Sub(*v[1], *v[0]), bb = Sub(*v[2], *v[0]), d = Sub(*v[3], *v[0]);
        const double det = Dot(a, Cross(bb, d));
        const double volume = std::fabs(det) / 6.0;
        const V3 x1 = Cross(bb, d), x2 = Cross(d, a), x3 = Cross(a, bb);
        const double la = Dot(a, a), lb = Dot(bb, bb), ld = Dot(d, d);
        const V3 num = { { la * x1[0] + lb * x2[0] + ld * x3[0], la * x1[1] + lb * x2[1] + ld * x3[1],
          la * x1[2] + lb * x2[2] + ld * x3[2] } };
        const double R = Norm(num) / (2.0 * std::fabs(det));
        const double r = 3.0 * volume / faceArea;
        radiusRatio[c] = volume > 0 ? 3.0 * r / R : 0.0;
      }
    }
  });
}
} // namespace featuremesh
