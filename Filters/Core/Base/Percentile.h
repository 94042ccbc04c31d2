// Percentiles of large arrays from an even sample: exact enough for a histogram range.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

namespace featuremesh
{
// The 0.5 and 99.5 percentiles of component c of n tuples of `channels` interleaved values, from one
// sample of at most ~1 M evenly strided tuples (a 9 M-voxel volume is not copied and partially
// sorted whole); { 0, 0 } when n is 0.
template <typename T>
std::array<double, 2> StridedRange(const T* values, std::int64_t n, int channels = 1, int c = 0)
{
  if (n <= 0)
  {
    return { { 0.0, 0.0 } };
  }
  const std::int64_t stride = std::max<std::int64_t>(1, n / 1000000);
  std::vector<double> v;
  v.reserve(static_cast<std::size_t>(n / stride + 1));
  for (std::int64_t i = 0; i < n; i += stride)
  {
    v.push_back(static_cast<double>(values[i * channels + c]));
  }
  const auto rank = [&](double q) {
    return std::min(v.size() - 1, static_cast<std::size_t>(q / 100.0 * static_cast<double>(v.size() - 1) + 0.5));
  };
  const auto low = v.begin() + static_cast<std::ptrdiff_t>(rank(0.5));
  const auto high = v.begin() + static_cast<std::ptrdiff_t>(rank(99.5));
  std::nth_element(v.begin(), low, v.end());
  // Every value after the low rank is at least its value: the high rank's is among them.
  if (high > low)
  {
    std::nth_element(low + 1, high, v.end());
  }
  return { { *low, *high } };
}

// A histogram's range over the values: their StridedRange, one unit wide when its ends meet.
template <typename T>
std::array<double, 2> HistogramRange(const T* values, std::int64_t n, int channels = 1, int c = 0)
{
  const std::array<double, 2> range = StridedRange(values, n, channels, c);
  return { { range[0], range[1] > range[0] ? range[1] : range[0] + 1.0 } };
}
} // namespace featuremesh
