#include "Halftoning.h"

#include "ImagingInternals.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace featuremesh
{
using namespace detail;
std::vector<std::int64_t> Halftone(const float* rho, const ImageGeometry& g, double q)
{
  std::vector<std::int64_t> dots;
  const int nx = g.Dims[0], ny = g.Dims[1], nz = g.Dims[2];
  const float threshold = static_cast<float>(q);
  const float dot = static_cast<float>(2.0 * q);
  const bool is2D = g.Is2D();
  // Error buffers: current slice and next slice, so memory stays two slices, not the volume. They
  // carry a one-cell margin all round: error pushed off the image lands there and is never read,
  // so the inner loop needs no bounds checks (the sums in the image cells are unchanged).
  const std::int64_t pitch = nx + 2;
  const std::size_t padded = static_cast<std::size_t>(pitch) * (ny + 2);
  std::vector<float> cur(padded, 0.f), nxt(is2D ? 0 : padded, 0.f);
  const float w = is2D ? 1.f : 0.5f;
  const float right = w * (7.f / 16.f), downLeft = w * (3.f / 16.f), down = w * (5.f / 16.f),
              downRight = w * (1.f / 16.f);
  const bool toNextSlice = !is2D;
  const std::int64_t slice = g.SliceStride();
  for (int k = 0; k < nz; ++k)
  {
    const bool carry = toNextSlice && k + 1 < nz;
    for (int j = 0; j < ny; ++j)
    {
      const float* in = rho + k * slice + static_cast<std::int64_t>(j) * nx;
      float* c = cur.data() + (j + 1) * pitch + 1;
      float* z = carry ? nxt.data() + (j + 1) * pitch + 1 : nullptr;
      // The error pushed to the right neighbour stays in a register: added last, as it would be
      // in the buffer, so the sums are unchanged, without a store-to-load chain per voxel.
      float fromLeft = 0.f;
      for (int i = 0; i < nx; ++i)
      {
        const float v = in[i] + (c[i] + fromLeft);
        fromLeft = 0.f;
        if (std::fabs(v) < 1e-6f)
        {
          // Negligible error is dropped: it would otherwise decay through the flat background
          // into denormal floats, which made this loop 10x slower on skull-stripped MR.
          continue;
        }
        float err = v;
        if (v >= threshold)
        {
          dots.push_back(k * slice + static_cast<std::int64_t>(j) * nx + i);
          err = v - dot;
        }
        // Bounded error: saturated regions must not flood their neighbours.
        err = std::max(-dot, std::min(dot, err));
        fromLeft = err * right;
        c[i + pitch - 1] += err * downLeft;
        c[i + pitch] += err * down;
        c[i + pitch + 1] += err * downRight;
        if (carry)
        {
          const float e = 0.5f * err;
          z[i] += e * (6.f / 16.f);
          const float side = e * (2.5f / 16.f);
          z[i - 1] += side;
          z[i + 1] += side;
          z[i - pitch] += side;
          z[i + pitch] += side;
        }
      }
    }
    if (toNextSlice)
    {
      std::swap(cur, nxt);
      std::fill(nxt.begin(), nxt.end(), 0.f);
    }
  }
  return dots;
}
} // namespace featuremesh
