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
  auto hard = [&](std::int64_t p) { return pr.Hard.empty() ? -1 : pr.Hard[p]; };
  if (static_cast<std::int64_t>(label.size()) != n)
  {
    label.assign(n, 0);
    for (std::int64_t p = 0; p < n; ++p)
    {
      const double* c = &pr.Cost[p * L];
      label[p] = static_cast<std::uint8_t>(hard(p) >= 0 ? hard(p) : std::min_element(c, c + L) - c);
    }
  }
  for (std::int64_t p = 0; p < n; ++p)
  {
    if (label[p] >= L || (hard(p) >= 0 && label[p] != hard(p)))
    {
      label[p] = static_cast<std::uint8_t>(hard(p) >= 0 ? hard(p) : 0);
    }
  }
  // K exceeds the energy of any labelling: a hard node never leaves its label.
  double K = 1.0;
  for (std::int64_t p = 0; p < n; ++p)
  {
    const double* c = &pr.Cost[p * L];
    K += std::fabs(*std::max_element(c, c + L)) + std::fabs(*std::min_element(c, c + L));
  }
  for (double w : pr.Weight)
  {
    K += w;
  }
  if (!std::isfinite(K))
  {
    r.Error = "the energy overflows (lambda or the graph are too large); lower lambda.";
    return r;
  }
  const GraphEdges& edges = *pr.Edges;
  const std::int64_t m = edges.Size();
  double energy = PottsEnergy(pr, label);
  std::vector<double> keep(n), take(n);
  try
  {
    Flow g(static_cast<int>(n), static_cast<int>(m), ThrowOutOfMemory);
    const int total = std::max(1, maxCycles) * L;
    for (r.Cycles = 0; r.Cycles < std::max(1, maxCycles);)
    {
      ++r.Cycles;
      bool lowered = false;
      for (int alpha = 0; alpha < L; ++alpha)
      {
        if (!progress(static_cast<double>((r.Cycles - 1) * L + alpha) / total))
        {
          r.Aborted = true;
          return r;
        }
        // Node p in the source segment keeps its label and pays keep[p]; in the sink it takes alpha
        // and pays take[p]. Nodes already at alpha are fixed and left out of the graph's edges.
        for (std::int64_t p = 0; p < n; ++p)
        {
          const double* c = &pr.Cost[p * L];
          if (label[p] == alpha)
          {
            keep[p] = take[p] = 0.0;
          }
          else
          {
            keep[p] = c[label[p]];
            take[p] = hard(p) >= 0 ? K : c[alpha];
          }
        }
        g.reset();
        g.add_node(static_cast<int>(n));
        edges.ForEach([&](std::int64_t k, std::int64_t p, std::int64_t q) {
          const double w = pr.Weight[k];
          const int a = label[p], b = label[q];
          if (w == 0.0 || (a == alpha && b == alpha))
          {
            return;
          }
          if (a == alpha)
          {
            keep[q] += w;
          }
          else if (b == alpha)
          {
            keep[p] += w;
          }
          else if (a == b)
          {
            g.add_edge(static_cast<int>(p), static_cast<int>(q), w, w);
          }
          else
          {
            // Keep/keep pays w (a != b), keep/alpha w, alpha/keep w, alpha/alpha 0.
            keep[q] += w;
            g.add_edge(static_cast<int>(p), static_cast<int>(q), w, 0.0);
          }
        });
        for (std::int64_t p = 0; p < n; ++p)
        {
          if (keep[p] != 0.0 || take[p] != 0.0)
          {
            g.add_tweights(static_cast<int>(p), take[p], keep[p]);
          }
        }
        g.maxflow();
        std::vector<std::uint8_t> moved(label);
        for (std::int64_t p = 0; p < n; ++p)
        {
          if (label[p] != alpha && g.what_segment(static_cast<int>(p)) == Flow::SINK)
          {
            moved[p] = static_cast<std::uint8_t>(alpha);
          }
        }
        const double e = PottsEnergy(pr, moved);
        if (e < energy - 1e-9 * std::max(1.0, std::fabs(energy)))
        {
          label.swap(moved);
          energy = e;
          ++r.Moves;
          lowered = true;
        }
      }
      if (!lowered)
      {
        break;
      }
    }
  }
  catch (const std::exception&)
  {
    r.Error = "not enough memory for the max-flow graph (" + std::to_string(n) + " nodes, " + std::to_string(m) + " edges).";
    return r;
  }
  r.Label = std::move(label);
  r.Energy = energy;
  return r;
}
} // namespace featuremesh
