// Halftoning (thesis 4.1): error diffusion of a feature map into dots.
#pragma once

#include "ImageGeometry.h"

#include <cstdint>
#include <vector>

namespace featuremesh
{
// Floyd-Steinberg error diffusion of rho with threshold q: a dot is worth 2q of feature (a midpoint
// quantiser, q = 0.5 is the classic algorithm), so raising q lowers the dot count. 3D uses half the
// classic in-slice stencil plus half to the next slice (centre 6/16, its 4-neighbours 2.5/16 each).
// Returns the voxel indices of the dots.
std::vector<std::int64_t> Halftone(const float* rho, const ImageGeometry& grid, double q);

// Halftone on the grid of median-axis voxels (ImageGeometry::MedianVoxelFactors), so that the dots
// are as even in world units as on cubic voxels: along an axis thinner than the other two, each run
// of m voxels is one cell holding their mean, and a cell's dot goes to its voxel of largest rho (the
// first on a tie). Ascending voxel indices; Halftone's own where every m is 1.
std::vector<std::int64_t> HalftoneInMedianVoxels(const float* rho, const ImageGeometry& grid, double q);
} // namespace featuremesh
