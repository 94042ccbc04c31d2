// Alpha-expansion (Boykov, Veksler & Zabih, "Fast approximate energy minimization via graph cuts",
// PAMI 2001) of a Potts energy on any graph, each move one Boykov-Kolmogorov max-flow:
//
//   E(L) = sum_p Cost_p(L_p) + sum_pq Weight_pq [L_p != L_q]
//
// A move lets every node keep its label or take label alpha; moves run for alpha = 0..Labels-1 in
// cycles until a cycle lowers the energy no more. The Potts term is a metric, so each move is the
// exact optimum among its labellings and the result lies within a factor 2 of the global optimum.
#pragma once

#include "GraphEdges.h"
#include "Parallel.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace featuremesh
{
struct PottsProblem
{
  std::int64_t Nodes = 0;
  int Labels = 0;               // 2..256
  const GraphEdges* Edges = nullptr;
  std::vector<double> Weight;   // per edge, >= 0
  std::vector<double> Cost;     // Nodes * Labels, node p's cost of label l at p * Labels + l
  std::vector<std::int16_t> Hard; // per node: -1 free, else the label it must take; empty = none
};

struct ExpansionResult
{
  std::vector<std::uint8_t> Label;
  double Energy = 0.0;
  int Moves = 0;  // expansion moves that lowered the energy
  int Cycles = 0; // passes over the labels
  std::string Error;
  bool Aborted = false;
};

// Each label's move graph with its flow, kept from one expansion to the next ("recycling", Alahari,
// Kohli & Torr, PAMI 2010, after Kohli & Torr's dynamic graph cuts): a move is then the last move of
// its label updated where labels, costs or hard labels changed since, and its max-flow starts from
// the last one's. Kept only while the graphs of all labels fit in Budget bytes; a change of the
// graph, its weights or the label count starts afresh.
class RecycledMoves
{
public:
  static constexpr std::int64_t Budget = std::int64_t(1) << 30;
  RecycledMoves();
  ~RecycledMoves();
  RecycledMoves(RecycledMoves&&) noexcept;
  RecycledMoves& operator=(RecycledMoves&&) noexcept;
  void Clear();
  struct State;
  std::unique_ptr<State> Kept;
};

// What a fresh expansion allocates (its max-flow graph, the problem's neighbourhood, the move's
// buffers), kept for the next one: on a BraTS band (~200 k voxels) the graph's arcs alone take
// ~40 MB, beyond what glibc's malloc recycles (32 MB), and come as fresh pages on every call.
class ExpansionWorkspace
{
public:
  ExpansionWorkspace();
  ~ExpansionWorkspace();
  ExpansionWorkspace(ExpansionWorkspace&&) noexcept;
  ExpansionWorkspace& operator=(ExpansionWorkspace&&) noexcept;
  // A caller that keeps one graph with its weights across expansions names them by a key (0: none):
  // while the key stays, the nodes' rows of edges are kept instead of built again. New edges or
  // weights need a new key.
  std::uint64_t GraphKey = 0;
  struct State;
  std::unique_ptr<State> Kept;
};

// The energy of `label` (hard constraints not checked), summed over fixed blocks: the same for any
// thread count.
double PottsEnergy(const PottsProblem& problem, const std::vector<std::uint8_t>& label,
  const ParallelFor& parallel = SerialFor());

// From `start` (empty: each node's hard label, else its cheapest), at most `maxCycles` cycles.
// Every input is checked first (finite costs and weights, edges naming nodes, hard labels in
// range): a problem is an Error sentence. Progress after each move; an abort leaves Aborted.
// With `recycled`, each label's move graph is kept and updated (above) instead of built anew; each
// move is the same exact optimum, so the result differs only where a move has tied cuts. `parallel`
// runs the checks, the energy's sums (over fixed blocks) and a kept graph's terminal terms; the
// result is the same for any thread count. Without `recycled`, `workspace` (optional) lends its
// memory; the result does not depend on it.
ExpansionResult AlphaExpansion(const PottsProblem& problem, std::vector<std::uint8_t> start,
  const ProgressFunction& progress = NoProgress(), int maxCycles = 8, RecycledMoves* recycled = nullptr,
  const ParallelFor& parallel = SerialFor(), ExpansionWorkspace* workspace = nullptr);
} // namespace featuremesh
