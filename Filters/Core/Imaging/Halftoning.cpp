#include "Halftoning.h"

#include "ImagingInternals.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace featuremesh
{
using namespace detail;
namespace
{
// Error diffusion over a grid of Dims cells (2D when the third is 1) whose rows come from row(j, k),
// a pointer to the row's Dims[0] values; returns the cells with dots, in order.
template <typename Row>
std::vector<std::int64_t> Diffuse(const std::array<int, 3>& dims, double q, Row&& row)
{
  std::vector<std::int64_t> dots;
  const int nx = dims[0], ny = dims[1], nz = dims[2];
  const float threshold = static_cast<float>(q);
  const float dot = static_cast<float>(2.0 * q);
  const bool is2D = nz == 1;
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
  const std::int64_t slice = static_cast<std::int64_t>(nx) * ny;
  for (int k = 0; k < nz; ++k)
  {
    const bool carry = toNextSlice && k + 1 < nz;
    for (int j = 0; j < ny; ++j)
    {
      const float* in = row(j, k);
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
} // namespace

std::vector<std::int64_t> Halftone(const float* rho, const ImageGeometry& g, double q)
{
  const std::int64_t slice = g.SliceStride();
  return Diffuse(g.Dims, q, [&](int j, int k) { return rho + k * slice + static_cast<std::int64_t>(j) * g.Dims[0]; });
}

std::vector<std::int64_t> HalftoneInMedianVoxels(const float* rho, const ImageGeometry& g, double q)
{
  const std::array<int, 3> m = g.MedianVoxelFactors();
  if (m[0] * m[1] * m[2] == 1)
  {
    return Halftone(rho, g, q);
  }
  std::array<int, 3> cells;
  for (int a = 0; a < 3; ++a)
  {
    cells[a] = (g.Dims[a] + m[a] - 1) / m[a];
  }
  // f(v) for each voxel of cell (ci, cj, ck): [c m, min((c + 1) m, Dims)) on each axis.
  const auto forCell = [&](int ci, int cj, int ck, auto&& f) {
    const std::array<int, 3> c{ { ci, cj, ck } };
    std::array<int, 3> lo, hi;
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = c[a] * m[a];
      hi[a] = std::min(lo[a] + m[a], g.Dims[a]);
    }
    for (int k = lo[2]; k < hi[2]; ++k)
    {
      for (int j = lo[1]; j < hi[1]; ++j)
      {
        for (int i = lo[0]; i < hi[0]; ++i)
        {
          f(g.Index(i, j, k));
        }
      }
    }
  };
  std::vector<float> means(cells[0]);
  std::vector<std::int64_t> dots = Diffuse(cells, q, [&](int cj, int ck) {
    for (int ci = 0; ci < cells[0]; ++ci)
    {
      double sum = 0.0;
      int count = 0;
      forCell(ci, cj, ck, [&](std::int64_t v) {
        sum += rho[v];
        ++count;
      });
      means[ci] = static_cast<float>(sum / count);
    }
    return means.data();
  });
  const std::int64_t cellSlice = static_cast<std::int64_t>(cells[0]) * cells[1];
  for (std::int64_t& d : dots)
  {
    std::int64_t peak = -1;
    forCell(static_cast<int>(d % cells[0]), static_cast<int>(d % cellSlice / cells[0]), static_cast<int>(d / cellSlice),
      [&](std::int64_t v) { peak = peak < 0 || rho[v] > rho[peak] ? v : peak; });
    d = peak;
  }
  std::sort(dots.begin(), dots.end());
  return dots;
}
} // namespace featuremesh
