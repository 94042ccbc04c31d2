#include "SeedReach.h"
#include "SimplexMesh.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_set>

namespace featuremesh
{
namespace
{
using Point = std::array<double, 3>;

double Distance2(const Point& a, const Point& b)
{
  return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
}

// One seed per cell of edge `cell`, the first in seed order: the nearest kept seed then lies within
// half a cell's diagonal of the nearest seed, and a brushed region of thousands of seeds costs as
// few as the cells it covers.
std::vector<Point> ThinSeeds(const std::vector<Point>& seeds, double cell)
{
  std::unordered_set<std::uint64_t> used;
  std::vector<Point> kept;
  for (const Point& s : seeds)
  {
    std::uint64_t key = 0;
    for (int a = 0; a < 3; ++a)
    {
      key = key * 2097152u + (static_cast<std::uint64_t>(std::floor(s[a] / cell) + 1048576.0) & 2097151u);
    }
    if (used.insert(key).second)
    {
      kept.push_back(s);
    }
  }
  return kept;
}
} // namespace

std::string ValidateParameters(const SeedReachParameters& p)
{
  if (!(p.Weight >= 0.0 && p.Weight <= 1e3))
  {
    return "the seed reach weight must lie in [0, 1000].";
  }
  if (!(p.Reach >= 0.0 && p.Reach <= 1e3))
  {
    return "the seed reach must lie in [0, 1000] (units of the largest distance from an object seed to the nearest background seed).";
  }
  return std::string();
}

Point NodeCentres::operator()(std::int64_t p) const
{
  if (!this->Centre.empty())
  {
    return this->Centre[p];
  }
  const auto ijk = this->Geometry.Coordinates(p);
  return this->Geometry.IndexToFrame({ { double(ijk[0]), double(ijk[1]), double(ijk[2]) } });
}

NodeCentres ElementCentres(const SimplexMesh& mesh)
{
  NodeCentres c;
  c.Geometry = mesh.Geometry();
  const std::int64_t m = mesh.NumberOfElements();
  const int k = mesh.VerticesPerCell();
  std::vector<Point> centre(m, Point{ { 0.0, 0.0, 0.0 } });
  for (std::int64_t e = 0; e < m; ++e)
  {
    for (int v = 0; v < k; ++v)
    {
      const Point q = mesh.FramePoint(mesh.Cell(e)[v]);
      for (int a = 0; a < 3; ++a)
      {
        centre[e][a] += q[a] / k;
      }
    }
  }
  c.Centre = SharedArray<Point>(std::move(centre));
  return c;
}

NodeCentres VoxelCentres(const ImageGeometry& g)
{
  NodeCentres c;
  c.Geometry = g;
  return c;
}

bool SeedReachCosts(const NodeCentres& nodes, const std::vector<std::int64_t>& seedVoxels,
  const std::vector<std::uint8_t>& seedLabels, int labels, const SeedReachParameters& p, const ParallelFor& parallel,
  std::vector<double>& cost, std::vector<double>* reach)
{
  cost.clear();
  if (reach)
  {
    reach->assign(labels, 0.0);
  }
  if (!(p.Weight > 0.0) || labels < 2)
  {
    return false;
  }
  const NodeCentres voxels = VoxelCentres(nodes.Geometry);
  std::vector<std::vector<Point>> seeds(labels);
  for (std::size_t s = 0; s < seedVoxels.size(); ++s)
  {
    if (seedLabels[s] < labels)
    {
      seeds[seedLabels[s]].push_back(voxels(seedVoxels[s]));
    }
  }
  // R per label, and its seeds thinned to cells of R / 8. Only the background seeds bound an object:
  // another object's may lie inside it (a tumour's core in its oedema).
  std::vector<double> R(labels, 0.0);
  std::vector<std::vector<Point>> near(labels);
  for (int l = 1; l < labels; ++l)
  {
    for (const Point& s : seeds[l])
    {
      double nearest = std::numeric_limits<double>::infinity();
      for (const Point& t : seeds[0])
      {
        nearest = std::min(nearest, Distance2(s, t));
      }
      if (std::isfinite(nearest))
      {
        R[l] = std::max(R[l], std::sqrt(nearest));
      }
    }
    if (R[l] > 0.0)
    {
      near[l] = ThinSeeds(seeds[l], R[l] / 8.0);
    }
  }
  if (reach)
  {
    *reach = R;
  }
  if (std::all_of(R.begin(), R.end(), [](double r) { return r == 0.0; }))
  {
    return false;
  }
  const std::int64_t n = nodes.Size();
  const int objects = labels - 1;
  cost.resize(static_cast<std::size_t>(n) * objects);
  // Seeds outer, nodes inner, over blocks of nodes held as coordinate rows: the inner loop
  // vectorises (most nodes lie beyond the reach of every seed, so every seed is visited).
  constexpr std::int64_t Block = 512;
  parallel(n, 16384, [&](std::int64_t p0, std::int64_t p1) {
    std::array<std::array<double, Block>, 3> x;
    std::array<double, Block> d2, beyond;
    for (std::int64_t b = p0; b < p1; b += Block)
    {
      const std::int64_t m = std::min(Block, p1 - b);
      const Point* centre = nodes.Centre.empty() ? nullptr : nodes.Centre.data() + b;
      for (std::int64_t i = 0; i < m; ++i)
      {
        const Point c = centre ? centre[i] : nodes(b + i);
        x[0][i] = c[0];
        x[1][i] = c[1];
        x[2][i] = c[2];
      }
      for (int l = 1; l < labels; ++l)
      {
        if (!(R[l] > 0.0))
        {
          for (std::int64_t i = 0; i < m; ++i)
          {
            cost[(b + i) * objects + l - 1] = 0.0;
          }
          continue;
        }
        const double free2 = (p.Reach * R[l]) * (p.Reach * R[l]);
        std::fill(d2.begin(), d2.begin() + m, std::numeric_limits<double>::infinity());
        for (const Point& s : near[l])
        {
          for (std::int64_t i = 0; i < m; ++i)
          {
            const double d = (x[0][i] - s[0]) * (x[0][i] - s[0]) + (x[1][i] - s[1]) * (x[1][i] - s[1]) +
              (x[2][i] - s[2]) * (x[2][i] - s[2]);
            d2[i] = std::min(d2[i], d);
          }
        }
        // Every node's term in vector registers (std::sqrt's errno keeps GCC's loop scalar), then kept
        // beyond the reach only.
        const Eigen::Map<const Eigen::ArrayXd> d(d2.data(), m);
        Eigen::Map<Eigen::ArrayXd>(beyond.data(), m) =
          (d > free2).select(p.Weight * (d.sqrt() / R[l] - p.Reach), 0.0);
        for (std::int64_t i = 0; i < m; ++i)
        {
          cost[(b + i) * objects + l - 1] = beyond[i];
        }
      }
    }
  });
  return true;
}
} // namespace featuremesh
