#include "EdgeSampling.h"

#include "ImagingInternals.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <vector>

namespace featuremesh
{
using namespace detail;
namespace
{
// Eight bytes that are each 0 or 1, packed into 8 bits (byte b -> bit b); the multiply cannot carry.
inline std::uint64_t PackBytes(const std::uint8_t* p)
{
  std::uint64_t x;
  std::memcpy(&x, p, 8);
  return (x * 0x0102040810204080ULL) >> 56;
}
} // namespace

std::uint8_t SamplingRadius(std::int64_t count, const std::int64_t moments[9], int dimension, const FeatureNodeParameters& p)
{
  const std::int64_t s0 = moments[0], s1 = moments[1], s2 = moments[2], q0 = moments[3], q1 = moments[4],
                     q2 = moments[5], q3 = moments[6], q4 = moments[7], q5 = moments[8];
  const std::array<int, 3>& radii = dimension == 2 ? p.Radii2D : p.Radii3D;
  int cls = 2; // curved, corner or speck: densest sampling
  if (count > dimension)
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
    if (dimension == 2)
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
  return static_cast<std::uint8_t>(radii[cls]);
}

std::vector<std::uint8_t> EdgeSampleRadii(const std::vector<std::int64_t>& pts,
  const std::vector<std::uint8_t>& edgeMap, const ImageGeometry& g, const FeatureNodeParameters& p,
  const ParallelFor& parallel)
{
  const bool is2D = g.Is2D();
  const int window = p.CovarianceNeighbourhood > 0 ? p.CovarianceNeighbourhood : (is2D ? 11 : 5);
  const int h = window / 2;
  const int width = 2 * h + 1;
  // Each row of the box is read as a bit pattern whose count and first and second x-moments come
  // from a table: one lookup per row instead of a branch per voxel. Integer
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
      const std::int64_t moments[9] = { s0, s1, s2, q0, q1, q2, q3, q4, q5 };
      result[t] = SamplingRadius(count, moments, g.Dimension(), p);
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

  // Radii are in voxels of the median axis: along an axis thinner than the other two, |d| voxels
  // count as ceil(|d| / m) (ImageGeometry::MedianVoxelFactors), so that kept points are not denser
  // across thin slices, which left flat tetrahedra stage 3 could not mend (docs/smoothing.md).
  const std::array<int, 3> m = g.MedianVoxelFactors();

  // Small radii (all the defaults): a map of the Chebyshev distance to the nearest kept point,
  // capped past the largest radius, stamped around each kept point. A point is blocked exactly when
  // that distance is at most its radius: one lookup per query.
  const int largest = radii.empty() ? 0 : *std::max_element(radii.begin(), radii.end());
  constexpr int maxStampRadius = 8;
  if (largest <= maxStampRadius)
  {
    const std::uint8_t far = static_cast<std::uint8_t>(largest + 1);
    std::vector<std::uint8_t> distance(static_cast<std::size_t>(g.Size()), far);
    std::vector<std::int64_t> kept;
    const int ir = largest * m[0], jr = largest * m[1], kr = g.Is2D() ? 0 : largest * m[2];
    // Each axis's offsets -r..r as distances: the stamp's inner loop looks them up.
    auto distances = [&m](int a, int r) {
      std::vector<int> d(2 * r + 1);
      for (int o = -r; o <= r; ++o)
      {
        d[o + r] = (std::abs(o) + m[a] - 1) / m[a];
      }
      return d;
    };
    const std::vector<int> alongI = distances(0, ir), alongJ = distances(1, jr), alongK = distances(2, kr);
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
        for (int dj = std::max(-jr, -j); dj <= std::min(jr, g.Dims[1] - 1 - j); ++dj)
        {
          std::uint8_t* row = distance.data() + g.Index(0, j + dj, k + dk);
          const int dkj = std::max(alongK[dk + kr], alongJ[dj + jr]);
          for (int di = std::max(-ir, -i); di <= std::min(ir, g.Dims[0] - 1 - i); ++di)
          {
            const std::uint8_t d = static_cast<std::uint8_t>(std::max(dkj, alongI[di + ir]));
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
    const int ri = radii[t] * m[0], rj = radii[t] * m[1], rk = radii[t] * m[2];
    bool blocked = false;
    for (int bz = std::max(0, (k - rk) / cell); !blocked && bz <= std::min(cz - 1, (k + rk) / cell); ++bz)
    {
      for (int by = std::max(0, (j - rj) / cell); !blocked && by <= std::min(cy - 1, (j + rj) / cell); ++by)
      {
        for (int bx = std::max(0, (i - ri) / cell); !blocked && bx <= std::min(cx - 1, (i + ri) / cell); ++bx)
        {
          for (std::int64_t q = head[(static_cast<size_t>(bz) * cy + by) * cx + bx]; q >= 0; q = next[q])
          {
            const auto& o = keptPos[q];
            if (std::abs(o[0] - i) <= ri && std::abs(o[1] - j) <= rj && std::abs(o[2] - k) <= rk)
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
} // namespace featuremesh
