#include "FeatureNodes.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <numeric>

namespace featuremesh
{
namespace
{
// Fixed block count for reductions, so that results never depend on the thread count.
constexpr std::int64_t ReductionBlocks = 64;

using Clock = std::chrono::steady_clock;
double SecondsSince(Clock::time_point t0)
{
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Central difference along one axis with one-sided differences on the border.
inline float Diff(const float* f, std::int64_t idx, int coord, int dim, std::int64_t stride)
{
  if (dim < 2)
  {
    return 0.f;
  }
  if (coord == 0)
  {
    return f[idx + stride] - f[idx];
  }
  if (coord == dim - 1)
  {
    return f[idx] - f[idx - stride];
  }
  return 0.5f * (f[idx + stride] - f[idx - stride]);
}

// The gradient direction quantised to one of the 8 (2D) or 26 (3D) neighbour steps: a component
// is kept, with its sign, when it is at least tan(22.5 deg) of the largest. Branch-free: on noisy
// images every test is a coin flip for the branch predictor.
inline std::array<int, 3> QuantisedDirection(float gx, float gy, float gz)
{
  constexpr float tan22 = 0.41421356f;
  const float cut = tan22 * std::max(std::fabs(gx), std::max(std::fabs(gy), std::fabs(gz)));
  auto component = [cut](float v) { return static_cast<int>(std::fabs(v) >= cut) * ((v > 0.f) - (v < 0.f)); };
  return { { component(gx), component(gy), component(gz) } };
}

inline void Coordinates(const ImageGeometry& g, std::int64_t idx, int& i, int& j, int& k)
{
  const std::int64_t slice = g.SliceStride();
  k = static_cast<int>(idx / slice);
  const std::int64_t r = idx - k * slice;
  j = static_cast<int>(r / g.Dims[0]);
  i = static_cast<int>(r - static_cast<std::int64_t>(j) * g.Dims[0]);
}

// True when some voxel within the centred box of half-width h around (i,j,k) is set in mask.
bool AnyInBox(const std::vector<std::uint8_t>& mask, const ImageGeometry& g, int i, int j, int k, int h)
{
  const int k0 = std::max(0, k - h), k1 = std::min(g.Dims[2] - 1, k + h);
  const int j0 = std::max(0, j - h), j1 = std::min(g.Dims[1] - 1, j + h);
  const int i0 = std::max(0, i - h), i1 = std::min(g.Dims[0] - 1, i + h);
  for (int kk = k0; kk <= k1; ++kk)
  {
    for (int jj = j0; jj <= j1; ++jj)
    {
      const std::uint8_t* row = mask.data() + g.Index(0, jj, kk);
      for (int ii = i0; ii <= i1; ++ii)
      {
        if (row[ii])
        {
          return true;
        }
      }
    }
  }
  return false;
}

// Eight bytes that are each 0 or 1, packed into 8 bits (byte b -> bit b); the multiply cannot carry.
inline std::uint64_t PackBytes(const std::uint8_t* p)
{
  std::uint64_t x;
  std::memcpy(&x, p, 8);
  return (x * 0x0102040810204080ULL) >> 56;
}

// Evenly spaced positions 0..last with gaps of at most `spacing`.
std::vector<int> EvenPositions(int extent, int spacing)
{
  std::vector<int> pos;
  if (extent <= 1)
  {
    pos.push_back(0);
    return pos;
  }
  const int last = extent - 1;
  const int segments = std::max(1, (last + spacing - 1) / spacing);
  for (int s = 0; s <= segments; ++s)
  {
    pos.push_back(static_cast<int>(std::lround(static_cast<double>(s) * last / segments)));
  }
  return pos;
}
} // namespace

std::string ValidateParameters(const FeatureNodeParameters& p)
{
  if (!(p.GaussianSigma >= 0.0 && p.GaussianSigma <= 50.0) || !(p.HessianSigma >= 0.0 && p.HessianSigma <= 50.0))
  {
    return "the Gaussian and Hessian sigmas must lie in [0, 50] voxels.";
  }
  if (!(p.LowThreshold >= 0.0) || !(p.HighThreshold > 0.0))
  {
    return "Canny thresholds must be non-negative and the high threshold positive.";
  }
  if (p.LowThreshold > p.HighThreshold)
  {
    return "the low Canny threshold is above the high one; they are out of order.";
  }
  if (!(p.MaximumPercentile > 0.0 && p.MaximumPercentile <= 100.0))
  {
    return "the gradient maximum percentile must lie in (0, 100].";
  }
  if (p.CovarianceNeighbourhood < 0 || p.CovarianceNeighbourhood > 41)
  {
    return "the covariance neighbourhood must be 0 (automatic) or an edge length up to 41 voxels.";
  }
  if (!(p.StraightRatio > 0.0 && p.StraightRatio <= p.CurvedRatio && p.CurvedRatio <= 1.0))
  {
    return "eigenvalue-ratio thresholds must satisfy 0 < straight <= curved <= 1.";
  }
  for (int r : { p.Radii2D[0], p.Radii2D[1], p.Radii2D[2], p.Radii3D[0], p.Radii3D[1], p.Radii3D[2] })
  {
    if (r < 0 || r > 50)
    {
      return "sampling radii must lie between 0 and 50 voxels.";
    }
  }
  if (!(p.FeaturePercentile > 0.0 && p.FeaturePercentile <= 100.0))
  {
    return "the feature-map maximum percentile must lie in (0, 100].";
  }
  if (!(p.HalftoneThreshold > 0.0 && p.HalftoneThreshold < 1.0))
  {
    return "the halftone threshold q must lie in (0, 1).";
  }
  if (!(p.HalftoneGamma > 0.0 && p.HalftoneGamma <= 10.0))
  {
    return "the halftone exponent gamma must lie in (0, 10].";
  }
  if (p.ExclusionWindow < 1 || p.ExclusionWindow > 101)
  {
    return "the exclusion window must be between 1 and 101 voxels.";
  }
  if (p.UniformSpacing < 1 || p.BoundarySpacing < 1)
  {
    return "uniform and boundary spacings must be at least one voxel.";
  }
  return std::string();
}

namespace
{
// True when all n values equal the first.
inline bool ConstantRow(const float* x, int n)
{
  const float c = x[0];
  bool same = true;
  for (int i = 1; i < n; ++i)
  {
    same &= x[i] == c;
  }
  return same;
}

// One Gaussian pass along x, row by row through a padded copy (borders replicated). Constant
// rows (the flat background of skull-stripped MR, padding) get the same sum the convolution would
// form, without convolving. Returns whether the smoothed row is constant.
bool SmoothRowX(const float* src, float* dst, int nx, const std::vector<float>& w, std::vector<float>& pad)
{
  const int r = static_cast<int>(w.size() / 2);
  if (ConstantRow(src, nx))
  {
    float acc = 0.f;
    for (int t = 0; t <= 2 * r; ++t)
    {
      acc += w[t] * src[0];
    }
    std::fill(dst, dst + nx, acc);
    return true;
  }
  for (int i = 0; i < nx + 2 * r; ++i)
  {
    pad[i] = src[std::min(nx - 1, std::max(0, i - r))];
  }
  // Tap by tap over the whole row, so the inner loop vectorises; per voxel the same sum, in the
  // same order, as a tap loop inside a voxel loop.
  std::fill(dst, dst + nx, 0.f);
  for (int t = 0; t <= 2 * r; ++t)
  {
    const float wt = w[t];
    const float* p = pad.data() + t;
    for (int i = 0; i < nx; ++i)
    {
      dst[i] += wt * p[i];
    }
  }
  return ConstantRow(dst, nx);
}

// One Gaussian pass across a stack of `count` rows of nx values (row q at rows + q * nx, `flat[q]`
// when it is constant): output row `o` from rows o-r..o+r, borders replicated, whole rows weighted
// and added so the inner loop runs along contiguous memory. When all source rows are constant, the
// same sum in the same order fills the row.
void SmoothAcrossRows(float* o, int nx, const std::vector<float>& w, const float* rows, const std::uint8_t* flat,
  int count, int index)
{
  const int r = static_cast<int>(w.size() / 2);
  auto source = [&](int t) { return std::min(count - 1, std::max(0, index + t)); };
  bool allFlat = true;
  float exact = 0.f;
  for (int t = -r; t <= r && allFlat; ++t)
  {
    allFlat = flat[source(t)] != 0;
    exact += w[t + r] * rows[static_cast<std::int64_t>(source(t)) * nx];
  }
  if (allFlat)
  {
    std::fill(o, o + nx, exact);
    return;
  }
  std::fill(o, o + nx, 0.f);
  for (int t = -r; t <= r; ++t)
  {
    const float* s = rows + static_cast<std::int64_t>(source(t)) * nx;
    const float wt = w[t + r];
    for (int i = 0; i < nx; ++i)
    {
      o[i] += wt * s[i];
    }
  }
}
} // namespace

void GaussianSmooth(const float* in, float* out, const ImageGeometry& g, double sigma, const ParallelFor& parallel)
{
  const std::int64_t n = g.Size();
  if (sigma <= 0.0)
  {
    std::copy(in, in + n, out);
    return;
  }
  const int r = std::max(1, static_cast<int>(std::ceil(3.0 * sigma)));
  std::vector<float> w(2 * r + 1);
  double sum = 0.0;
  for (int t = -r; t <= r; ++t)
  {
    sum += w[t + r] = static_cast<float>(std::exp(-0.5 * t * t / (sigma * sigma)));
  }
  for (float& v : w)
  {
    v = static_cast<float>(v / sum);
  }
  const int nx = g.Dims[0], ny = g.Dims[1], nz = g.Dims[2];
  const std::int64_t slice = g.SliceStride();
  if (nz == 1)
  {
    // 2D: the x pass over all rows in parallel, then the y pass in parallel.
    std::vector<float> xs(slice);
    std::vector<std::uint8_t> flat(ny);
    parallel(ny, 16, [&](std::int64_t j0, std::int64_t j1) {
      std::vector<float> pad(nx + 2 * r);
      for (std::int64_t j = j0; j < j1; ++j)
      {
        flat[j] = SmoothRowX(in + j * nx, xs.data() + j * nx, nx, w, pad);
      }
    });
    parallel(ny, 16, [&](std::int64_t j0, std::int64_t j1) {
      for (std::int64_t j = j0; j < j1; ++j)
      {
        SmoothAcrossRows(out + j * nx, nx, w, xs.data(), flat.data(), ny, static_cast<int>(j));
      }
    });
    return;
  }
  // x and y, one slice at a time in a slice-sized buffer that stays in cache; no volume-sized
  // temporary (a fresh 36 MB buffer costs ~20 ms of page faults on these machines).
  parallel(nz, 1, [&](std::int64_t k0, std::int64_t k1) {
    std::vector<float> xs(slice), pad(nx + 2 * r);
    std::vector<std::uint8_t> flat(ny);
    for (std::int64_t k = k0; k < k1; ++k)
    {
      for (int j = 0; j < ny; ++j)
      {
        flat[j] = SmoothRowX(in + k * slice + static_cast<std::int64_t>(j) * nx,
          xs.data() + static_cast<std::int64_t>(j) * nx, nx, w, pad);
      }
      for (int j = 0; j < ny; ++j)
      {
        SmoothAcrossRows(out + k * slice + static_cast<std::int64_t>(j) * nx, nx, w, xs.data(), flat.data(), ny, j);
      }
    }
  });
  // z, in place: each task copies the column of rows it owns (all k for one j) into a private
  // buffer, then writes the smoothed rows back.
  parallel(ny, 1, [&](std::int64_t j0, std::int64_t j1) {
    std::vector<float> column(static_cast<std::size_t>(nz) * nx);
    std::vector<std::uint8_t> flat(nz);
    for (std::int64_t j = j0; j < j1; ++j)
    {
      for (int k = 0; k < nz; ++k)
      {
        const float* row = out + k * slice + j * nx;
        std::copy(row, row + nx, column.data() + static_cast<std::int64_t>(k) * nx);
        flat[k] = ConstantRow(row, nx) ? 1 : 0;
      }
      for (int k = 0; k < nz; ++k)
      {
        SmoothAcrossRows(out + k * slice + j * nx, nx, w, column.data(), flat.data(), nz, k);
      }
    }
  });
}

void GradientMagnitude(const float* f, const ImageGeometry& g, float* magnitude, const ParallelFor& parallel)
{
  const std::int64_t sx = 1, sy = g.Dims[0], sz = g.SliceStride();
  const std::int64_t rows = static_cast<std::int64_t>(g.Dims[1]) * g.Dims[2];
  parallel(rows, 16, [&](std::int64_t r0, std::int64_t r1) {
    for (std::int64_t r = r0; r < r1; ++r)
    {
      const int j = static_cast<int>(r % g.Dims[1]);
      const int k = static_cast<int>(r / g.Dims[1]);
      const std::int64_t row = g.Index(0, j, k);
      const bool interior = g.Dims[0] > 2 && j > 0 && j + 1 < g.Dims[1] && (g.Dims[2] == 1 || (k > 0 && k + 1 < g.Dims[2]));
      if (interior)
      {
        // Branch-free central differences, so the compiler vectorises the row.
        const float* c = f + row;
        const std::int64_t szz = g.Dims[2] == 1 ? 0 : sz;
        float* out = magnitude + row;
        for (int i = 1; i + 1 < g.Dims[0]; ++i)
        {
          const float gx = 0.5f * (c[i + 1] - c[i - 1]);
          const float gy = 0.5f * (c[i + sy] - c[i - sy]);
          const float gz = 0.5f * (c[i + szz] - c[i - szz]);
          out[i] = std::sqrt(gx * gx + gy * gy + gz * gz);
        }
      }
      std::int64_t idx = row;
      for (int i = 0; i < g.Dims[0]; ++i, ++idx)
      {
        if (interior && i > 0 && i + 1 < g.Dims[0])
        {
          i = g.Dims[0] - 2;
          idx = row + i;
          continue;
        }
        const float gx = Diff(f, idx, i, g.Dims[0], sx);
        const float gy = Diff(f, idx, j, g.Dims[1], sy);
        const float gz = Diff(f, idx, k, g.Dims[2], sz);
        magnitude[idx] = std::sqrt(gx * gx + gy * gy + gz * gz);
      }
    }
  });
}

double RobustMaximum(const float* v, std::int64_t n, double percentile, const ParallelFor& parallel)
{
  if (n <= 0)
  {
    return 0.0;
  }
  const std::int64_t block = (n + ReductionBlocks - 1) / ReductionBlocks;
  std::vector<float> blockMax(ReductionBlocks, 0.f);
  parallel(ReductionBlocks, 1, [&](std::int64_t b0, std::int64_t b1) {
    for (std::int64_t b = b0; b < b1; ++b)
    {
      float m = 0.f;
      for (std::int64_t i = b * block, e = std::min(n, (b + 1) * block); i < e; ++i)
      {
        m = std::max(m, v[i]);
      }
      blockMax[b] = m;
    }
  });
  const double maximum = *std::max_element(blockMax.begin(), blockMax.end());
  if (percentile >= 100.0 || maximum <= 0.0)
  {
    return maximum;
  }
  constexpr int bins = 4096;
  // Counts are integers, so any split into blocks gives the same histogram: few blocks on small
  // images, where merging 64 histograms would cost as much as filling them.
  const std::int64_t histBlocks = std::max<std::int64_t>(1, std::min<std::int64_t>(ReductionBlocks, n / (16 * bins)));
  const std::int64_t histBlock = (n + histBlocks - 1) / histBlocks;
  std::vector<std::int32_t> hist(static_cast<size_t>(histBlocks) * bins, 0);
  const double scale = bins / maximum;
  parallel(histBlocks, 1, [&](std::int64_t b0, std::int64_t b1) {
    for (std::int64_t b = b0; b < b1; ++b)
    {
      std::int32_t* h = hist.data() + b * bins;
      for (std::int64_t i = b * histBlock, e = std::min(n, (b + 1) * histBlock); i < e; ++i)
      {
        h[std::min(bins - 1, static_cast<int>(v[i] * scale))]++;
      }
    }
  });
  std::vector<std::int64_t> total(bins, 0);
  for (std::int64_t b = 0; b < histBlocks; ++b)
  {
    for (int i = 0; i < bins; ++i)
    {
      total[i] += hist[b * bins + i];
    }
  }
  const double target = percentile / 100.0 * static_cast<double>(n);
  std::int64_t cumulative = 0;
  for (int i = 0; i < bins; ++i)
  {
    cumulative += total[i];
    if (static_cast<double>(cumulative) >= target)
    {
      // Upper edge of the bin: a percentile falling in the zero bin of a mostly flat image
      // still gives a positive maximum.
      return std::min(maximum, (i + 1) / scale);
    }
  }
  return maximum;
}

std::vector<std::uint8_t> CannyEdges(const float* f, const ImageGeometry& g, double low, double high, double percentile,
  const ParallelFor& parallel, double* gradientMaximum, float* magnitudeBuffer)
{
  const std::int64_t n = g.Size();
  std::vector<float> ownMagnitude(magnitudeBuffer ? 0 : n);
  float* mag = magnitudeBuffer ? magnitudeBuffer : ownMagnitude.data();
  GradientMagnitude(f, g, mag, parallel);
  const double gmax = RobustMaximum(mag, n, percentile, parallel);
  if (gradientMaximum)
  {
    *gradientMaximum = gmax;
  }
  std::vector<std::uint8_t> state(n, 0); // 0 none, 1 weak candidate, 2 strong
  if (gmax <= 0.0)
  {
    return state;
  }
  const float lowValue = static_cast<float>(low * gmax);
  const float highValue = static_cast<float>(high * gmax);
  const std::int64_t sy = g.Dims[0], sz = g.SliceStride();
  const std::int64_t rows = static_cast<std::int64_t>(g.Dims[1]) * g.Dims[2];

  // Non-maximum suppression along the quantised gradient direction; ties resolved by ">" on one
  // side and ">=" on the other, so a two-voxel plateau keeps exactly one voxel.
  parallel(rows, 16, [&, mag](std::int64_t r0, std::int64_t r1) {
    // Locals, not captured references: the byte stores into `state` may alias anything, and would
    // force a reload of every captured value per voxel.
    std::uint8_t* const edgeState = state.data();
    const float lowV = lowValue, highV = highValue;
    for (std::int64_t r = r0; r < r1; ++r)
    {
      const int j = static_cast<int>(r % g.Dims[1]);
      const int k = static_cast<int>(r / g.Dims[1]);
      const std::int64_t row = g.Index(0, j, k);
      const bool interiorRow = g.Dims[0] > 2 && j > 0 && j + 1 < g.Dims[1] && (g.Dims[2] == 1 || (k > 0 && k + 1 < g.Dims[2]));
      if (interiorRow)
      {
        // Away from the border: central differences and neighbours without bounds checks (the
        // same values the general loop below computes).
        const std::int64_t szz = g.Dims[2] == 1 ? 0 : sz;
        for (int i = 1; i + 1 < g.Dims[0]; ++i)
        {
          // Branch-free past the threshold test, which large flat regions predict well.
          const std::int64_t idx = row + i;
          const float m = mag[idx];
          if (m < lowV || m <= 0.f)
          {
            continue;
          }
          const float gx = 0.5f * (f[idx + 1] - f[idx - 1]);
          const float gy = 0.5f * (f[idx + sy] - f[idx - sy]);
          const float gz = 0.5f * (f[idx + szz] - f[idx - szz]); // 0 in 2D (szz = 0)
          const std::array<int, 3> d = QuantisedDirection(gx, gy, gz);
          const std::int64_t step = d[0] + d[1] * sy + d[2] * szz;
          const bool keep = (m > mag[idx + step]) & (m >= mag[idx - step]);
          edgeState[idx] = static_cast<std::uint8_t>(keep * (1 + (m >= highV)));
        }
      }
      std::int64_t idx = row;
      for (int i = 0; i < g.Dims[0]; ++i, ++idx)
      {
        if (interiorRow && i > 0 && i + 1 < g.Dims[0])
        {
          i = g.Dims[0] - 2;
          idx = row + i;
          continue;
        }
        const float m = mag[idx];
        if (m < lowValue || m <= 0.f)
        {
          continue;
        }
        const float gx = Diff(f, idx, i, g.Dims[0], 1);
        const float gy = Diff(f, idx, j, g.Dims[1], sy);
        const float gz = Diff(f, idx, k, g.Dims[2], sz);
        const std::array<int, 3> d = QuantisedDirection(gx, gy, gz);
        const int dx = d[0], dy = d[1], dz = d[2];
        float ahead = 0.f, behind = 0.f;
        if (g.Contains(i + dx, j + dy, k + dz))
        {
          ahead = mag[g.Index(i + dx, j + dy, k + dz)];
        }
        if (g.Contains(i - dx, j - dy, k - dz))
        {
          behind = mag[g.Index(i - dx, j - dy, k - dz)];
        }
        if (m > ahead && m >= behind)
        {
          state[idx] = m >= highValue ? 2 : 1;
        }
      }
    }
  });
  // Hysteresis: grow the strong voxels through connected candidates, marking visited ones 3. The
  // result (the candidate components that hold a strong voxel) does not depend on visiting order.
  const int kr = g.Is2D() ? 0 : 1;
  const int nx = g.Dims[0], ny = g.Dims[1], nz = g.Dims[2];
  std::vector<std::int64_t> offsets;
  for (int dk = -kr; dk <= kr; ++dk)
  {
    for (int dj = -1; dj <= 1; ++dj)
    {
      for (int di = -1; di <= 1; ++di)
      {
        if (di || dj || dk)
        {
          offsets.push_back(dk * sz + dj * sy + di);
        }
      }
    }
  }
  std::vector<std::int64_t> stack;
  for (std::int64_t s = 0; s < n; ++s)
  {
    if (state[s] != 2)
    {
      continue;
    }
    state[s] = 3;
    stack.push_back(s);
    while (!stack.empty())
    {
      const std::int64_t c = stack.back();
      stack.pop_back();
      int i, j, k;
      Coordinates(g, c, i, j, k);
      const bool interior = i > 0 && i + 1 < nx && j > 0 && j + 1 < ny && (kr == 0 || (k > 0 && k + 1 < nz));
      if (interior)
      {
        // No bounds checks away from the border: plain offsets.
        for (const std::int64_t o : offsets)
        {
          const std::int64_t q = c + o;
          if (state[q] == 1 || state[q] == 2)
          {
            state[q] = 3;
            stack.push_back(q);
          }
        }
        continue;
      }
      for (int dk = -kr; dk <= kr; ++dk)
      {
        for (int dj = -1; dj <= 1; ++dj)
        {
          for (int di = -1; di <= 1; ++di)
          {
            if (!g.Contains(i + di, j + dj, k + dk))
            {
              continue;
            }
            const std::int64_t q = g.Index(i + di, j + dj, k + dk);
            if (state[q] == 1 || state[q] == 2)
            {
              state[q] = 3;
              stack.push_back(q);
            }
          }
        }
      }
    }
  }
  parallel(n, 65536, [&](std::int64_t b, std::int64_t e) {
    for (std::int64_t i = b; i < e; ++i)
    {
      state[i] = state[i] == 3 ? 1 : 0;
    }
  });
  return state;
}

std::vector<std::uint8_t> EdgeSampleRadii(const std::vector<std::int64_t>& pts,
  const std::vector<std::uint8_t>& edgeMap, const ImageGeometry& g, const FeatureNodeParameters& p,
  const ParallelFor& parallel)
{
  const bool is2D = g.Is2D();
  const int window = p.CovarianceNeighbourhood > 0 ? p.CovarianceNeighbourhood : (is2D ? 11 : 5);
  const int h = window / 2;
  const int width = 2 * h + 1;
  const std::array<int, 3>& radii = is2D ? p.Radii2D : p.Radii3D;
  // Each row of the box is read as a bit pattern whose count and first and second x-moments come
  // from a table: one lookup per row instead of a branch per voxel (3x faster on BraTS). Integer
  // sums, so the moments are exact and identical to a voxel-by-voxel sum.
  constexpr int maxTableWidth = 13;
  const bool useTable = width <= maxTableWidth;
  std::vector<std::array<std::int32_t, 3>> rowMoments;
  if (useTable)
  {
    rowMoments.resize(std::size_t(1) << width);
    for (std::size_t bits = 0; bits < rowMoments.size(); ++bits)
    {
      std::array<std::int32_t, 3> m{ { 0, 0, 0 } };
      for (int b = 0; b < width; ++b)
      {
        if (bits >> b & 1)
        {
          const int x = b - h;
          m[0] += 1;
          m[1] += x;
          m[2] += x * x;
        }
      }
      rowMoments[bits] = m;
    }
  }
  const unsigned widthMask = (1u << width) - 1u;
  const std::int64_t n = g.Size();
  std::vector<std::uint8_t> result(pts.size());
  parallel(static_cast<std::int64_t>(pts.size()), 256, [&](std::int64_t b, std::int64_t e) {
    // Locals rather than captures, and scalar accumulators rather than arrays, so that they stay
    // in registers (they were spilled and reloaded per row).
    const std::uint8_t* const edges = edgeMap.data();
    const std::array<std::int32_t, 3>* const table = rowMoments.data();
    const int nx = g.Dims[0], ny = g.Dims[1], nz = g.Dims[2];
    const unsigned mask = widthMask;
    for (std::int64_t t = b; t < e; ++t)
    {
      int i, j, k;
      Coordinates(g, pts[t], i, j, k);
      // Moments relative to the centre point keep the sums small and exact (integers).
      std::int64_t count = 0, s0 = 0, s1 = 0, s2 = 0, q0 = 0, q1 = 0, q2 = 0, q3 = 0, q4 = 0, q5 = 0;
      const int k0 = std::max(0, k - h), k1 = std::min(nz - 1, k + h);
      const int j0 = std::max(0, j - h), j1 = std::min(ny - 1, j + h);
      const int i0 = std::max(0, i - h), i1 = std::min(nx - 1, i + h);
      const bool packed = useTable && i - h >= 0 && i + h < nx;
      for (int kk = k0; kk <= k1; ++kk)
      {
        const std::int64_t z = kk - k;
        // Per-slice sums: count, x, x^2, y, y^2, xy.
        std::int64_t C = 0, X = 0, XX = 0, YC = 0, YYC = 0, YX = 0;
        for (int jj = j0; jj <= j1; ++jj)
        {
          const std::int64_t y = jj - j;
          const std::int64_t rowStart = g.Index(0, jj, kk);
          const std::uint8_t* row = edges + rowStart;
          std::int64_t c = 0, sx = 0, sxx = 0;
          if (useTable)
          {
            unsigned bits = 0;
            const std::int64_t from = rowStart + i - h;
            if (packed && from + 16 <= n)
            {
              // Interior row: two 8-byte loads, each packed to 8 bits (bytes are 0 or 1).
              bits = static_cast<unsigned>(PackBytes(edges + from) | PackBytes(edges + from + 8) << 8) & mask;
            }
            else
            {
              for (int ii = i0; ii <= i1; ++ii)
              {
                bits |= static_cast<unsigned>(row[ii] != 0) << (ii - i + h);
              }
            }
            const auto& m = table[bits];
            c = m[0];
            sx = m[1];
            sxx = m[2];
          }
          else
          {
            for (int ii = i0; ii <= i1; ++ii)
            {
              const std::int64_t on = row[ii] != 0, x = ii - i;
              c += on;
              sx += on * x;
              sxx += on * x * x;
            }
          }
          C += c;
          X += sx;
          XX += sxx;
          YC += y * c;
          YYC += y * y * c;
          YX += y * sx;
        }
        count += C;
        s0 += X;
        s1 += YC;
        s2 += z * C;
        q0 += XX;
        q1 += YYC;
        q2 += z * z * C;
        q3 += YX;
        q4 += z * X;
        q5 += z * YC;
      }
      int cls = 2; // curved, corner or speck: densest sampling
      if (count > g.Dimension())
      {
        const double c = static_cast<double>(count);
        const double m0 = static_cast<double>(s0), m1 = static_cast<double>(s1), m2 = static_cast<double>(s2);
        Eigen::Matrix3d cov;
        cov(0, 0) = static_cast<double>(q0) / c - m0 * m0 / (c * c);
        cov(1, 1) = static_cast<double>(q1) / c - m1 * m1 / (c * c);
        cov(2, 2) = static_cast<double>(q2) / c - m2 * m2 / (c * c);
        cov(0, 1) = cov(1, 0) = static_cast<double>(q3) / c - m0 * m1 / (c * c);
        cov(0, 2) = cov(2, 0) = static_cast<double>(q4) / c - m0 * m2 / (c * c);
        cov(1, 2) = cov(2, 1) = static_cast<double>(q5) / c - m1 * m2 / (c * c);
        double ratio = 1.0;
        if (is2D)
        {
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es;
          es.computeDirect(cov.topLeftCorner<2, 2>(), Eigen::EigenvaluesOnly);
          const double l1 = es.eigenvalues()(1), l2 = std::max(0.0, es.eigenvalues()(0));
          ratio = l1 > 1e-12 ? l2 / l1 : 1.0;
        }
        else
        {
          Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
          es.computeDirect(cov, Eigen::EigenvaluesOnly);
          const double l1 = es.eigenvalues()(2), l3 = std::max(0.0, es.eigenvalues()(0));
          ratio = l1 > 1e-12 ? l3 / l1 : 1.0;
        }
        cls = ratio < p.StraightRatio ? 0 : (ratio < p.CurvedRatio ? 1 : 2);
      }
      result[t] = static_cast<std::uint8_t>(radii[cls]);
    }
  });
  return result;
}

std::vector<std::int64_t> ThinEdgePoints(
  const std::vector<std::int64_t>& pts, const std::vector<std::uint8_t>& radii, const ImageGeometry& g)
{
  // Densely sampled (curved) points first, so that straight runs give way to corners; within a
  // radius, in voxel order. A counting sort: radii are small integers.
  std::array<std::int64_t, 257> first{};
  for (std::uint8_t r : radii)
  {
    first[r + 1]++;
  }
  for (int r = 1; r < 257; ++r)
  {
    first[r] += first[r - 1];
  }
  std::vector<std::int64_t> order(pts.size());
  for (std::size_t t = 0; t < pts.size(); ++t)
  {
    order[first[radii[t]]++] = static_cast<std::int64_t>(t);
  }

  // Small radii (all the defaults): a map of the Chebyshev distance to the nearest kept point,
  // capped past the largest radius, stamped around each kept point. A point is blocked exactly when
  // that distance is at most its radius: one lookup per query (BraTS thinning 43 -> 25 ms).
  const int largest = radii.empty() ? 0 : *std::max_element(radii.begin(), radii.end());
  constexpr int maxStampRadius = 8;
  if (largest <= maxStampRadius)
  {
    const std::uint8_t far = static_cast<std::uint8_t>(largest + 1);
    std::vector<std::uint8_t> distance(static_cast<std::size_t>(g.Size()), far);
    std::vector<std::int64_t> kept;
    const int kr = g.Is2D() ? 0 : largest;
    for (std::int64_t t : order)
    {
      if (distance[pts[t]] <= radii[t])
      {
        continue;
      }
      kept.push_back(t);
      int i, j, k;
      Coordinates(g, pts[t], i, j, k);
      for (int dk = std::max(-kr, -k); dk <= std::min(kr, g.Dims[2] - 1 - k); ++dk)
      {
        for (int dj = std::max(-largest, -j); dj <= std::min(largest, g.Dims[1] - 1 - j); ++dj)
        {
          std::uint8_t* row = distance.data() + g.Index(0, j + dj, k + dk);
          const int dkj = std::max(std::abs(dk), std::abs(dj));
          for (int di = std::max(-largest, -i); di <= std::min(largest, g.Dims[0] - 1 - i); ++di)
          {
            const std::uint8_t d = static_cast<std::uint8_t>(std::max(dkj, std::abs(di)));
            row[i + di] = std::min(row[i + di], d);
          }
        }
      }
    }
    return kept;
  }

  // Bucket grid of kept points, so that a query looks at a few cells instead of a (2R+1)^3 box.
  constexpr int cell = 4;
  const int cx = (g.Dims[0] + cell - 1) / cell, cy = (g.Dims[1] + cell - 1) / cell,
            cz = (g.Dims[2] + cell - 1) / cell;
  std::vector<std::int64_t> head(static_cast<size_t>(cx) * cy * cz, -1);
  std::vector<std::int64_t> next;
  std::vector<std::array<int, 3>> keptPos;
  std::vector<std::int64_t> kept;
  for (std::int64_t t : order)
  {
    int i, j, k;
    Coordinates(g, pts[t], i, j, k);
    const int r = radii[t];
    bool blocked = false;
    for (int bz = std::max(0, (k - r) / cell); !blocked && bz <= std::min(cz - 1, (k + r) / cell); ++bz)
    {
      for (int by = std::max(0, (j - r) / cell); !blocked && by <= std::min(cy - 1, (j + r) / cell); ++by)
      {
        for (int bx = std::max(0, (i - r) / cell); !blocked && bx <= std::min(cx - 1, (i + r) / cell); ++bx)
        {
          for (std::int64_t q = head[(static_cast<size_t>(bz) * cy + by) * cx + bx]; q >= 0; q = next[q])
          {
            const auto& o = keptPos[q];
            if (std::abs(o[0] - i) <= r && std::abs(o[1] - j) <= r && std::abs(o[2] - k) <= r)
            {
              blocked = true;
              break;
            }
          }
        }
      }
    }
    if (blocked)
    {
      continue;
    }
    const size_t c = (static_cast<size_t>(k / cell) * cy + j / cell) * cx + i / cell;
    next.push_back(head[c]);
    head[c] = static_cast<std::int64_t>(keptPos.size());
    keptPos.push_back({ { i, j, k } });
    kept.push_back(t);
  }
  return kept;
}

inline float LargestAbsEigenvalueInline(float a11, float a22, float a33, float a12, float a13, float a23)
{
  // Trigonometric solution of the characteristic cubic (Smith 1961) without trigonometry: for
  // C = (A - qI)/p the roots are 2cos((acos r)/3 + 2k pi/3), r = det(C)/2. The largest,
  // 2cos(2 acos(u)/3) with u = sqrt((1+r)/2), is smooth in u on [0,1]: a degree-8 polynomial
  // (Chebyshev fit, error 9e-9) replaces acos and cos, and the smallest root follows from
  // c2 + c3 = -c1, c2 c3 = c1^2 - 3. Branch-free, so a row of voxels vectorises; it replaced
  // Eigen's computeDirect (atan2, sincos), which took 90 of 650 ms on BraTS.
  const float q = (a11 + a22 + a33) * (1.f / 3.f);
  const float b11 = a11 - q, b22 = a22 - q, b33 = a33 - q;
  const float p2 = (b11 * b11 + b22 * b22 + b33 * b33 + 2.f * (a12 * a12 + a13 * a13 + a23 * a23)) * (1.f / 6.f);
  const float p = std::sqrt(p2);
  // p = 0 means B = 0: any finite inv then gives C = 0 and both roots q.
  const float inv = 1.f / std::max(p, 1e-30f);
  const float c11 = b11 * inv, c22 = b22 * inv, c33 = b33 * inv, c12 = a12 * inv, c13 = a13 * inv, c23 = a23 * inv;
  const float det = c11 * (c22 * c33 - c23 * c23) - c12 * (c12 * c33 - c23 * c13) + c13 * (c12 * c23 - c22 * c13);
  const float r = std::min(1.f, std::max(-1.f, 0.5f * det));
  const float u = std::sqrt(0.5f * (1.f + r));
  const float g = 0.50000001f +
    u * (0.57734945f +
          u * (-0.1110921f +
                u * (0.05326813f +
                      u * (-0.03190076f + u * (0.01957721f + u * (-0.01023717f + u * (0.00366753f + u * -0.0006323f)))))));
  const float c1 = 2.f * g;
  const float c3 = -0.5f * (c1 + std::sqrt(std::max(0.f, 12.f - 3.f * c1 * c1)));
  const float largest = q + p * c1, smallest = q + p * c3;
  return std::max(std::fabs(largest), std::fabs(smallest));
}

float LargestAbsEigenvalue(float a11, float a22, float a33, float a12, float a13, float a23)
{
  return LargestAbsEigenvalueInline(a11, a22, a33, a12, a13, a23);
}

void HessianFeatureMap(const float* f, const ImageGeometry& g, double gamma, double percentile,
  const ParallelFor& parallel, float* rho, double* featureMaximum)
{
  const std::int64_t n = g.Size();
  const int nx = g.Dims[0];
  const std::int64_t sy = nx, sz = g.SliceStride();
  const std::int64_t rows = static_cast<std::int64_t>(g.Dims[1]) * g.Dims[2];
  const bool is2D = g.Is2D();
  // Second differences need one voxel on each side: the border keeps rho = 0.
  parallel(rows, 16, [&, f, rho](std::int64_t r0, std::int64_t r1) {
    for (std::int64_t r = r0; r < r1; ++r)
    {
      const int j = static_cast<int>(r % g.Dims[1]);
      const int k = static_cast<int>(r / g.Dims[1]);
      float* const out = rho + g.Index(0, j, k);
      if (nx < 3 || j == 0 || j == g.Dims[1] - 1 || (!is2D && (k == 0 || k == g.Dims[2] - 1)))
      {
        std::fill(out, out + nx, 0.f);
        continue;
      }
      out[0] = out[nx - 1] = 0.f;
      const float* const c = f + g.Index(0, j, k);
      if (is2D)
      {
        for (int i = 1; i < nx - 1; ++i)
        {
          const float v2 = 2.f * c[i];
          const float hxx = c[i + 1] - v2 + c[i - 1];
          const float hyy = c[i + sy] - v2 + c[i - sy];
          const float hxy = 0.25f * (c[i + 1 + sy] - c[i + 1 - sy] - c[i - 1 + sy] + c[i - 1 - sy]);
          const float mean = 0.5f * (hxx + hyy);
          const float d = std::sqrt(0.25f * (hxx - hyy) * (hxx - hyy) + hxy * hxy);
          const float norm = std::fabs(mean) + d; // max(|mean+d|, |mean-d|)
          // NaN and infinities (overflowing differences) give 0, as a comparison that vectorises.
          out[i] = norm - norm == 0.f ? norm : 0.f;
        }
        continue;
      }
      for (int i = 1; i < nx - 1; ++i)
      {
        const float v2 = 2.f * c[i];
        const float hxx = c[i + 1] - v2 + c[i - 1];
        const float hyy = c[i + sy] - v2 + c[i - sy];
        const float hzz = c[i + sz] - v2 + c[i - sz];
        const float hxy = 0.25f * (c[i + 1 + sy] - c[i + 1 - sy] - c[i - 1 + sy] + c[i - 1 - sy]);
        const float hxz = 0.25f * (c[i + 1 + sz] - c[i + 1 - sz] - c[i - 1 + sz] + c[i - 1 - sz]);
        const float hyz = 0.25f * (c[i + sy + sz] - c[i + sy - sz] - c[i - sy + sz] + c[i - sy - sz]);
        const float norm = LargestAbsEigenvalueInline(hxx, hyy, hzz, hxy, hxz, hyz);
        out[i] = norm - norm == 0.f ? norm : 0.f;
      }
    }
  });
  const double a = RobustMaximum(rho, n, percentile, parallel);
  if (featureMaximum)
  {
    *featureMaximum = a;
  }
  if (a <= 0.0)
  {
    std::fill(rho, rho + n, 0.f);
    return;
  }
  const float inv = static_cast<float>(1.0 / a);
  const float gam = static_cast<float>(gamma);
  parallel(n, 65536, [&](std::int64_t b, std::int64_t e) {
    for (std::int64_t i = b; i < e; ++i)
    {
      const float v = std::min(1.f, rho[i] * inv);
      rho[i] = gam == 1.f ? v : std::pow(v, gam);
    }
  });
}

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

FeatureNodeResult ComputeFeatureNodes(const float* image, const std::uint8_t* edgeInput, const ImageGeometry& g,
  const FeatureNodeParameters& p, const ParallelFor& parallel, const ProgressFunction& progress)
{
  FeatureNodeResult out;
  const std::int64_t n = g.Size();
  const bool is2D = g.Is2D();
  // Two volume-sized buffers, each used twice: (Canny-scale image, gradient magnitude), then
  // (feature map, Hessian-scale image). A fresh 36 MB buffer costs ~20 ms of page faults here,
  // and default-initialised storage skips a needless zero fill.
  std::unique_ptr<float[]> bufferA(new float[n]), bufferB(new float[n]);
  float* f = bufferA.get();
  float* work = bufferB.get();
  auto t0 = Clock::now();
  GaussianSmooth(image, f, g, p.GaussianSigma, parallel);
  out.StepSeconds.emplace_back("gaussian", SecondsSince(t0));
  if (!progress(0.1))
  {
    out.Aborted = true;
    return out;
  }
  t0 = Clock::now();

  // 1. Edges: Canny, or the supplied edge map.
  if (edgeInput)
  {
    out.EdgeMap.assign(edgeInput, edgeInput + n);
    for (auto& v : out.EdgeMap)
    {
      v = v ? 1 : 0;
    }
  }
  else
  {
    out.EdgeMap = CannyEdges(f, g, p.LowThreshold, p.HighThreshold, p.MaximumPercentile, parallel,
      &out.GradientMaximum, work);
  }
  out.StepSeconds.emplace_back("canny", SecondsSince(t0));
  if (!progress(0.3))
  {
    out.Aborted = true;
    return out;
  }

  // 2. PCA-adaptive sampling of the edge points.
  t0 = Clock::now();
  std::vector<std::int64_t> edgePoints;
  {
    // Per-block lists joined in block order: the same voxel order whatever the thread count.
    const std::int64_t block = (n + ReductionBlocks - 1) / ReductionBlocks;
    std::vector<std::vector<std::int64_t>> found(ReductionBlocks);
    parallel(ReductionBlocks, 1, [&](std::int64_t b0, std::int64_t b1) {
      for (std::int64_t b = b0; b < b1; ++b)
      {
        for (std::int64_t i = b * block, e = std::min(n, (b + 1) * block); i < e; ++i)
        {
          if (out.EdgeMap[i])
          {
            found[b].push_back(i);
          }
        }
      }
    });
    std::size_t total = 0;
    for (const auto& f : found)
    {
      total += f.size();
    }
    edgePoints.reserve(total);
    for (const auto& f : found)
    {
      edgePoints.insert(edgePoints.end(), f.begin(), f.end());
    }
  }
  out.EdgeVoxels = static_cast<std::int64_t>(edgePoints.size());
  const std::vector<std::uint8_t> radii = EdgeSampleRadii(edgePoints, out.EdgeMap, g, p, parallel);
  out.StepSeconds.emplace_back("pca", SecondsSince(t0));
  t0 = Clock::now();
  const std::vector<std::int64_t> kept = ThinEdgePoints(edgePoints, radii, g);
  out.StepSeconds.emplace_back("thinning", SecondsSince(t0));
  if (!progress(0.5))
  {
    out.Aborted = true;
    return out;
  }

  // Node occupancy, one node per voxel: boundary nodes claim first, then Canny, halftone, uniform.
  std::vector<std::uint8_t> occupied(n, 0);
  auto add = [&](int i, int j, int k, NodeType type, float radius) {
    const std::int64_t idx = g.Index(i, j, k);
    if (occupied[idx])
    {
      return;
    }
    occupied[idx] = 1;
    out.Positions.push_back({ { i, j, k } });
    out.Type.push_back(type);
    out.Fixed.push_back(type == NodeType::Canny || type == NodeType::Boundary ? 1 : 0);
    out.SampleRadius.push_back(radius);
    out.Counts[static_cast<int>(type)]++;
  };

  // 3. Boundary nodes: corners always, evenly spaced along the border (2D) or on the box faces (3D).
  t0 = Clock::now();
  {
    const std::vector<int> px = EvenPositions(g.Dims[0], p.BoundarySpacing);
    const std::vector<int> py = EvenPositions(g.Dims[1], p.BoundarySpacing);
    const std::vector<int> pz = EvenPositions(g.Dims[2], p.BoundarySpacing);
    const float r = 0.5f * p.BoundarySpacing;
    const int lx = g.Dims[0] - 1, ly = g.Dims[1] - 1, lz = g.Dims[2] - 1;
    for (int k : pz)
    {
      for (int j : py)
      {
        for (int i : px)
        {
          const bool onFace = i == 0 || i == lx || j == 0 || j == ly || (!is2D && (k == 0 || k == lz));
          if (onFace)
          {
            add(i, j, k, NodeType::Boundary, r);
          }
        }
      }
    }
  }
  for (std::int64_t t : kept)
  {
    int i, j, k;
    Coordinates(g, edgePoints[t], i, j, k);
    add(i, j, k, NodeType::Canny, static_cast<float>(radii[t]));
  }
  out.StepSeconds.emplace_back("boundary", SecondsSince(t0));

  // 4. Halftoning points, away from edges.
  const int h = p.ExclusionWindow / 2;
  if (p.Halftoning)
  {
    t0 = Clock::now();
    const float* fh = f;
    float* rho = work;
    if (p.HessianSigma != p.GaussianSigma)
    {
      // The gradient magnitude and the Canny-scale image are spent: reuse both buffers.
      GaussianSmooth(image, work, g, p.HessianSigma, parallel);
      fh = work;
      rho = f;
    }
    HessianFeatureMap(fh, g, p.HalftoneGamma, p.FeaturePercentile, parallel, rho, &out.FeatureMaximum);
    out.StepSeconds.emplace_back("hessian", SecondsSince(t0));
    if (!progress(0.8))
    {
      out.Aborted = true;
      return out;
    }
    t0 = Clock::now();
    const std::vector<std::int64_t> dots = Halftone(rho, g, p.HalftoneThreshold);
    for (std::int64_t d : dots)
    {
      int i, j, k;
      Coordinates(g, d, i, j, k);
      if (!AnyInBox(out.EdgeMap, g, i, j, k, h))
      {
        add(i, j, k, NodeType::Halftone, static_cast<float>(h));
      }
    }
    out.StepSeconds.emplace_back("halftone", SecondsSince(t0));
  }

  // 5. Uniform lattice points where no edge voxel and no node lies within the window.
  t0 = Clock::now();
  {
    // Edge voxels count as occupied from here: no uniform point near them (and none lands on one,
    // as the window around a uniform point is free of them).
    for (std::int64_t i = 0; i < n; ++i)
    {
      occupied[i] |= out.EdgeMap[i];
    }
    const int s = p.UniformSpacing;
    const int start = s / 2;
    for (int k = is2D ? 0 : start; k < g.Dims[2]; k += s)
    {
      for (int j = start; j < g.Dims[1]; j += s)
      {
        for (int i = start; i < g.Dims[0]; i += s)
        {
          if (!AnyInBox(occupied, g, i, j, k, h))
          {
            add(i, j, k, NodeType::Uniform, 0.5f * s);
          }
        }
      }
    }
  }
  out.StepSeconds.emplace_back("uniform", SecondsSince(t0));
  progress(1.0);
  return out;
}
} // namespace featuremesh
