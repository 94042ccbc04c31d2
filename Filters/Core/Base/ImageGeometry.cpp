#include "ImageGeometry.h"

#include <cmath>

namespace featuremesh
{
namespace
{
bool IsIdentity(const std::array<double, 9>& d)
{
  return d == std::array<double, 9>{ { 1, 0, 0, 0, 1, 0, 0, 0, 1 } };
}

double Determinant(const std::array<double, 9>& d)
{
  return d[0] * (d[4] * d[8] - d[5] * d[7]) - d[1] * (d[3] * d[8] - d[5] * d[6]) + d[2] * (d[3] * d[7] - d[4] * d[6]);
}
} // namespace

std::string ImageGeometry::Validate() const
{
  for (int a = 0; a < 3; ++a)
  {
    if (this->Dims[a] < 1)
    {
      return "the image has no voxels along axis " + std::to_string(a) + ".";
    }
    if (!std::isfinite(this->Spacing[a]) || this->Spacing[a] == 0.0)
    {
      return "the image spacing along axis " + std::to_string(a) + " is " + std::to_string(this->Spacing[a]) +
        "; it must be finite and non-zero.";
    }
    // World-to-index round trips stay exact enough for voxel ownership within this range (spacing
    // 1e30 lost 7 of 64 000 voxels).
    if (std::fabs(this->Spacing[a]) > 1e12 || std::fabs(this->Spacing[a]) < 1e-12)
    {
      return "the image spacing along axis " + std::to_string(a) + " is " + std::to_string(this->Spacing[a]) +
        "; it must lie within 1e-12 and 1e12 in magnitude (rescale the image's units, e.g. with Change Spacing).";
    }
    if (!std::isfinite(this->Origin[a]))
    {
      return "the image origin is not finite.";
    }
  }
  const double det = Determinant(this->Direction);
  if (!std::isfinite(det) || std::fabs(det) < 1e-12)
  {
    return "the image's direction matrix is singular or not finite.";
  }
  return std::string();
}

bool ImageGeometry::IsMirrored() const
{
  double sign = Determinant(this->Direction);
  for (double s : this->Spacing)
  {
    sign = s < 0 ? -sign : sign;
  }
  return sign < 0;
}

std::array<double, 3> ImageGeometry::IndexToWorld(const std::array<double, 3>& index) const
{
  // The order of vtkImageData::TransformContinuousIndexToPhysicalPoint, so both give the same bits.
  const auto& s = this->Spacing;
  const auto& d = this->Direction;
  std::array<double, 3> w;
  for (int c = 0; c < 3; ++c)
  {
    w[c] = index[0] * s[0] * d[3 * c] + index[1] * s[1] * d[3 * c + 1] + index[2] * s[2] * d[3 * c + 2] + this->Origin[c];
  }
  return w;
}

std::array<double, 3> ImageGeometry::WorldToIndex(const std::array<double, 3>& world) const
{
  const double r[3] = { world[0] - this->Origin[0], world[1] - this->Origin[1], world[2] - this->Origin[2] };
  std::array<double, 3> index;
  if (IsIdentity(this->Direction))
  {
    for (int a = 0; a < 3; ++a)
    {
      index[a] = r[a] / this->Spacing[a];
    }
  }
  else
  {
    // Direction^-1 r by cofactors, then divide by the spacing.
    const auto& d = this->Direction;
    const double inv = 1.0 / Determinant(d);
    const double m[9] = { d[4] * d[8] - d[5] * d[7], d[2] * d[7] - d[1] * d[8], d[1] * d[5] - d[2] * d[4],
      d[5] * d[6] - d[3] * d[8], d[0] * d[8] - d[2] * d[6], d[2] * d[3] - d[0] * d[5], d[3] * d[7] - d[4] * d[6],
      d[1] * d[6] - d[0] * d[7], d[0] * d[4] - d[1] * d[3] };
    for (int a = 0; a < 3; ++a)
    {
      index[a] = (m[3 * a] * r[0] + m[3 * a + 1] * r[1] + m[3 * a + 2] * r[2]) * inv / this->Spacing[a];
    }
  }
  for (double& c : index)
  {
    const double n = std::round(c);
    if (std::fabs(c - n) < 1e-6)
    {
      c = n;
    }
  }
  return index;
}

std::array<double, 3> ImageGeometry::FrameToIndex(const std::array<double, 3>& frame) const
{
  std::array<double, 3> index;
  for (int a = 0; a < 3; ++a)
  {
    index[a] = frame[a] / std::fabs(this->Spacing[a]);
  }
  return index;
}

std::int64_t ImageGeometry::VoxelAt(const std::array<double, 3>& world) const
{
  const std::array<double, 3> c = this->WorldToIndex(world);
  int ijk[3];
  for (int a = 0; a < 3; ++a)
  {
    // Half a voxel of slack: a point belongs to the voxel that contains it.
    if (!(std::isfinite(c[a]) && c[a] > -0.5 && c[a] < this->Dims[a] - 0.5))
    {
      return -1;
    }
    ijk[a] = this->Dims[a] == 1 ? 0 : static_cast<int>(std::lround(c[a]));
  }
  return this->Index(ijk[0], ijk[1], ijk[2]);
}

bool SeedVoxels(const std::vector<std::array<double, 3>>& world, const ImageGeometry& geometry, const char* what,
  std::vector<std::int64_t>& voxels, std::string& error)
{
  voxels.clear();
  if (world.empty())
  {
    error = std::string("no ") + what + " seeds were given; connect a point set with at least one point.";
    return false;
  }
  std::size_t outside = 0;
  for (const auto& p : world)
  {
    const std::int64_t v = geometry.VoxelAt(p);
    if (v < 0)
    {
      ++outside;
      continue;
    }
    voxels.push_back(v);
  }
  if (outside)
  {
    error = std::to_string(outside) + " of " + std::to_string(world.size()) + " " + what +
      " seeds fall outside the image (or are not finite).";
    return false;
  }
  return true;
}
} // namespace featuremesh
