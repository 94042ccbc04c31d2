// Canny edges (thesis 2.1): non-maximum suppression and hysteresis on a smoothed image.
#pragma once

#include "ImageGeometry.h"
#include "Parallel.h"

#include <cstdint>
#include <vector>

namespace featuremesh
{
// Canny edges on an already smoothed image: non-maximum suppression along the quantised gradient
// direction, hysteresis by 8-/26-connectivity. Returns 1 on edge voxels. The thresholds are
// low and high times a robust maximum (the `percentile` of the gradient magnitude), and at least
// lowFloor and highFloor (gradient-magnitude units: the noise's level away from the border;
// near it, where the noise's gradient varies more, scaled by BorderNoiseFactors of the image's
// smoothing sigma). `magnitudeBuffer`, when given, is n floats of scratch for the gradient magnitude.
std::vector<std::uint8_t> CannyEdges(const float* smoothed, const ImageGeometry& grid, double low, double high,
  double percentile, const ParallelFor& parallel, double* gradientMaximum = nullptr,
  float* magnitudeBuffer = nullptr, double lowFloor = 0.0, double highFloor = 0.0, double smoothingSigma = 0.0);
} // namespace featuremesh
