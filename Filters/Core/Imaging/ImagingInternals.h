// Helpers shared by the imaging sources (not part of the Core's API).
#pragma once

#include "ImageGeometry.h"

#include <cstdint>

namespace featuremesh
{
namespace detail
{
// Fixed block count for reductions, so that results never depend on the thread count.
constexpr std::int64_t ReductionBlocks = 64;

// Central difference along one axis with one-sided differences on the border.
inline float Diff(const float* f, std::int64_t idx, int coord, int dim, std::int64_t stride)
{
  if (dim < 2)
  {
    return 0.f;
  }
  if (coord == 0)
  {
    return f[idx + stride] - f[idx];
  }
  if (coord == dim - 1)
  {
    return f[idx] - f[idx - stride];
  }
  return 0.5f * (f[idx + stride] - f[idx - stride]);
}

inline void Coordinates(const ImageGeometry& g, std::int64_t idx, int& i, int& j, int& k)
{
  const std::array<int, 3> c = g.Coordinates(idx);
  i = c[0];
  j = c[1];
  k = c[2];
}
} // namespace detail
} // namespace featuremesh
