// The image frame every stage shares, and the project's only world <-> index conversion.
//
// Voxels are stored x fastest, as VTK stores images; indices count from the first voxel of the
// extent. world = Origin + Direction * (index * Spacing), Direction row-major, as vtkImageData.
// "Frame" coordinates are index * |Spacing|: the image's own axes in world units. Meshing, quality
// and contact measures use them, so that an oriented, offset or mirrored image gives the same mesh
// and labels as the same voxels with an identity frame (for an orthonormal Direction, frame and
// world coordinates differ by a rigid motion, mirrors included).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace featuremesh
{
struct ImageGeometry
{
  std::array<int, 3> Dims{ { 1, 1, 1 } };
  // World position of voxel (0, 0, 0).
  std::array<double, 3> Origin{ { 0, 0, 0 } };
  std::array<double, 3> Spacing{ { 1, 1, 1 } };
  std::array<double, 9> Direction{ { 1, 0, 0, 0, 1, 0, 0, 0, 1 } };

  std::int64_t Size() const { return static_cast<std::int64_t>(Dims[0]) * Dims[1] * Dims[2]; }
  bool Is2D() const { return Dims[2] == 1; }
  int Dimension() const { return Is2D() ? 2 : 3; }
  std::int64_t Index(int i, int j, int k) const
  {
    return (static_cast<std::int64_t>(k) * Dims[1] + j) * Dims[0] + i;
  }
  // World area (2D) or volume (3D) of one voxel.
  double VoxelVolume() const
  {
    return std::fabs(Spacing[0] * Spacing[1]) * (Is2D() ? 1.0 : std::fabs(Spacing[2]));
  }
  // The smallest |spacing| over the image's axes (2D: the first two).
  double FinestSpacing() const
  {
    const double inPlane = std::min(std::fabs(Spacing[0]), std::fabs(Spacing[1]));
    return Is2D() ? inPlane : std::min(inPlane, std::fabs(Spacing[2]));
  }
  // The median |spacing| of the three axes (2D: the finer of the two): the finest when two axes
  // share it (thick slices), else one axis thinner than the other two does not set it.
  double MedianSpacing() const
  {
    std::array<double, 3> s{ { std::fabs(Spacing[0]), std::fabs(Spacing[1]), std::fabs(Spacing[2]) } };
    if (Is2D())
    {
      return std::min(s[0], s[1]);
    }
    std::sort(s.begin(), s.end());
    return s[1];
  }
  // Per axis, how many of its voxels span one voxel of the median axis, rounded, at least 1: 1 on
  // every axis but one thinner than the other two. Distances in voxels measured with these
  // factors are even in world units where an axis is thin, as the median axis's elsewhere.
  std::array<int, 3> MedianVoxelFactors() const
  {
    const double unit = MedianSpacing();
    std::array<int, 3> m{ { 1, 1, 1 } };
    for (int a = 0; a < Dimension(); ++a)
    {
      m[a] = std::max(1, static_cast<int>(std::lround(unit / std::fabs(Spacing[a]))));
    }
    return m;
  }
  std::int64_t SliceStride() const { return static_cast<std::int64_t>(Dims[0]) * Dims[1]; }
  // The (i, j, k) of a voxel index: the inverse of Index.
  std::array<int, 3> Coordinates(std::int64_t v) const
  {
    const std::int64_t slice = SliceStride();
    const int k = static_cast<int>(v / slice);
    const std::int64_t r = v - k * slice;
    const int j = static_cast<int>(r / Dims[0]);
    return { { static_cast<int>(r - static_cast<std::int64_t>(j) * Dims[0]), j, k } };
  }
  bool Contains(int i, int j, int k) const
  {
    return i >= 0 && j >= 0 && k >= 0 && i < Dims[0] && j < Dims[1] && k < Dims[2];
  }

  // Empty when the frame is usable (finite, non-zero spacing; finite origin; invertible
  // direction), else a sentence saying what is wrong.
  std::string Validate() const;
  // True when world coordinates are a mirror image of frame coordinates (det(Direction) times the
  // signs of the spacing is negative): orientations flip between the two.
  bool IsMirrored() const;

  std::array<double, 3> IndexToWorld(const std::array<double, 3>& index) const;
  // Continuous index of a world point; components within 1e-6 of an integer snap to it, so that
  // points made from voxel centres come back exactly on them.
  std::array<double, 3> WorldToIndex(const std::array<double, 3>& world) const;
  std::array<double, 3> IndexToFrame(const std::array<double, 3>& index) const
  {
    return { { index[0] * std::fabs(Spacing[0]), index[1] * std::fabs(Spacing[1]), index[2] * std::fabs(Spacing[2]) } };
  }
  std::array<double, 3> FrameToIndex(const std::array<double, 3>& frame) const;
  // The voxel containing a world point (nearest centre, half a voxel of slack; a one-voxel axis
  // takes half its spacing either side), or -1 outside the image or for a non-finite point.
  std::int64_t VoxelAt(const std::array<double, 3>& world) const;
};

// The voxels of seed points given in world coordinates. False, with a sentence naming how many
// fall outside the image (or that none were given), when any does; `what` names the seed kind.
bool SeedVoxels(const std::vector<std::array<double, 3>>& world, const ImageGeometry& geometry, const char* what,
  std::vector<std::int64_t>& voxels, std::string& error);
} // namespace featuremesh
