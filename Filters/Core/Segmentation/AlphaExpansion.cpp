#include "AlphaExpansion.h"
#include "FlowGraph.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

namespace featuremesh
{
namespace
{
using Flow = FlowGraph;

// Loops over fixed blocks of nodes (or of the edges' blocks), so that a sum adds its blocks' partial
// sums in block order and comes out the same for any thread count.
constexpr std::int64_t NodeBlock = 16384;

std::int64_t NodeBlocks(const PottsProblem& pr)
{
  return (pr.Nodes + NodeBlock - 1) / NodeBlock;
}

// Threads start per loop (VTK 9.2's STDThread backend): a graph of a few blocks runs on this one.
constexpr std::int64_t ThreadedBlocks = 8;

template <typename F>
void ForBlocks(const ParallelFor& parallel, std::int64_t blocks, F&& f)
{
  const auto body = [&](std::int64_t b0, std::int64_t b1) {
    for (std::int64_t b = b0; b < b1; ++b)
    {
      f(b);
    }
  };
  blocks < ThreadedBlocks ? body(0, blocks) : parallel(blocks, 1, body);
}

template <typename F>
void ForNodeBlocks(const PottsProblem& pr, const ParallelFor& parallel, F&& f)
{
  ForBlocks(parallel, NodeBlocks(pr),
    [&](std::int64_t b) { f(b, b * NodeBlock, std::min(pr.Nodes, (b + 1) * NodeBlock)); });
}

std::int16_t HardLabel(const PottsProblem& pr, std::int64_t p)
{
  return pr.Hard.empty() ? -1 : pr.Hard[p];
}

// The moves' start: checks every input (finite costs and weights, hard labels in range, edges
// naming nodes) and, in the same passes over the node and the edge blocks, sets the start labels
// (`label` when it has one per node, a kept result, else each node's cheapest; hard nodes their
// own, a label out of range 0) and sums their energy as PottsEnergy does. Costs and weights of at
// most 1e150 on at most GraphSizeProblem's nodes and edges keep every energy far below overflow.
std::string Start(const PottsProblem& pr, std::vector<std::uint8_t>& label, const ParallelFor& parallel, double& energy)
{
  if (pr.Labels < 2 || pr.Labels > 256)
  {
    return "alpha-expansion needs 2 to 256 labels.";
  }
  if (pr.Nodes <= 0 || !pr.Edges)
  {
    return "the graph is empty.";
  }
  if (std::string size = GraphSizeProblem(pr.Nodes, pr.Edges->Size()); !size.empty())
  {
    return size;
  }
  if (static_cast<std::int64_t>(pr.Cost.size()) != pr.Nodes * pr.Labels ||
    static_cast<std::int64_t>(pr.Weight.size()) != pr.Edges->Size() ||
    (!pr.Hard.empty() && static_cast<std::int64_t>(pr.Hard.size()) != pr.Nodes))
  {
    return "the costs, weights or hard labels do not match the graph.";
  }
  const int L = pr.Labels;
  const bool cheapest = static_cast<std::int64_t>(label.size()) != pr.Nodes;
  if (cheapest)
  {
    label.resize(pr.Nodes);
  }
  enum : std::uint8_t { BadCost = 1, BadWeight = 2, BadHard = 4, BadEnd = 8 };
  std::vector<std::uint8_t> nodeBad(NodeBlocks(pr), 0), edgeBad(pr.Edges->Blocks(), 0);
  std::vector<double> nodeSum(nodeBad.size(), 0.0), edgeSum(edgeBad.size(), 0.0);
  // Each block's flags and sum in locals, stored once: neighbouring ones share a cache line.
  ForNodeBlocks(pr, parallel, [&](std::int64_t b, std::int64_t p0, std::int64_t p1) {
    bool cost = false, hard = false;
    for (std::int64_t i = p0 * L; i < p1 * L; ++i)
    {
      cost = cost || !(std::fabs(pr.Cost[i]) <= 1e150);
    }
    for (std::int64_t p = p0; p < p1 && !pr.Hard.empty(); ++p)
    {
      hard = hard || pr.Hard[p] < -1 || pr.Hard[p] >= L;
    }
    nodeBad[b] = (cost ? BadCost : 0) | (hard ? BadHard : 0);
    if (cost || hard)
    {
      return;
    }
    double sum = 0.0;
    for (std::int64_t p = p0; p < p1; ++p)
    {
      const std::int16_t h = HardLabel(pr, p);
      const double* c = &pr.Cost[p * L];
      if (cheapest)
      {
        label[p] = static_cast<std::uint8_t>(h >= 0 ? h : std::min_element(c, c + L) - c);
      }
      if (label[p] >= L || (h >= 0 && label[p] != h))
      {
        label[p] = static_cast<std::uint8_t>(h >= 0 ? h : 0);
      }
      sum += c[label[p]];
    }
    nodeSum[b] = sum;
  });
  ForBlocks(parallel, pr.Edges->Blocks(), [&](std::int64_t b) {
    bool weight = false, end = false;
    double sum = 0.0;
    pr.Edges->ForEach(b, b + 1, [&](std::int64_t e, std::int64_t a, std::int64_t c) {
      weight = weight || !(pr.Weight[e] >= 0.0 && pr.Weight[e] <= 1e150);
      const bool inside = a >= 0 && c >= 0 && a < pr.Nodes && c < pr.Nodes;
      end = end || !inside;
      sum += inside && label[a] != label[c] ? pr.Weight[e] : 0.0;
    });
    edgeBad[b] = (weight ? BadWeight : 0) | (end ? BadEnd : 0);
    edgeSum[b] = sum;
  });
  std::uint8_t bad = 0;
  for (std::uint8_t f : nodeBad)
  {
    bad |= f;
  }
  for (std::uint8_t f : edgeBad)
  {
    bad |= f;
  }
  energy = 0.0;
  for (double e : nodeSum)
  {
    energy += e;
  }
  for (double e : edgeSum)
  {
    energy += e;
  }
  return bad & BadCost ? "a label cost is not finite; check the image for NaN or infinite values."
    : bad & BadWeight  ? "a boundary weight is negative or not finite."
    : bad & BadHard    ? "a hard label lies outside [0, labels)."
    : bad & BadEnd     ? "an edge names a node outside the graph."
                       : std::string();
}
} // namespace

double PottsEnergy(const PottsProblem& pr, const std::vector<std::uint8_t>& label, const ParallelFor& parallel)
{
  std::vector<double> nodeSum(NodeBlocks(pr), 0.0), edgeSum(pr.Edges->Blocks(), 0.0);
  ForNodeBlocks(pr, parallel, [&](std::int64_t b, std::int64_t p0, std::int64_t p1) {
    double sum = 0.0;
    for (std::int64_t p = p0; p < p1; ++p)
    {
      sum += pr.Cost[p * pr.Labels + label[p]];
    }
    nodeSum[b] = sum;
  });
  ForBlocks(parallel, pr.Edges->Blocks(), [&](std::int64_t b) {
    double sum = 0.0;
    pr.Edges->ForEach(b, b + 1, [&](std::int64_t k, std::int64_t a, std::int64_t c) {
      sum += label[a] != label[c] ? pr.Weight[k] : 0.0;
    });
    edgeSum[b] = sum;
  });
  double e = 0.0;
  for (double s : nodeSum)
  {
    e += s;
  }
  for (double s : edgeSum)
  {
    e += s;
  }
  return e;
}

namespace
{
// v sized n; grown, its capacity half again as large: a graph that grows a little from one call to
// the next (a voxel band's kept domain) keeps its arrays and their pages, not fresh ones each time.
template <typename T>
void ResizeWithRoom(std::vector<T>& v, std::size_t n)
{
  if (v.capacity() < n)
  {
    v.reserve(n + n / 2);
  }
  v.resize(n);
}

// Each node's summed boundary weight (Reach: the most a move's pairwise terms can reward it for
// switching), and its neighbours with the edges' weights in compressed rows (First), to price a
// move by the nodes it moved. Side: 2 e when the node is edge e's first end, 2 e + 1 its second.
// Neighbours and sides in 32 bits (GraphSizeProblem keeps nodes and 2 x edges below 2^31): the
// moves stream these rows, and they are most of what a move reads.
struct Neighbourhood
{
  std::vector<double> Reach, Weight;
  std::vector<std::int64_t> First;
  std::vector<std::int32_t> Neighbour, Side;
  // Whether the edges come in ascending order of their first ends (a voxel band's faces): then a
  // node's first-end entries, in the order of the nodes, are the edges in their own order.
  bool FirstEndsAscending = false;
  Neighbourhood() = default;
  explicit Neighbourhood(const PottsProblem& pr) { this->Build(pr); }
  // Reuses the vectors' memory.
  void Build(const PottsProblem& pr)
  {
    const std::int64_t n = pr.Nodes;
    ResizeWithRoom(this->Reach, n);
    ResizeWithRoom(this->First, n + 1);
    std::fill(this->Reach.begin(), this->Reach.end(), 0.0);
    std::fill(this->First.begin(), this->First.end(), 0);
    this->FirstEndsAscending = true;
    std::int64_t last = 0;
    pr.Edges->ForEach([&](std::int64_t k, std::int64_t p, std::int64_t q) {
      this->Reach[p] += pr.Weight[k];
      this->Reach[q] += pr.Weight[k];
      ++this->First[p + 1];
      ++this->First[q + 1];
      this->FirstEndsAscending = this->FirstEndsAscending && p >= last;
      last = p;
    });
    for (std::int64_t p = 0; p < n; ++p)
    {
      this->First[p + 1] += this->First[p];
    }
    ResizeWithRoom(this->Neighbour, this->First[n]);
    ResizeWithRoom(this->Weight, this->First[n]);
    ResizeWithRoom(this->Side, this->First[n]);
    std::vector<std::int64_t> at(this->First.begin(), this->First.end() - 1);
    pr.Edges->ForEach([&](std::int64_t k, std::int64_t p, std::int64_t q) {
      this->Side[at[p]] = static_cast<std::int32_t>(2 * k);
      this->Neighbour[at[p]] = static_cast<std::int32_t>(q);
      this->Weight[at[p]++] = pr.Weight[k];
      this->Side[at[q]] = static_cast<std::int32_t>(2 * k + 1);
      this->Neighbour[at[q]] = static_cast<std::int32_t>(p);
      this->Weight[at[q]++] = pr.Weight[k];
    });
  }
};

// A move's energy change, from the nodes it switched and their edges (an edge between two switched
// nodes counted once); moved(q) tells whether q is one of them.
template <typename Moved>
double MoveChange(const PottsProblem& pr, int alpha, const std::vector<std::uint8_t>& label, const Neighbourhood& around,
  const std::vector<std::int64_t>& switched, Moved&& moved)
{
  const int L = pr.Labels;
  double change = 0.0;
  for (const std::int64_t p : switched)
  {
    change += pr.Cost[p * L + alpha] - pr.Cost[p * L + label[p]];
    for (std::int64_t j = around.First[p]; j < around.First[p + 1]; ++j)
    {
      const std::int64_t q = around.Neighbour[j];
      const bool both = moved(q);
      if (both && q < p)
      {
        continue;
      }
      change += around.Weight[j] * ((both ? 0 : alpha != label[q]) - (label[p] != label[q] ? 1.0 : 0.0));
    }
  }
  return change;
}

// One alpha-expansion move on the graph g (reset here): the nodes it switches to alpha and the
// energy change. Free node p keeps its label and pays Keep[Id[p]] (source segment), or takes alpha
// and pays Take[Id[p]] (sink); the loops after the first visit the free nodes only. Fixed, and left
// out of the graph: nodes at alpha, hard nodes of another label, and nodes whose cost of alpha
// exceeds their cost of keeping by at least their summed boundary weight (no neighbours can make
// switching pay, so keeping is optimal: the move stays exact).
struct MoveBuffers
{
  std::vector<double> Keep, Take; // by id in the move's graph
  std::vector<std::int32_t> Id;   // a node's id in the move's graph, -1 when fixed (after the flow: or kept)
  std::vector<std::int64_t> Free; // the free nodes in ascending order: Free[Id[p]] == p
};
double ExpansionMove(const PottsProblem& pr, int alpha, const std::vector<std::uint8_t>& label, const Neighbourhood& around,
  Flow& g, MoveBuffers& buffers, std::vector<std::int64_t>& switched)
{
  const std::int64_t n = pr.Nodes;
  const int L = pr.Labels;
  std::vector<double>& keep = buffers.Keep;
  std::vector<double>& take = buffers.Take;
  std::vector<std::int32_t>& id = buffers.Id;
  std::vector<std::int64_t>& freeNodes = buffers.Free;
  ResizeWithRoom(id, n);
  freeNodes.clear();
  for (std::int64_t p = 0; p < n; ++p)
  {
    const double* c = &pr.Cost[p * L];
    const bool isFree = label[p] != alpha && HardLabel(pr, p) < 0 && c[alpha] - c[label[p]] < around.Reach[p];
    id[p] = isFree ? static_cast<std::int32_t>(freeNodes.size()) : -1;
    if (isFree)
    {
      freeNodes.push_back(p);
    }
  }
  const std::int32_t active = static_cast<std::int32_t>(freeNodes.size());
  switched.clear();
  if (active == 0)
  {
    return 0.0;
  }
  ResizeWithRoom(keep, active);
  ResizeWithRoom(take, active);
  for (std::int32_t a = 0; a < active; ++a)
  {
    const double* c = &pr.Cost[freeNodes[a] * L];
    keep[a] = c[label[freeNodes[a]]];
    take[a] = c[alpha];
  }
  g.reset();
  g.add_node(active);
  if (around.FirstEndsAscending)
  {
    // The same terms and edges from the free nodes' rows alone: each node's sums in its edges'
    // order, the edges added in theirs (a move of few free nodes skips most edges).
    for (std::int32_t x = 0; x < active; ++x)
    {
      const std::int64_t p = freeNodes[x];
      const int a = label[p];
      for (std::int64_t j = around.First[p]; j < around.First[p + 1]; ++j)
      {
        const double w = around.Weight[j];
        const std::int64_t q = around.Neighbour[j];
        if (w == 0.0)
        {
          continue;
        }
        const int b = label[q];
        if (id[q] < 0)
        {
          keep[x] += a != b ? w : 0.0;
          take[x] += alpha != b ? w : 0.0;
        }
        else if ((around.Side[j] & 1) == 0)
        {
          g.add_edge(x, id[q], w, a == b ? w : 0.0);
        }
        else if (a != b)
        {
          keep[x] += w;
        }
      }
    }
  }
  else
  {
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
        const std::int32_t x = id[p] < 0 ? id[q] : id[p];
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
        keep[id[q]] += w;
        g.add_edge(id[p], id[q], w, 0.0);
      }
    });
  }
  for (std::int32_t x = 0; x < active; ++x)
  {
    const double low = std::min(keep[x], take[x]);
    g.add_tweights(x, take[x] - low, keep[x] - low);
  }
  g.maxflow();
  // The switched nodes keep their ids, the others drop theirs: MoveChange then asks no segments.
  for (std::int32_t x = 0; x < active; ++x)
  {
    if (g.what_segment(x) == Flow::SINK)
    {
      switched.push_back(freeNodes[x]);
    }
    else
    {
      id[freeNodes[x]] = -1;
    }
  }
  return MoveChange(pr, alpha, label, around, switched, [&](std::int64_t q) { return id[q] >= 0; });
}

// A label's kept move graph: every node and edge, with the labels, terminal terms (take - keep) and
// edge capacities it was last set for; the nodes whose label or hard label changed since (their
// edges change) and those whose cost of alpha or of their label did (their terminal term changes);
// the free nodes in the sink segment of its last max-flow (Sink, listed in SinkList).
struct LabelGraph
{
  std::unique_ptr<Flow> G;
  std::unique_ptr<maxflow::Block<int>> Changed; // libmaxflow's nodes whose segment may have changed
  std::vector<std::uint8_t> Label, Sink;
  std::vector<double> Net, Cap; // Cap[2 e], Cap[2 e + 1]: edge e's first -> second end, and back
  std::vector<std::int64_t> Relabelled, CostChanged, SinkList;
  bool Built = false;
};
} // namespace

struct RecycledMoves::State
{
  std::int64_t Nodes = 0;
  int Labels = 0;
  GraphEdges Edges;
  std::vector<double> Weight, Cost;
  std::vector<std::int16_t> Hard;
  std::vector<std::uint8_t> Label; // after the last move
  std::unique_ptr<Neighbourhood> Around;
  std::vector<LabelGraph> Graph;
  std::vector<std::uint32_t> Stamp; // a node's last visit, to visit each once per move
  std::uint32_t Visit = 0;
  // Scratch of a sync: which of a node's costs changed, whether its label did; a move's terms.
  std::vector<std::uint64_t> Which;
  std::vector<std::uint8_t> Moved;
  std::vector<double> Terms;
};

struct ExpansionWorkspace::State
{
  Neighbourhood Around;
  std::uint64_t AroundKey = 0; // the GraphKey Around was built for
  std::unique_ptr<Flow> Graph;
  MoveBuffers Buffers;
};
ExpansionWorkspace::ExpansionWorkspace() = default;
ExpansionWorkspace::~ExpansionWorkspace() = default;
ExpansionWorkspace::ExpansionWorkspace(ExpansionWorkspace&&) noexcept = default;
ExpansionWorkspace& ExpansionWorkspace::operator=(ExpansionWorkspace&&) noexcept = default;

RecycledMoves::RecycledMoves() = default;
RecycledMoves::~RecycledMoves() = default;
RecycledMoves::RecycledMoves(RecycledMoves&&) noexcept = default;
RecycledMoves& RecycledMoves::operator=(RecycledMoves&&) noexcept = default;
void RecycledMoves::Clear()
{
  this->Kept.reset();
}

namespace
{
// What the kept graphs of all labels take: libmaxflow's 48-byte nodes and 32-byte arcs, and the
// labels, terms and capacities each is set for.
std::int64_t RecycledBytes(std::int64_t nodes, std::int64_t edges, int labels)
{
  return labels * (nodes * (48 + 8 + 2) + edges * 2 * (32 + 8));
}

// Nodes whose label changed: every built graph updates them at its next move.
void RecordRelabelled(RecycledMoves::State& st, const std::vector<std::int64_t>& nodes)
{
  for (LabelGraph& g : st.Graph)
  {
    if (g.Built)
    {
      g.Relabelled.insert(g.Relabelled.end(), nodes.begin(), nodes.end());
    }
  }
}

// The kept state for this problem and the labels the moves start from (null when its graphs would
// not fit the budget): started afresh for another graph, weights or label count, else told which
// nodes' labels, costs or hard labels changed.
RecycledMoves::State* SyncRecycled(
  RecycledMoves& recycled, const PottsProblem& pr, const std::vector<std::uint8_t>& label, const ParallelFor& parallel)
{
  const std::int64_t n = pr.Nodes, m = pr.Edges->Size();
  const int L = pr.Labels;
  if (RecycledBytes(n, m, L) > RecycledMoves::Budget)
  {
    recycled.Clear();
    return nullptr;
  }
  std::unique_ptr<RecycledMoves::State>& k = recycled.Kept;
  if (!k || k->Nodes != n || k->Labels != L || !k->Edges.Same(*pr.Edges) || k->Weight != pr.Weight)
  {
    k.reset(new RecycledMoves::State);
    k->Nodes = n;
    k->Labels = L;
    k->Edges = pr.Edges->Keepable();
    k->Weight = pr.Weight;
    k->Cost = pr.Cost;
    k->Hard = pr.Hard.empty() ? std::vector<std::int16_t>(n, -1) : pr.Hard;
    k->Label = label;
    k->Around.reset(new Neighbourhood(pr));
    k->Graph.resize(L);
    k->Stamp.assign(n, 0);
    return k.get();
  }
  // Per node, whether its label or hard label changed, and which of its label costs did (bit l for
  // label l, bit 63 for every label from 63 on).
  const auto bit = [](int l) { return std::uint64_t(1) << std::min(l, 63); };
  std::vector<std::uint64_t>& which = k->Which;
  std::vector<std::uint8_t>& moved = k->Moved;
  which.resize(n);
  moved.resize(n);
  ForNodeBlocks(pr, parallel, [&](std::int64_t, std::int64_t p0, std::int64_t p1) {
    for (std::int64_t p = p0; p < p1; ++p)
    {
      const std::int16_t h = HardLabel(pr, p);
      const double* c = &pr.Cost[p * L];
      double* was = &k->Cost[p * L];
      std::uint64_t w = 0;
      moved[p] = h != k->Hard[p] || label[p] != k->Label[p];
      if (moved[p])
      {
        k->Hard[p] = h;
        k->Label[p] = label[p];
      }
      for (int l = 0; l < L; ++l)
      {
        if (c[l] != was[l])
        {
          w |= bit(l);
          was[l] = c[l];
        }
      }
      which[p] = w;
    }
  });
  std::vector<std::int64_t> relabelled, costChanged;
  for (std::int64_t p = 0; p < n; ++p)
  {
    if (moved[p])
    {
      relabelled.push_back(p);
    }
    if (which[p])
    {
      costChanged.push_back(p);
    }
  }
  RecordRelabelled(*k, relabelled);
  for (int alpha = 0; alpha < L; ++alpha)
  {
    LabelGraph& g = k->Graph[alpha];
    for (std::size_t i = 0; i < costChanged.size() && g.Built; ++i)
    {
      const std::int64_t p = costChanged[i];
      if (which[p] & (bit(alpha) | bit(g.Label[p])))
      {
        g.CostChanged.push_back(p);
      }
    }
    g.Built = g.Built && static_cast<std::int64_t>(g.Relabelled.size() + g.CostChanged.size()) <= 2 * n;
  }
  return k.get();
}

// The move of alpha on its kept graph: built at its first move, later updated where the nodes' labels
// changed (their edges, and their and their neighbours' terminal terms) or their costs did, and its
// max-flow run on from the last one's (libmaxflow's reused search trees). An edge whose flow exceeds
// its new capacity sends the excess back through the terminals (Kohli & Torr's reparameterisation).
// The same move as ExpansionMove, with every node in the graph: fixed ones stay isolated.
double RecycledMove(const PottsProblem& pr, int alpha, const std::vector<std::uint8_t>& label, RecycledMoves::State& st,
  std::vector<std::int64_t>& switched, const ParallelFor& parallel)
{
  const std::int64_t n = pr.Nodes, m = pr.Edges->Size();
  const int L = pr.Labels;
  const Neighbourhood& around = *st.Around;
  const std::vector<std::int16_t>& hard = st.Hard;
  LabelGraph& lg = st.Graph[alpha];
  const auto fixed = [&](std::int64_t p) { return label[p] == alpha || hard[p] >= 0; };
  const auto net = [&](std::int64_t p) {
    if (fixed(p))
    {
      return 0.0;
    }
    const int a = label[p];
    double keep = pr.Cost[p * L + a], take = pr.Cost[p * L + alpha];
    for (std::int64_t j = around.First[p]; j < around.First[p + 1]; ++j)
    {
      const int b = label[around.Neighbour[j]];
      if (fixed(around.Neighbour[j]))
      {
        keep += a != b ? around.Weight[j] : 0.0;
        take += alpha != b ? around.Weight[j] : 0.0;
      }
      else if (a != b && (around.Side[j] & 1))
      {
        keep += around.Weight[j];
      }
    }
    return take - keep;
  };
  // The terms of the nodes `list` names (all nodes when null), side by side: each reads only.
  std::vector<double>& terms = st.Terms;
  const auto netOf = [&](const std::vector<std::int64_t>* list, std::int64_t count) {
    terms.resize(count);
    const auto body = [&](std::int64_t i0, std::int64_t i1) {
      for (std::int64_t i = i0; i < i1; ++i)
      {
        terms[i] = net(list ? (*list)[i] : i);
      }
    };
    // A few nodes (most moves of a re-cut) are not worth starting threads for.
    count < ThreadedBlocks * NodeBlock ? body(0, count) : parallel(count, NodeBlock, body);
  };
  const auto capacities = [&](std::int64_t p, std::int64_t q, double w, double& c1, double& c2) {
    c1 = fixed(p) || fixed(q) ? 0.0 : w;
    c2 = fixed(p) || fixed(q) || label[p] != label[q] ? 0.0 : w;
  };
  // A node's segment as the move reads it: free and on the sink side.
  const auto recheck = [&](std::int64_t p) {
    const bool sink = !fixed(p) && lg.G->what_segment(static_cast<int>(p)) == Flow::SINK;
    if (sink && !lg.Sink[p])
    {
      lg.SinkList.push_back(p);
    }
    lg.Sink[p] = sink;
  };
  if (!lg.Built)
  {
    if (!lg.G)
    {
      // In small pages: on the 2-core VMs, advised huge pages made a first cut's graphs (~45 MB a
      // label on BraTS) take 0.3-0.5 s each to touch in half the runs (docs/benchmark.md).
      lg.G.reset(new Flow(static_cast<int>(n), static_cast<int>(m), ThrowOutOfMemory));
      lg.Changed.reset(new maxflow::Block<int>(4096));
    }
    Flow& g = *lg.G;
    g.reset();
    g.add_node(static_cast<int>(n));
    lg.Cap.resize(static_cast<std::size_t>(2 * m));
    pr.Edges->ForEach([&](std::int64_t k, std::int64_t p, std::int64_t q) {
      capacities(p, q, pr.Weight[k], lg.Cap[2 * k], lg.Cap[2 * k + 1]);
      g.add_edge(static_cast<int>(p), static_cast<int>(q), lg.Cap[2 * k], lg.Cap[2 * k + 1]);
    });
    netOf(nullptr, n);
    lg.Net.swap(terms);
    for (std::int64_t p = 0; p < n; ++p)
    {
      g.add_tweights(static_cast<int>(p), std::max(lg.Net[p], 0.0), std::max(-lg.Net[p], 0.0));
    }
    lg.Label = label;
    lg.Relabelled.clear();
    lg.CostChanged.clear();
    lg.Built = true;
    g.maxflow(false);
    lg.Sink.assign(n, 0);
    lg.SinkList.clear();
    for (std::int64_t p = 0; p < n; ++p)
    {
      recheck(p);
    }
  }
  else
  {
    Flow& g = *lg.G;
    // Only a change of sign of a node's terminal residual, or of an arc's between zero and not,
    // can change the search trees: the other nodes are not marked (libmaxflow's mark_node).
    const auto sign = [](double v) { return (v > 0.0) - (v < 0.0); };
    const auto addTerminal = [&](std::int64_t p, double source, double sink) {
      const int before = sign(g.get_trcap(static_cast<int>(p)));
      g.add_tweights(static_cast<int>(p), source, sink);
      if (sign(g.get_trcap(static_cast<int>(p))) != before)
      {
        g.mark_node(static_cast<int>(p));
      }
    };
    if (++st.Visit == 0)
    {
      std::fill(st.Stamp.begin(), st.Stamp.end(), 0);
      st.Visit = 1;
    }
    std::vector<std::int64_t> touched;
    const auto touch = [&](std::int64_t p) {
      if (st.Stamp[p] != st.Visit)
      {
        st.Stamp[p] = st.Visit;
        touched.push_back(p);
      }
    };
    const Flow::arc_id arcs = g.get_first_arc();
    for (const std::int64_t p : lg.Relabelled)
    {
      lg.Label[p] = label[p];
      touch(p);
      for (std::int64_t j = around.First[p]; j < around.First[p + 1]; ++j)
      {
        const std::int64_t q = around.Neighbour[j], k = around.Side[j] >> 1;
        touch(q);
        const bool second = around.Side[j] & 1;
        const std::int64_t a = second ? q : p, b = second ? p : q;
        double c1, c2;
        capacities(a, b, around.Weight[j], c1, c2);
        if (c1 == lg.Cap[2 * k] && c2 == lg.Cap[2 * k + 1])
        {
          continue;
        }
        const double was1 = g.get_rcap(arcs + 2 * k), was2 = g.get_rcap(arcs + 2 * k + 1);
        const double flow = lg.Cap[2 * k] - was1;
        double r1 = c1 - flow, r2 = c2 + flow;
        if (r1 < 0.0)
        {
          addTerminal(a, -r1, 0.0);
          addTerminal(b, 0.0, -r1);
          r1 = 0.0;
          r2 = c1 + c2;
        }
        else if (r2 < 0.0)
        {
          addTerminal(b, -r2, 0.0);
          addTerminal(a, 0.0, -r2);
          r2 = 0.0;
          r1 = c1 + c2;
        }
        g.set_rcap(arcs + 2 * k, r1);
        g.set_rcap(arcs + 2 * k + 1, r2);
        lg.Cap[2 * k] = c1;
        lg.Cap[2 * k + 1] = c2;
        if ((was1 > 0.0) != (r1 > 0.0) || (was2 > 0.0) != (r2 > 0.0))
        {
          g.mark_node(static_cast<int>(a));
          g.mark_node(static_cast<int>(b));
        }
      }
    }
    for (const std::int64_t p : lg.CostChanged)
    {
      touch(p);
    }
    netOf(&touched, static_cast<std::int64_t>(touched.size()));
    for (std::size_t i = 0; i < touched.size(); ++i)
    {
      const std::int64_t p = touched[i];
      const double t = terms[i];
      if (t != lg.Net[p])
      {
        addTerminal(p, t - lg.Net[p], 0.0);
        lg.Net[p] = t;
      }
    }
    g.maxflow(true, lg.Changed.get());
    // Segments change only for libmaxflow's listed nodes; fixed or freed nodes are relabelled ones.
    for (int* i = lg.Changed->ScanFirst(); i; i = lg.Changed->ScanNext())
    {
      g.remove_from_changed_list(*i);
      recheck(*i);
    }
    lg.Changed->Reset();
    for (const std::int64_t p : lg.Relabelled)
    {
      recheck(p);
    }
    lg.Relabelled.clear();
    lg.CostChanged.clear();
  }
  // The sink list without the nodes that left it.
  lg.SinkList.erase(std::remove_if(lg.SinkList.begin(), lg.SinkList.end(), [&](std::int64_t p) { return !lg.Sink[p]; }),
    lg.SinkList.end());
  switched = lg.SinkList;
  std::sort(switched.begin(), switched.end());
  return MoveChange(pr, alpha, label, around, switched, [&](std::int64_t q) { return lg.Sink[q] != 0; });
}
} // namespace

ExpansionResult AlphaExpansion(const PottsProblem& pr, std::vector<std::uint8_t> label, const ProgressFunction& progress,
  int maxCycles, RecycledMoves* recycled, const ParallelFor& parallel, ExpansionWorkspace* workspace)
{
  ExpansionResult r;
  double energy = 0.0;
  r.Error = Start(pr, label, parallel, energy);
  if (!r.Error.empty())
  {
    return r;
  }
  const std::int64_t n = pr.Nodes;
  const int L = pr.Labels;
  const std::int64_t m = pr.Edges->Size();
  try
  {
    RecycledMoves::State* kept = recycled ? SyncRecycled(*recycled, pr, label, parallel) : nullptr;
    ExpansionWorkspace own;
    ExpansionWorkspace::State* fresh = nullptr;
    if (!kept)
    {
      ExpansionWorkspace& w = workspace ? *workspace : own;
      if (!w.Kept)
      {
        w.Kept = std::make_unique<ExpansionWorkspace::State>();
      }
      fresh = w.Kept.get();
      const std::vector<std::int64_t>& rows = fresh->Around.First;
      if (w.GraphKey == 0 || fresh->AroundKey != w.GraphKey || static_cast<std::int64_t>(rows.size()) != n + 1 ||
        rows.back() != 2 * m)
      {
        fresh->AroundKey = 0; // until built
        fresh->Around.Build(pr);
      }
      fresh->AroundKey = w.GraphKey;
      if (!fresh->Graph)
      {
        fresh->Graph = std::make_unique<Flow>(static_cast<int>(n), static_cast<int>(m), ThrowOutOfMemory);
      }
    }
    const Neighbourhood& around = kept ? *kept->Around : fresh->Around;
    const int total = std::max(1, maxCycles) * L;
    std::vector<std::int64_t> switched;
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
        const double change = kept ? RecycledMove(pr, alpha, label, *kept, switched, parallel)
                                   : ExpansionMove(pr, alpha, label, around, *fresh->Graph, fresh->Buffers, switched);
        if (!switched.empty() && change < -1e-9 * std::max(1.0, std::fabs(energy)))
        {
          for (const std::int64_t p : switched)
          {
            label[p] = static_cast<std::uint8_t>(alpha);
          }
          if (kept)
          {
            for (const std::int64_t p : switched)
            {
              kept->Label[p] = static_cast<std::uint8_t>(alpha);
            }
            RecordRelabelled(*kept, switched);
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
    if (recycled)
    {
      recycled->Clear();
    }
    if (workspace)
    {
      workspace->Kept.reset();
    }
    r.Error = "not enough memory for the max-flow graph (" + std::to_string(n) + " nodes, " + std::to_string(m) + " edges).";
    return r;
  }
  r.Energy = PottsEnergy(pr, label, parallel); // summed afresh: the moves' changes carry rounding
  r.Label = std::move(label);
  return r;
}
} // namespace featuremesh
