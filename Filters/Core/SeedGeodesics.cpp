#include "SeedGeodesics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <utility>

namespace featuremesh
{
namespace
{
// Pops between progress checks.
constexpr std::int64_t CheckEvery = (std::int64_t(1) << 16) - 1;

// Neighbours of a node with the edge's step length: explicit edges as CSR (built in two passes,
// count then insert), the grid's from the index.
class Adjacency
{
public:
  explicit Adjacency(const GeodesicGraph& g)
    : Graph(g)
  {
    const GraphEdges& edges = *g.Edges;
    if (edges.IsGrid())
    {
      const auto& d = edges.GridDims();
      this->Dims = { { d[0], d[1], d[2] } };
      return;
    }
    const std::int64_t m = edges.Size();
    this->Offset.assign(g.Nodes + 1, 0);
    for (std::int64_t e = 0; e < m; ++e)
    {
      ++this->Offset[edges.First()[e] + 1];
      ++this->Offset[edges.Second()[e] + 1];
    }
    for (std::int64_t p = 0; p < g.Nodes; ++p)
    {
      this->Offset[p + 1] += this->Offset[p];
    }
    this->Neighbour.resize(2 * m);
    this->Edge.resize(2 * m);
    std::vector<std::int64_t> next(this->Offset.begin(), this->Offset.end() - 1);
    for (std::int64_t e = 0; e < m; ++e)
    {
      const std::int64_t a = edges.First()[e], b = edges.Second()[e];
      this->Neighbour[next[a]] = b;
      this->Edge[next[a]++] = e;
      this->Neighbour[next[b]] = a;
      this->Edge[next[b]++] = e;
    }
  }

  // f(q, step) for every neighbour q of p.
  template <typename F>
  void ForEach(std::int64_t p, F&& f) const
  {
    if (this->Offset.empty())
    {
      const std::int64_t nx = this->Dims[0], ny = this->Dims[1], nxy = nx * ny;
      const std::int64_t i = p % nx, j = (p / nx) % ny, k = p / nxy;
      if (i > 0) f(p - 1, 1.0);
      if (i + 1 < nx) f(p + 1, 1.0);
      if (j > 0) f(p - nx, 1.0);
      if (j + 1 < ny) f(p + nx, 1.0);
      if (k > 0) f(p - nxy, 1.0);
      if (k + 1 < this->Dims[2]) f(p + nxy, 1.0);
      return;
    }
    for (std::int64_t s = this->Offset[p]; s < this->Offset[p + 1]; ++s)
    {
      f(this->Neighbour[s], !this->Graph.Step || this->Graph.Step->empty() ? 1.0 : (*this->Graph.Step)[this->Edge[s]]);
    }
  }

private:
  const GeodesicGraph& Graph;
  std::array<std::int64_t, 3> Dims{ { 0, 0, 0 } };
  std::vector<std::int64_t> Offset, Neighbour, Edge;
};

std::vector<double> Distances(const GeodesicGraph& g, const Adjacency& adjacency, const std::vector<std::uint8_t>& hard,
  std::uint8_t seedKind, double scale, double lengthWeight, const ProgressFunction& progress)
{
  const std::int64_t n = g.Nodes;
  std::vector<double> distance(n, std::numeric_limits<double>::infinity());
  using Entry = std::pair<double, std::int64_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap;
  for (std::int64_t p = 0; p < n; ++p)
  {
    if (hard[p] == seedKind)
    {
      distance[p] = 0.0;
      heap.emplace(0.0, p);
    }
  }
  const double inverse = 1.0 / scale;
  std::int64_t popped = 0;
  while (!heap.empty())
  {
    const auto [d, p] = heap.top();
    heap.pop();
    if (d > distance[p])
    {
      continue;
    }
    if ((++popped & CheckEvery) == 0 && !progress(std::min(1.0, static_cast<double>(popped) / static_cast<double>(n))))
    {
      return {};
    }
    const double value = g.Value[p];
    adjacency.ForEach(p, [&](std::int64_t q, double step) {
      const double candidate = d + std::fabs(g.Value[q] - value) * inverse + lengthWeight * step;
      if (candidate < distance[q])
      {
        distance[q] = candidate;
        heap.emplace(candidate, q);
      }
    });
  }
  return distance;
}
} // namespace

std::string ValidateParameters(const SeedGeodesicParameters& p)
{
  if (!(p.Weight >= 0.0 && p.Weight <= 1e3))
  {
    return "the geodesic weight must lie in [0, 1000].";
  }
  if (!(p.LengthWeight >= 0.0 && p.LengthWeight <= 1e3))
  {
    return "the geodesic length weight must lie in [0, 1000].";
  }
  return std::string();
}

std::vector<double> GeodesicDistances(const GeodesicGraph& graph, const std::vector<std::uint8_t>& hard,
  std::uint8_t seedKind, double scale, double lengthWeight, const ProgressFunction& progress)
{
  const Adjacency adjacency(graph);
  return Distances(graph, adjacency, hard, seedKind, scale, lengthWeight, progress);
}

bool SeedGeodesicCosts(const GeodesicGraph& graph, const std::vector<std::uint8_t>& hard, double scale,
  const SeedGeodesicParameters& par, const ParallelFor& parallel, std::vector<double>& costObject,
  std::vector<double>& costBackground, const ProgressFunction& progress)
{
  costObject.clear();
  costBackground.clear();
  const bool both = std::find(hard.begin(), hard.end(), 1) != hard.end() && std::find(hard.begin(), hard.end(), 2) != hard.end();
  if (par.Weight <= 0.0 || !both || graph.Nodes == 0)
  {
    return true;
  }
  if (!(scale > 0.0) || !std::isfinite(scale))
  {
    scale = 1.0;
  }
  const Adjacency adjacency(graph);
  const std::vector<double> toObject = Distances(graph, adjacency, hard, 1, scale, par.LengthWeight, SubProgress(progress, 0.0, 0.45));
  if (toObject.empty())
  {
    return false;
  }
  const std::vector<double> toBackground = Distances(graph, adjacency, hard, 2, scale, par.LengthWeight, SubProgress(progress, 0.45, 0.9));
  if (toBackground.empty())
  {
    return false;
  }
  constexpr double mix = 0.01;
  costObject.resize(graph.Nodes);
  costBackground.resize(graph.Nodes);
  parallel(graph.Nodes, 65536, [&](std::int64_t p0, std::int64_t p1) {
    for (std::int64_t p = p0; p < p1; ++p)
    {
      const double dO = toObject[p], dB = toBackground[p];
      // Unreachable from both (a separate component): no preference.
      double object = 0.5;
      if (std::isfinite(dO) || std::isfinite(dB))
      {
        object = !std::isfinite(dB) ? 1.0 : (!std::isfinite(dO) ? 0.0 : (dO + dB > 0.0 ? dB / (dO + dB) : 0.5));
      }
      costObject[p] = -par.Weight * std::log(mix + (1.0 - 2.0 * mix) * object);
      costBackground[p] = -par.Weight * std::log(mix + (1.0 - 2.0 * mix) * (1.0 - object));
    }
  });
  return progress(1.0);
}
} // namespace featuremesh
