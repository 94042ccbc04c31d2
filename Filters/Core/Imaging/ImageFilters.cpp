#include "ImageFilters.h"

#include "ImagingInternals.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace featuremesh
{
using namespace detail;
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

std::vector<float> GaussianKernel(double sigma)
{
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
  return w;
}

double EstimateNoiseSigma(const float* image, const ImageGeometry& g, const ParallelFor& parallel)
{
  const bool is2D = g.Is2D();
  const int bx = g.Dims[0] / 2, by = g.Dims[1] / 2, bz = is2D ? 1 : g.Dims[2] / 2;
  const std::int64_t blocks = static_cast<std::int64_t>(bx) * by * bz;
  if (blocks == 0)
  {
    return 0.0;
  }
  const std::int64_t sy = g.Dims[0], sz = g.SliceStride();
  std::vector<float> detail(static_cast<std::size_t>(blocks));
  const std::int64_t rows = static_cast<std::int64_t>(by) * bz;
  parallel(rows, 64, [&](std::int64_t r0, std::int64_t r1) {
    for (std::int64_t r = r0; r < r1; ++r)
    {
      const int j = static_cast<int>(r % by), k = static_cast<int>(r / by);
      const float* c = image + g.Index(0, 2 * j, is2D ? 0 : 2 * k);
      float* out = detail.data() + r * bx;
      for (int i = 0; i < bx; ++i, c += 2)
      {
        // Sums in double: the differences of large, nearly equal values stay exact enough.
        double d = (static_cast<double>(c[0]) - c[1]) - (static_cast<double>(c[sy]) - c[sy + 1]);
        if (!is2D)
        {
          d -= (static_cast<double>(c[sz]) - c[sz + 1]) - (static_cast<double>(c[sz + sy]) - c[sz + sy + 1]);
        }
        out[i] = static_cast<float>(std::fabs(d) / (is2D ? 2.0 : std::sqrt(8.0)));
      }
    }
  });
  auto middle = detail.begin() + blocks / 2;
  std::nth_element(detail.begin(), middle, detail.end());
  const double median = *middle;
  return std::isfinite(median) ? median / 0.6745 : 0.0;
}

double FilteredNoiseDeviation(int dimension, double sigma, const std::vector<double>& taps)
{
  std::vector<double> kernel(1, 1.0);
  if (sigma > 0.0)
  {
    const std::vector<float> w = GaussianKernel(sigma);
    kernel.assign(w.begin(), w.end());
  }
  double smooth = 0.0;
  for (const double w : kernel)
  {
    smooth += w * w;
  }
  std::vector<double> along(kernel.size() + taps.size() - 1, 0.0);
  for (std::size_t a = 0; a < kernel.size(); ++a)
  {
    for (std::size_t b = 0; b < taps.size(); ++b)
    {
      along[a + b] += kernel[a] * taps[b];
    }
  }
  double sum = 0.0;
  for (const double w : along)
  {
    sum += w * w;
  }
  return std::sqrt(sum * std::pow(smooth, dimension - 1));
}

std::vector<float> BorderNoiseFactors(int n, double sigma, const std::vector<double>& taps)
{
  std::vector<float> factor(static_cast<std::size_t>(std::max(0, n)), 1.f);
  if (n < 2)
  {
    return factor;
  }
  std::vector<double> kernel(1, 1.0);
  if (sigma > 0.0)
  {
    const std::vector<float> w = GaussianKernel(sigma);
    kernel.assign(w.begin(), w.end());
  }
  const int r = static_cast<int>(kernel.size() / 2), h = static_cast<int>(taps.size() / 2);
  // Row x of the smoothing (replicated border) as weights on the input voxels.
  auto smoothRow = [&](int x) {
    std::vector<double> row(static_cast<std::size_t>(n), 0.0);
    for (int t = -r; t <= r; ++t)
    {
      row[std::min(std::max(x + t, 0), n - 1)] += kernel[t + r];
    }
    return row;
  };
  auto deviation = [&](int x) {
    std::vector<double> row(static_cast<std::size_t>(n), 0.0);
    auto add = [&](int at, double w) {
      const std::vector<double> s = smoothRow(at);
      for (int v = 0; v < n; ++v)
      {
        row[v] += w * s[v];
      }
    };
    if (x - h < 0 || x + h > n - 1)
    {
      // The gradient's one-sided difference at the ends.
      add(std::min(x + 1, n - 1), 1.0);
      add(std::max(x - 1, 0), -1.0);
    }
    else
    {
      for (int t = -h; t <= h; ++t)
      {
        add(x + t, taps[t + h]);
      }
    }
    double sum = 0.0, smooth = 0.0;
    const std::vector<double> s = smoothRow(x);
    for (int v = 0; v < n; ++v)
    {
      sum += row[v] * row[v];
      smooth += s[v] * s[v];
    }
    return std::make_pair(std::sqrt(sum), std::sqrt(smooth));
  };
  const double along = FilteredNoiseDeviation(1, sigma, taps);
  double across = 0.0;
  for (const double w : kernel)
  {
    across += w * w;
  }
  across = std::sqrt(across);
  // Within r + h of an end the replicated border enters; beyond, the interior values hold.
  for (int x = 0; x < n; ++x)
  {
    const int e = std::min(x, n - 1 - x);
    if (e > r + h)
    {
      continue;
    }
    const auto d = deviation(x);
    factor[x] = static_cast<float>(std::max({ 1.0, d.first / along, d.second / across }));
  }
  return factor;
}

void GaussianSmooth(const float* in, float* out, const ImageGeometry& g, double sigma, const ParallelFor& parallel)
{
  const std::int64_t n = g.Size();
  if (sigma <= 0.0)
  {
    std::copy(in, in + n, out);
    return;
  }
  const std::vector<float> w = GaussianKernel(sigma);
  const int r = static_cast<int>(w.size() / 2);
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

void LocalContrast(const float* in, float* out, const ImageGeometry& g, double sigma, const ParallelFor& parallel)
{
  const std::int64_t n = g.Size();
  if (n == 0)
  {
    return;
  }
  // Sums over fixed chunks, added in order: the same eps on any number of threads.
  constexpr std::int64_t chunks = 64;
  const std::int64_t per = (n + chunks - 1) / chunks;
  std::vector<double> sum(chunks, 0.0), square(chunks, 0.0);
  parallel(chunks, 1, [&](std::int64_t c0, std::int64_t c1) {
    for (std::int64_t c = c0; c < c1; ++c)
    {
      for (std::int64_t v = c * per, end = std::min(n, v + per); v < end; ++v)
      {
        sum[c] += in[v];
      }
    }
  });
  double mean = 0.0;
  for (double s : sum)
  {
    mean += s;
  }
  mean /= static_cast<double>(n);
  parallel(chunks, 1, [&](std::int64_t c0, std::int64_t c1) {
    for (std::int64_t c = c0; c < c1; ++c)
    {
      for (std::int64_t v = c * per, end = std::min(n, v + per); v < end; ++v)
      {
        square[c] += (in[v] - mean) * (in[v] - mean);
      }
    }
  });
  double variance = 0.0;
  for (double s : square)
  {
    variance += s;
  }
  const float eps = std::max(std::numeric_limits<float>::min(), static_cast<float>(1e-3 * std::sqrt(variance / static_cast<double>(n))));
  std::vector<float> local(n), spread(n);
  GaussianSmooth(in, local.data(), g, sigma, parallel);
  parallel(n, 65536, [&](std::int64_t b, std::int64_t e) {
    for (std::int64_t v = b; v < e; ++v)
    {
      out[v] = in[v] - local[v];
      local[v] = out[v] * out[v];
    }
  });
  GaussianSmooth(local.data(), spread.data(), g, sigma, parallel);
  parallel(n, 65536, [&](std::int64_t b, std::int64_t e) {
    for (std::int64_t v = b; v < e; ++v)
    {
      out[v] /= std::sqrt(spread[v]) + eps;
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

inline float LargestAbsEigenvalueInline(float a11, float a22, float a33, float a12, float a13, float a23)
{
  // Trigonometric solution of the characteristic cubic (Smith 1961) without trigonometry: for
  // C = (A - qI)/p the roots are 2cos((acos r)/3 + 2k pi/3), r = det(C)/2. The largest,
  // 2cos(2 acos(u)/3) with u = sqrt((1+r)/2), is smooth in u on [0,1]: a degree-8 polynomial
  // (Chebyshev fit, error 9e-9) replaces acos and cos, and the smallest root follows from
  // c2 + c3 = -c1, c2 c3 = c1^2 - 3. Branch-free, so a row of voxels vectorises; it replaced
  // Eigen's computeDirect (atan2, sincos).
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
  const ParallelFor& parallel, float* rho, double* featureMaximum, double floor, double smoothingSigma)
{
  const std::int64_t n = g.Size();
  const int nx = g.Dims[0];
  const std::int64_t sy = nx, sz = g.SliceStride();
  const std::int64_t rows = static_cast<std::int64_t>(g.Dims[1]) * g.Dims[2];
  const bool is2D = g.Is2D();
  // The floor at each voxel: `floor` times the border factors of its row and column (0 without one).
  std::array<std::vector<float>, 3> border;
  for (int a = 0; a < 3; ++a)
  {
    border[a] = floor > 0.0 ? BorderNoiseFactors(g.Dims[a], smoothingSigma, { 1.0, -2.0, 1.0 })
                            : std::vector<float>(static_cast<std::size_t>(g.Dims[a]), 1.f);
  }
  const float cut = static_cast<float>(std::max(0.0, floor));
  // Second differences need one voxel on each side: the border keeps rho = 0.
  parallel(rows, 16, [&, f, rho](std::int64_t r0, std::int64_t r1) {
    for (std::int64_t r = r0; r < r1; ++r)
    {
      const int j = static_cast<int>(r % g.Dims[1]);
      const int k = static_cast<int>(r / g.Dims[1]);
      float* const out = rho + g.Index(0, j, k);
      const float rowCut = cut * border[1][j] * border[2][k];
      const float* const xFactor = border[0].data();
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
          // NaN and infinities (overflowing differences) give 0, as a comparison that vectorises;
          // so does a norm below the floor.
          out[i] = norm - norm == 0.f && !(norm < rowCut * xFactor[i]) ? norm : 0.f;
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
        out[i] = norm - norm == 0.f && !(norm < rowCut * xFactor[i]) ? norm : 0.f;
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

namespace
{
// Squared distance transform of one line: d[q] = min_p (q - p)^2 + f[p] (f = Far where unset).
void LowerEnvelope(const double* f, int n, double* d, int* v, double* z)
{
  int k = 0;
  v[0] = 0;
  z[0] = -std::numeric_limits<double>::infinity();
  z[1] = std::numeric_limits<double>::infinity();
  for (int q = 1; q < n; ++q)
  {
    double s;
    for (;;)
    {
      const int r = v[k];
      s = ((f[q] + double(q) * q) - (f[r] + double(r) * r)) / (2.0 * (q - r));
      if (s > z[k])
      {
        break;
      }
      --k; // z[0] = -inf ends this
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = std::numeric_limits<double>::infinity();
  }
  k = 0;
  for (int q = 0; q < n; ++q)
  {
    while (z[k + 1] < q)
    {
      ++k;
    }
    d[q] = double(q - v[k]) * (q - v[k]) + f[v[k]];
  }
}
} // namespace

std::vector<float> DistanceToMask(const std::uint8_t* mask, const ImageGeometry& g, const ParallelFor& parallel)
{
  const std::int64_t n = g.Size();
  // Far: larger than any squared distance in an image, small enough that differences of squares
  // next to it stay exact to 1e-4.
  constexpr double Far = 1e12;
  std::vector<double> sq(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i)
  {
    sq[i] = mask[i] ? 0.0 : Far;
  }
  const std::int64_t stride[3] = { 1, g.Dims[0], g.SliceStride() };
  for (int a = 0; a < g.Dimension(); ++a)
  {
    const int len = g.Dims[a];
    const int b = a == 0 ? 1 : 0, c = a == 2 ? 1 : 2;
    const std::int64_t lines = static_cast<std::int64_t>(g.Dims[b]) * g.Dims[c];
    parallel(lines, 64, [&](std::int64_t l0, std::int64_t l1) {
      std::vector<double> f(len), d(len), z(len + 1);
      std::vector<int> v(len);
      for (std::int64_t l = l0; l < l1; ++l)
      {
        const std::int64_t base = (l % g.Dims[b]) * stride[b] + (l / g.Dims[b]) * stride[c];
        for (int q = 0; q < len; ++q)
        {
          f[q] = sq[base + q * stride[a]];
        }
        LowerEnvelope(f.data(), len, d.data(), v.data(), z.data());
        for (int q = 0; q < len; ++q)
        {
          sq[base + q * stride[a]] = std::min(d[q], Far);
        }
      }
    });
  }
  std::vector<float> out(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i)
  {
    out[i] = sq[i] >= 0.5 * Far ? std::numeric_limits<float>::infinity() : static_cast<float>(std::sqrt(sq[i]));
  }
  return out;
}
} // namespace featuremesh
