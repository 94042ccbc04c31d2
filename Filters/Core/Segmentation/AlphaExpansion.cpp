#include "AlphaExpansion.h"

#include <maxflow.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

namespace featuremesh
{
namespace
{
using Flow = maxflow::Graph_DDD;

// libmaxflow calls this before exit(1) when an allocation fails: throwing keeps the host alive.
void ThrowOutOfMemory(const char* what)
{
  throw std::runtime_error(std::string("max-flow: ") + what);
}

std::string Validate(const PottsProblem& pr)
{
  if (pr.Labels < 2 || pr.Labels > 256)
  {
    return "alpha-expansion needs 2 to 256 labels.";
  }
  if (pr.Nodes <= 0 || !pr.Edges)
  {
    return "the graph is empty.";
  }
  if (pr.Nodes > 2000000000 || 2 * pr.Edges->Size() > 2000000000)
  {
    return "the graph is too large for the max-flow library (node ids are 32-bit).";
  }
  if (static_cast<std::int64_t>(pr.Cost.size()) != pr.Nodes * pr.Labels ||
    static_cast<std::int64_t>(pr.Weight.size()) != pr.Edges->Size() ||
    (!pr.Hard.empty() && static_cast<std::int64_t>(pr.Hard.size()) != pr.Nodes))
  {
    return "the costs, weights or hard labels do not match the graph.";
  }
  for (double c : pr.Cost)
  {
    if (!std::isfinite(c) || std::fabs(c) > 1e150)
    {
      return "a label cost is not finite; check the image for NaN or infinite values.";
    }
  }
  for (double w : pr.Weight)
  {
    if (!(w >= 0.0 && w <= 1e150))
    {
      return "a boundary weight is negative or not finite.";
    }
  }
  for (std::int16_t h : pr.Hard)
  {
    if (h < -1 || h >= pr.Labels)
    {
      return "a hard label lies outside [0, labels).";
    }
  }
  bool bad = false;
  pr.Edges->ForEach([&](std::int64_t, std::int64_t a, std::int64_t b) {
    bad = bad || a < 0 || b < 0 || a >= pr.Nodes || b >= pr.Nodes;
  });
  return bad ? "an edge names a node outside the graph." : std::string();
}
} // namespace

double PottsEnergy(const PottsProblem& pr, const std::vector<std::uint8_t>& label)
{
  double e = 0.0;
  for (std::int64_t p = 0; p < pr.Nodes; ++p)
  {
    e += pr.Cost[p * pr.Labels + label[p]];
  }
  pr.Edges->ForEach([&](std::int64_t k, std::int64_t a, std::int64_t b) {
    if (label[a] != label[b])
    {
      e += pr.Weight[k];
    }
  });
  return e;
}

namespace
{
std::int16_t HardLabel(const PottsProblem& pr, std::int64_t p)
{
  return pr.Hard.empty() ? -1 : pr.Hard[p];
}

// The labelling the moves start from: `label` when it has one label per node (a kept result), else
// each node's cheapest label; hard nodes take their own, a label out of range 0.
void StartLabels(const PottsProblem& pr, std::vector<std::uint8_t>& label)
{
  const std::int64_t n = pr.Nodes;
  const int L = pr.Labels;
  if (static_cast<std::int64_t>(label.size()) != n)
  {
    label.assign(n, 0);
    for (std::int64_t p = 0; p < n; ++p)
    {
      const double* c = &pr.Cost[p * L];
      label[p] = static_cast<std::uint8_t>(HardLabel(pr, p) >= 0 ? HardLabel(pr, p) : std::min_element(c, c + L) - c);
    }
  }
  for (std::int64_t p = 0; p < n; ++p)
  {
    const std::int16_t h = HardLabel(pr, p);
    if (label[p] >= L || (h >= 0 && label[p] != h))
    {
      label[p] = static_cast<std::uint8_t>(h >= 0 ? h : 0);
    }
  }
}

// A bound on the energy of any labelling: finite costs and weights whose sum overflows are an error.
double EnergyBound(const PottsProblem& pr)
{
  double K = 1.0;
  for (std::int64_t p = 0; p < pr.Nodes; ++p)
  {
    const double* c = &pr.Cost[p * pr.Labels];
    K += std::fabs(*std::max_element(c, c + pr.Labels)) + std::fabs(*std::min_element(c, c + pr.Labels));
  }
  for (double w : pr.Weight)
  {
    K += w;
  }
  return K;
}

// Each node's summed boundary weight (Reach: the most a move's pairwise terms can reward it for
// switching), and its neighbours with the edges' weights in compressed rows (First), to price a
// move by the nodes it moved.
struct Neighbourhood
{
  std::vector<double> Reach, Weight;
  std::vector<std::int64_t> First, Neighbour;
  explicit Neighbourhood(const PottsProblem& pr)
    : Reach(pr.Nodes, 0.0)
    , First(pr.Nodes + 1, 0)
  {
    const std::int64_t n = pr.Nodes;
    pr.Edges->ForEach([&](std::int64_t k, std::int64_t p, std::int64_t q) {
      this->Reach[p] += pr.Weight[k];
      this->Reach[q] += pr.Weight[k];
      ++this->First[p + 1];
      ++this->First[q + 1];
    });
    for (std::int64_t p = 0; p < n; ++p)
    {
      this->First[p + 1] += this->First[p];
    }
    this->Neighbour.resize(this->First[n]);
    this->Weight.resize(this->First[n]);
    std::vector<std::int64_t> at(this->First.begin(), this->First.end() - 1);
    pr.Edges->ForEach([&](std::int64_t k, std::int64_t p, std::int64_t q) {
      this->Neighbour[at[p]] = q;
      this->Weight[at[p]++] = pr.Weight[k];
      this->Neighbour[at[q]] = p;
      this->Weight[at[q]++] = pr.Weight[k];
    });
  }
};

// One alpha-expansion move on the graph g (reset here): the nodes it switches to alpha and the
// energy change. Node p keeps its label and pays keep[p] (source segment), or takes alpha and pays
// take[p] (sink). Fixed, and left out of the graph: nodes at alpha, hard nodes of another label, and
// nodes whose cost of alpha exceeds their cost of keeping by at least their summed boundary weight
// (no neighbours can make switching pay, so keeping is optimal: the move stays exact).
struct MoveBuffers
{
  std::vector<double> Keep, Take;
  std::vector<std::int32_t> Id; // a node's id in the move's graph, -1 when it is fixed
};
double ExpansionMove(const PottsProblem& pr, int alpha, const std::vector<std::uint8_t>& label, const Neighbourhood& around,
  Flow& g, MoveBuffers& buffers, std::vector<std::int64_t>& switched)
{
  const std::int64_t n = pr.Nodes;
  const int L = pr.Labels;
  std::vector<double>& keep = buffers.Keep;
  std::vector<double>& take = buffers.Take;
  std::vector<std::int32_t>& id = buffers.Id;
  keep.resize(n);
  take.resize(n);
  id.resize(n);
  std::int32_t active = 0;
  for (std::int64_t p = 0; p < n; ++p)
  {
    const double* c = &pr.Cost[p * L];
    keep[p] = take[p] = 0.0;
    id[p] = -1;
    if (label[p] != alpha && HardLabel(pr, p) < 0 && c[alpha] - c[label[p]] < around.Reach[p])
    {
      keep[p] = c[label[p]];
      take[p] = c[alpha];
      id[p] = active++;
    }
  }
  switched.clear();
  if (active == 0)
  {
    return 0.0;
  }
  g.reset();
  g.add_node(active);
  pr.Edges->ForEach([&](std::int64_t k, std::int64_t p, std::int64_t q) {
    const double w = pr.Weight[k];
    const int a = label[p], b = label[q];
    if (w == 0.0 || (id[p] < 0 && id[q] < 0))
    {
      return;
    }
    if (id[p] < 0 || id[q] < 0)
    {
      // One end fixed at its label f: the other pays w when its choice differs from f.
      const std::int64_t x = id[p] < 0 ? q : p;
      const int f = id[p] < 0 ? a : b;
      const int own = id[p] < 0 ? b : a;
      keep[x] += own != f ? w : 0.0;
      take[x] += alpha != f ? w : 0.0;
    }
    else if (a == b)
    {
      g.add_edge(id[p], id[q], w, w);
    }
    else
    {
      // Keep/keep pays w (a != b), keep/alpha w, alpha/keep w, alpha/alpha 0.
      keep[q] += w;
      g.add_edge(id[p], id[q], w, 0.0);
    }
  });
  for (std::int64_t p = 0; p < n; ++p)
  {
    if (id[p] >= 0)
    {
      const double low = std::min(keep[p], take[p]);
      g.add_tweights(id[p], take[p] - low, keep[p] - low);
    }
  }
  g.maxflow();
  for (std::int64_t p = 0; p < n; ++p)
  {
    if (id[p] >= 0 && g.what_segment(id[p]) == Flow::SINK)
    {
      switched.push_back(p);
    }
  }
  // The move's energy change, from the nodes it switched and their edges (an edge between two
  // switched nodes counted once).
  double change = 0.0;
  for (const std::int64_t p : switched)
  {
    change += pr.Cost[p * L + alpha] - pr.Cost[p * L + label[p]];
    for (std::int64_t j = around.First[p]; j < around.First[p + 1]; ++j)
    {
      const std::int64_t q = around.Neighbour[j];
      const bool both = id[q] >= 0 && g.what_segment(id[q]) == Flow::SINK;
      if (both && q < p)
      {
        continue;
      }
      change += around.Weight[j] * ((both ? 0 : alpha != label[q]) - (label[p] != label[q] ? 1.0 : 0.0));
    }
  }
  return change;
}
} // namespace

ExpansionResult AlphaExpansion(const PottsProblem& pr, std::vector<std::uint8_t> label, const ProgressFunction& progress,
  int maxCycles)
{
  ExpansionResult r;
  r.Error = Validate(pr);
  if (!r.Error.empty())
  {
    return r;
  }
  const std::int64_t n = pr.Nodes;
  const int L = pr.Labels;
  StartLabels(pr, label);
  if (!std::isfinite(EnergyBound(pr)))
  {
    r.Error = "the energy overflows (lambda or the graph are too large); lower lambda.";
    return r;
  }
  const std::int64_t m = pr.Edges->Size();
  double energy = PottsEnergy(pr, label);
  const Neighbourhood around(pr);
  try
  {
    Flow g(static_cast<int>(n), static_cast<int>(m), ThrowOutOfMemory);
    const int total = std::max(1, maxCycles) * L;
    std::vector<std::int64_t> switched;
    MoveBuffers buffers;
    // Done when every label's move has been tried since the last move that lowered the energy.
    int sinceLowered = 0;
    for (r.Cycles = 0; r.Cycles < std::max(1, maxCycles) && sinceLowered < L;)
    {
      ++r.Cycles;
      for (int alpha = 0; alpha < L && sinceLowered < L; ++alpha, ++sinceLowered)
      {
        if (!progress(static_cast<double>((r.Cycles - 1) * L + alpha) / total))
        {
          r.Aborted = true;
          return r;
        }
        const double change = ExpansionMove(pr, alpha, label, around, g, buffers, switched);
        if (!switched.empty() && change < -1e-9 * std::max(1.0, std::fabs(energy)))
        {
          for (const std::int64_t p : switched)
          {
            label[p] = static_cast<std::uint8_t>(alpha);
          }
          energy += change;
          ++r.Moves;
          sinceLowered = 0;
        }
      }
    }
  }
  catch (const std::exception&)
  {
    r.Error = "not enough memory for the max-flow graph (" + std::to_string(n) + " nodes, " + std::to_string(m) + " edges).";
    return r;
  }
  r.Energy = PottsEnergy(pr, label); // summed afresh: the moves' changes carry rounding
  r.Label = std::move(label);
  return r;
}
} // namespace featuremesh
