#include "Canny.h"
#include "Memory.h"

#include "ImagingInternals.h"

#include "ImageFilters.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace featuremesh
{
using namespace detail;
namespace
{
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
} // namespace

namespace
{
// Canny's two thresholds on the gradient magnitude, each raised to its noise floor, which grows
// near the border, where the noise's gradient varies more (Border: per axis, per index).
struct CannyThresholds
{
  float Low = 0.f, High = 0.f, LowFloor = 0.f, HighFloor = 0.f;
  bool Floored = false;
  std::array<std::vector<float>, 3> Border;
};

// Step 2: non-maximum suppression along the quantised gradient direction; ties resolved by ">" on
// one side and ">=" on the other, so a two-voxel plateau keeps exactly one voxel. `state`: 0 none,
// 1 weak candidate, 2 strong.
void SuppressNonMaxima(const float* f, const float* mag, const ImageGeometry& g, const CannyThresholds& t,
  const ParallelFor& parallel, std::vector<std::uint8_t>& state)
{
  const std::int64_t sy = g.Dims[0], sz = g.SliceStride();
  const std::int64_t rows = static_cast<std::int64_t>(g.Dims[1]) * g.Dims[2];
  const bool floored = t.Floored;
  const float lowValue = t.Low, highValue = t.High, lowFloorValue = t.LowFloor, highFloorValue = t.HighFloor;
  const auto& border = t.Border;
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
      const float rowFactor = floored ? border[1][j] * border[2][k] : 1.f;
      const float* const xFactor = floored ? border[0].data() : nullptr;
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
          const float factor = floored ? rowFactor * xFactor[i] : 1.f;
          const float lowAt = floored ? std::max(lowV, lowFloorValue * factor) : lowV;
          if (m < lowAt || m <= 0.f)
          {
            continue;
          }
          const float gx = 0.5f * (f[idx + 1] - f[idx - 1]);
          const float gy = 0.5f * (f[idx + sy] - f[idx - sy]);
          const float gz = 0.5f * (f[idx + szz] - f[idx - szz]); // 0 in 2D (szz = 0)
          const std::array<int, 3> d = QuantisedDirection(gx, gy, gz);
          const std::int64_t step = d[0] + d[1] * sy + d[2] * szz;
          const bool keep = (m > mag[idx + step]) & (m >= mag[idx - step]);
          const float highAt = floored ? std::max(highV, highFloorValue * factor) : highV;
          edgeState[idx] = static_cast<std::uint8_t>(keep * (1 + (m >= highAt)));
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
        const float factor = floored ? rowFactor * xFactor[i] : 1.f;
        const float lowAt = floored ? std::max(lowValue, lowFloorValue * factor) : lowValue;
        const float highAt = floored ? std::max(highValue, highFloorValue * factor) : highValue;
        if (m < lowAt || m <= 0.f)
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
          state[idx] = m >= highAt ? 2 : 1;
        }
      }
    }
  });
}

// Step 3: hysteresis: the strong voxels grown through connected candidates (visited ones marked 3,
// then the only edges). The result, the candidate components that hold a strong voxel, does not
// depend on visiting order.
void Hysteresis(const ImageGeometry& g, const ParallelFor& parallel, std::vector<std::uint8_t>& state)
{
  const std::int64_t n = g.Size(), sy = g.Dims[0], sz = g.SliceStride();
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
}
} // namespace

std::vector<std::uint8_t> CannyEdges(const float* f, const ImageGeometry& g, double low, double high, double percentile,
  const ParallelFor& parallel, double* gradientMaximum, float* magnitudeBuffer, double lowFloor, double highFloor,
  double smoothingSigma)
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
  std::vector<std::uint8_t> state; // 0 none, 1 weak candidate, 2 strong
  AssignFresh(state, n, std::uint8_t(0));
  if (gmax <= 0.0)
  {
    return state;
  }
  // 1. The thresholds: fractions of the robust maximum, each at least its noise floor.
  CannyThresholds t;
  t.Low = static_cast<float>(std::max(low * gmax, lowFloor));
  t.High = static_cast<float>(std::max(high * gmax, highFloor));
  t.Floored = lowFloor > 0.0 || highFloor > 0.0;
  for (int a = 0; a < 3 && t.Floored; ++a)
  {
    t.Border[a] = BorderNoiseFactors(g.Dims[a], smoothingSigma, { 0.5, 0.0, -0.5 });
  }
  t.LowFloor = static_cast<float>(lowFloor);
  t.HighFloor = static_cast<float>(highFloor);
  // 2-3. Thin, then connect.
  SuppressNonMaxima(f, mag, g, t, parallel, state);
  Hysteresis(g, parallel, state);

  return state;
}
} // namespace featuremesh
