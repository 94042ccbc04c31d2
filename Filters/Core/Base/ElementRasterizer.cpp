#include "ElementRasterizer.h"
#include "Vector3.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace featuremesh
{
ElementRasterizer::ElementRasterizer(const SimplexMesh& mesh)
  : M(&mesh)
{
  for (int a = 0; a < 3; ++a)
  {
    this->TwiceCentre[a] = mesh.Geometry().Dims[a] - 1.0;
  }
  // Normals of faces between lattice nodes are integers below 2 * 4096^2, plane offsets below
  // 3 * 2^37, row values below 2^41: all exact in double.
  const auto& d = mesh.Geometry().Dims;
  this->ExactBounds = d[0] < 4096 && d[1] < 4096 && d[2] < 4096;
  if (mesh.InSpatialOrder())
  {
    this->Order.resize(static_cast<std::size_t>(mesh.NumberOfElements()));
    std::iota(this->Order.begin(), this->Order.end(), std::int64_t(0));
  }
  else
  {
    this->Order = SpatialElementOrder(mesh);
  }
}

template <typename T>
double InterpolateAt(const T* values, const ImageGeometry& g, const double index[3])
{
  int base[3];
  double w[3][2];
  std::int64_t step[3];
  const std::int64_t stride[3] = { 1, g.Dims[0], g.SliceStride() };
  for (int a = 0; a < 3; ++a)
  {
    const double c = std::min(std::max(index[a], 0.0), static_cast<double>(g.Dims[a] - 1));
    base[a] = std::min(static_cast<int>(std::floor(c)), std::max(0, g.Dims[a] - 2));
    const double t = g.Dims[a] > 1 ? c - base[a] : 0.0;
    w[a][0] = 1.0 - t;
    // A one-voxel axis has no upper neighbour: weight 0.
    w[a][1] = g.Dims[a] > 1 ? t : 0.0;
    step[a] = g.Dims[a] > 1 ? stride[a] : 0;
  }
  const T* origin = values + g.Index(base[0], base[1], base[2]);
  // Corners in bit order (x fastest), each weight the product in axis order, zero weights skipped.
  double result = 0.0;
  for (int corner = 0; corner < 8; ++corner)
  {
    const int bx = corner & 1, by = (corner >> 1) & 1, bz = (corner >> 2) & 1;
    const double weight = w[0][bx] * w[1][by] * w[2][bz];
    if (weight != 0.0)
    {
      result += weight * origin[bx * step[0] + by * step[1] + bz * step[2]];
    }
  }
  return result;
}

template <typename T>
ElementStatistics ComputeElementStatistics(const ElementRasterizer& raster, const T* values,
  const ParallelFor& parallel, const ProgressFunction& progress, std::int32_t* owner)
{
  const SimplexMesh& mesh = raster.Mesh();
  const auto& P = mesh.Points();
  const int vpc = mesh.VerticesPerCell();
  const std::int64_t m = raster.NumberOfElements();
  ElementStatistics s;
  s.PixelCount.assign(m, 0);
  s.Mean.assign(m, 0.0);
  s.StdDev.assign(m, 0.0);
  s.Interpolated.assign(m, 0);
  if (owner)
  {
    std::fill(owner, owner + mesh.Geometry().Size(), -1);
  }
  const std::vector<std::int64_t>& order = raster.SpatialOrder();
  s.Aborted = !BatchedFor(m, 512, parallel, progress, [&](std::int64_t b, std::int64_t e) {
    for (std::int64_t i = b; i < e; ++i)
    {
      const std::int64_t c = order[i];
      // One pass with sums shifted by the element's first value: no cancellation for large,
      // nearly constant elements, and half the memory traffic of a two-pass variance.
      std::int64_t count = 0;
      double shift = 0.0, sum = 0.0, ss = 0.0;
      raster.ForEachSpan(c, [&](std::int64_t first, std::int64_t n) {
        if (owner)
        {
          std::fill_n(owner + first, n, static_cast<std::int32_t>(c));
        }
        if (count == 0)
        {
          shift = static_cast<double>(values[first]);
        }
        count += n;
        for (const T* v = values + first; v != values + first + n; ++v)
        {
          const double d = static_cast<double>(*v) - shift;
          sum += d;
          ss += d * d;
        }
      });
      if (count == 0)
      {
        double centroid[3] = { 0, 0, 0 };
        for (int v = 0; v < vpc; ++v)
        {
          for (int a = 0; a < 3; ++a)
          {
            centroid[a] += P[mesh.Cell(c)[v]][a] / vpc;
          }
        }
        s.Mean[c] = InterpolateAt(values, mesh.Geometry(), centroid);
        s.Interpolated[c] = 1;
        continue;
      }
      const double meanShifted = sum / static_cast<double>(count);
      const double mean = shift + meanShifted;
      ss = std::max(0.0, ss / static_cast<double>(count) - meanShifted * meanShifted);
      s.PixelCount[c] = count;
      s.Mean[c] = mean;
      s.StdDev[c] = std::sqrt(ss);
    }
  });
  return s;
}

// Every type an image's values come in (vtkTemplateMacro's list).
#define FEATUREMESH_INSTANTIATE(T)                                                                   \
  template double InterpolateAt<T>(const T*, const ImageGeometry&, const double[3]);                \
  template ElementStatistics ComputeElementStatistics<T>(                                            \
    const ElementRasterizer&, const T*, const ParallelFor&, const ProgressFunction&, std::int32_t*);
FEATUREMESH_INSTANTIATE(double)
FEATUREMESH_INSTANTIATE(float)
FEATUREMESH_INSTANTIATE(long long)
FEATUREMESH_INSTANTIATE(unsigned long long)
FEATUREMESH_INSTANTIATE(long)
FEATUREMESH_INSTANTIATE(unsigned long)
FEATUREMESH_INSTANTIATE(int)
FEATUREMESH_INSTANTIATE(unsigned int)
FEATUREMESH_INSTANTIATE(short)
FEATUREMESH_INSTANTIATE(unsigned short)
FEATUREMESH_INSTANTIATE(char)
FEATUREMESH_INSTANTIATE(signed char)
FEATUREMESH_INSTANTIATE(unsigned char)
#undef FEATUREMESH_INSTANTIATE

std::vector<std::int32_t> VoxelOwners(const ElementRasterizer& raster, const ParallelFor& parallel,
  const ProgressFunction& progress)
{
  std::vector<std::int32_t> owner(raster.Mesh().Geometry().Size(), -1);
  // Each centre has exactly one owner, so the writes never collide.
  const std::vector<std::int64_t>& order = raster.SpatialOrder();
  const bool done = BatchedFor(raster.NumberOfElements(), 512, parallel, progress, [&](std::int64_t b, std::int64_t e) {
    for (std::int64_t i = b; i < e; ++i)
    {
      const std::int64_t c = order[i];
      raster.ForEachSpan(c, [&](std::int64_t first, std::int64_t n) {
        std::fill_n(owner.begin() + first, n, static_cast<std::int32_t>(c));
      });
    }
  });
  if (!done)
  {
    owner.clear();
  }
  return owner; // not a conditional expression, which would copy the map
}
} // namespace featuremesh
