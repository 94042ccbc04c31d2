// Canny edges (thesis 2.1): non-maximum suppression and hysteresis on a smoothed image.
#pragma once

#include "ImageGeometry.h"
#include "Parallel.h"

#include <cstdint>
#include <vector>

namespace featuremesh
{
// Canny edges on an already smoothed image: non-maximum suppression along the quantised gradient
// direction, hysteresis by 8-/26-connectivity. Returns 1 on edge voxels.
// `magnitudeBuffer`, when given, is n floats of scratch for the gradient magnitude.
std::vector<std::uint8_t> CannyEdges(const float* smoothed, const ImageGeometry& grid, double low, double high,
  double percentile, const ParallelFor& parallel, double* gradientMaximum = nullptr,
  float* magnitudeBuffer = nullptr);
} // namespace featuremesh
