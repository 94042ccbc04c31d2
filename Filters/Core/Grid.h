// A regular voxel grid in index space (x fastest), as VTK stores images.
#pragma once
#include <array>
#include <cstdint>

namespace featuremesh
{
struct Grid
{
  std::array<int, 3> Dims{ { 1, 1, 1 } };

  std::int64_t Size() const
  {
    return static_cast<std::int64_t>(Dims[0]) * Dims[1] * Dims[2];
  }
  bool Is2D() const { return Dims[2] == 1; }
  int Dimension() const { return Is2D() ? 2 : 3; }
  std::int64_t Index(int i, int j, int k) const
  {
    return (static_cast<std::int64_t>(k) * Dims[1] + j) * Dims[0] + i;
  }
  std::int64_t SliceStride() const { return static_cast<std::int64_t>(Dims[0]) * Dims[1]; }
  bool Contains(int i, int j, int k) const
  {
    return i >= 0 && j >= 0 && k >= 0 && i < Dims[0] && j < Dims[1] && k < Dims[2];
  }
};
} // namespace featuremesh
