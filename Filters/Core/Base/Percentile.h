// Percentiles of large arrays from an even sample: exact enough for a histogram range.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace featuremesh
{
// Percentile q (0..100) of component c of n tuples of `channels` interleaved values, over at most
// ~1 M evenly strided tuples (a 9 M-voxel volume is not copied and partially sorted whole); 0 when
// n is 0.
template <typename T>
double StridedPercentile(const T* values, std::int64_t n, double q, int channels = 1, int c = 0)
{
  if (n <= 0)
  {
    return 0.0;
  }
  const std::int64_t stride = std::max<std::int64_t>(1, n / 1000000);
  std::vector<double> v;
  v.reserve(static_cast<std::size_t>(n / stride + 1));
  for (std::int64_t i = 0; i < n; i += stride)
  {
    v.push_back(static_cast<double>(values[i * channels + c]));
  }
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q / 100.0 * static_cast<double>(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}
} // namespace featuremesh
