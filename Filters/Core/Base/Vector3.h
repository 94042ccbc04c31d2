// Small 3-vector helpers for the geometry of elements (quality, smoothing).
#pragma once

#include <array>
#include <cmath>

namespace featuremesh
{
namespace vector3
{
using V3 = std::array<double, 3>;
inline V3 Sub(const V3& a, const V3& b)
{
  return { { a[0] - b[0], a[1] - b[1], a[2] - b[2] } };
}
inline V3 Cross(const V3& a, const V3& b)
{
  return { { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] } };
}
inline double Dot(const V3& a, const V3& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline double Norm(const V3& a)
{
  return std::sqrt(Dot(a, a));
}
} // namespace vector3
} // namespace featuremesh
