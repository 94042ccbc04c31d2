#include "SeedGeodesics.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <mutex>
#include <queue>
#include <string>
#include <thread>
#include <utility>

namespace featuremesh
{
namespace
{
// Pops between progress checks.
constexpr std::int64_t CheckEvery = (std::int64_t(1) << 16) - 1;

// Neighbours of a node with the step to each, each entry a 32-bit neighbour id with its step as a
// float beside it (the cuts allow fewer than 2^31 nodes and edge ends): for explicit edges with at
// most four per node (a mesh's face neighbours) four slots per node in a 32-byte block, so a node's
// neighbours are one cache miss (Dijkstra pops nodes all over the graph); else CSR (two passes,
// count then insert); the grid's from the index. Either way in the order of the edges.
class Adjacency
{
public:
  Adjacency(const GraphEdges& edges, std::int64_t nodes, const SharedArray<double>& step)
  {
    if (edges.IsGrid())
    {
      const auto& d = edges.GridDims();
      this->Dims = { { d[0], d[1], d[2] } };
      return;
    }
    const std::int64_t m = edges.Size();
    std::vector<std::uint32_t> degree(nodes + 1, 0);
    for (std::int64_t e = 0; e < m; ++e)
    {
      ++degree[edges.First()[e] + 1];
      ++degree[edges.Second()[e] + 1];
    }
    this->Explicit = true;
    const auto length = [&](std::int64_t e) { return step.empty() ? 1.0f : static_cast<float>(step[e]); };
    if (*std::max_element(degree.begin(), degree.end()) <= Slots)
    {
      // Aligned to the block: a block never straddles two cache lines.
      this->Storage.assign(Slots * nodes + Slots, Neighbour{ None, 0.0f });
      const auto address = reinterpret_cast<std::uintptr_t>(this->Storage.data());
      this->First = (Slots - (address / sizeof(Neighbour)) % Slots) % Slots;
      Neighbour* block = this->Storage.data() + this->First;
      std::vector<std::uint8_t> filled(nodes, 0);
      for (std::int64_t e = 0; e < m; ++e)
      {
        const std::int64_t a = edges.First()[e], b = edges.Second()[e];
        block[Slots * a + filled[a]++] = Neighbour{ static_cast<std::uint32_t>(b), length(e) };
        block[Slots * b + filled[b]++] = Neighbour{ static_cast<std::uint32_t>(a), length(e) };
      }
      return;
    }
    for (std::int64_t p = 0; p < nodes; ++p)
    {
      degree[p + 1] += degree[p];
    }
    this->Offset = degree;
    this->Storage.resize(2 * m);
    std::vector<std::uint32_t>& next = degree; // each node's next free entry
    for (std::int64_t e = 0; e < m; ++e)
    {
      const std::int64_t a = edges.First()[e], b = edges.Second()[e];
      this->Storage[next[a]++] = Neighbour{ static_cast<std::uint32_t>(b), length(e) };
      this->Storage[next[b]++] = Neighbour{ static_cast<std::uint32_t>(a), length(e) };
    }
  }

  // Asks the cache for p's neighbours ahead of their use (Dijkstra, as it pushes p: the block is
  // then in cache when p pops, instead of one miss per pop).
  void Prefetch(std::int64_t p) const
  {
    if (this->Explicit && this->Offset.empty())
    {
      __builtin_prefetch(this->Storage.data() + this->First + Slots * p);
    }
  }
  // f(q, step) for every neighbour q of p.
  template <typename F>
  void ForEach(std::int64_t p, F&& f) const
  {
    if (!this->Explicit)
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
    const Neighbour* entry = this->Storage.data() + this->First;
    if (this->Offset.empty())
    {
      const Neighbour* block = entry + Slots * p;
      for (int s = 0; s < Slots && block[s].Node != None; ++s)
      {
        f(static_cast<std::int64_t>(block[s].Node), static_cast<double>(block[s].Step));
      }
      return;
    }
    for (std::uint32_t s = this->Offset[p]; s < this->Offset[p + 1]; ++s)
    {
      f(static_cast<std::int64_t>(entry[s].Node), static_cast<double>(entry[s].Step));
    }
  }

private:
  static constexpr int Slots = 4;
  static constexpr std::uint32_t None = 0xffffffffu;
  struct Neighbour
  {
    std::uint32_t Node;
    float Step;
  };
  std::array<std::int64_t, 3> Dims{ { 0, 0, 0 } };
  bool Explicit = false;
  std::vector<std::uint32_t> Offset; // CSR; empty with blocks of Slots
  std::vector<Neighbour> Storage;
  std::size_t First = 0; // the first entry in Storage
};

// A radix heap (Ahuja, Mehlhorn, Orlin & Tarjan 1990) of 8-byte entries, a 32-bit key above a
// 32-bit node: Dijkstra pops keys that never decrease, so an entry is filed by the highest bit in
// which its key differs from the last key popped, and each entry moves down at most 32 times
// instead of sifting through a binary heap's log n levels on every push and pop.
class RadixHeap
{
public:
  bool Empty() const { return this->Size == 0; }
  void Push(std::uint64_t entry)
  {
    this->Bucket[this->Index(entry >> 32)].push_back(entry);
    ++this->Size;
  }
  std::uint64_t Pop()
  {
    if (this->Bucket[0].empty())
    {
      int i = 1;
      while (this->Bucket[i].empty())
      {
        ++i;
      }
      std::vector<std::uint64_t>& from = this->Bucket[i];
      this->Last = static_cast<std::uint32_t>(*std::min_element(from.begin(), from.end()) >> 32);
      for (const std::uint64_t e : from)
      {
        this->Bucket[this->Index(e >> 32)].push_back(e);
      }
      from.clear();
    }
    const std::uint64_t e = this->Bucket[0].back();
    this->Bucket[0].pop_back();
    --this->Size;
    return e;
  }

private:
  int Index(std::uint64_t key) const
  {
    const std::uint32_t x = static_cast<std::uint32_t>(key) ^ this->Last;
    return x == 0 ? 0 : 32 - __builtin_clz(x);
  }
  std::array<std::vector<std::uint64_t>, 33> Bucket;
  std::uint32_t Last = 0;
  std::int64_t Size = 0;
};

// Distances from one kind of seeds, with the seed each node's shortest path starts from.
struct DistanceField
{
  SharedArray<double> Distance; // shared with the callers that asked for it, copied before a change
  std::vector<std::int32_t> Root;   // -1 unreachable (fewer than 2^31 nodes)
  // Kept fields only (a new scale rescales them): each node's shortest path as its two sums, the
  // intensity steps (image units) and the travel (the adjacency's float steps), its distance
  // Intensity / Scale + lengthWeight x Travel; a new scale weighs them again in one pass.
  bool KeepsSums = false;
  std::vector<double> Intensity, Travel;
  double Scale = 0.0;               // the intensity unit the distances are in
  // The nodes whose distance changed since Settle(), each once; or every node (AllChanged, also
  // before the first Settle()). Lets the costs made of a kept field be redone where it changed.
  std::vector<std::int64_t> Changed;
  std::vector<std::uint8_t> Marked;
  bool AllChanged = true;

  void Change(std::int64_t p)
  {
    if (!this->AllChanged && !this->Marked[p])
    {
      this->Marked[p] = 1;
      this->Changed.push_back(p);
    }
  }
  void ChangeAll()
  {
    this->AllChanged = true;
    std::vector<std::int64_t>().swap(this->Changed);
    std::vector<std::uint8_t>().swap(this->Marked);
  }
  // The nodes changed since the last Settle() (empty when AllChanged), handed over: changes are
  // recorded afresh from here on.
  std::vector<std::int64_t> Settle()
  {
    if (this->AllChanged)
    {
      this->Marked.assign(this->Distance.size(), 0);
    }
    for (std::int64_t p : this->Changed)
    {
      this->Marked[p] = 0;
    }
    this->AllChanged = false;
    return std::exchange(this->Changed, {});
  }
};

// Relaxes the edge p -> q (of length `step`) in `field` at `inverse` = 1 / scale: true when it
// shortens q's distance, which it then takes with p's root (and its sums, kept).
inline bool Relax(DistanceField& field, double* distance, const double* value, std::int64_t p, std::int64_t q, double step,
  double inverse, double lengthWeight)
{
  const double rise = std::fabs(value[q] - value[p]);
  if (!field.KeepsSums)
  {
    const double candidate = distance[p] + rise * inverse + lengthWeight * step;
    if (candidate < distance[q])
    {
      distance[q] = candidate;
      field.Root[q] = field.Root[p];
      return true;
    }
    return false;
  }
  const double intensity = field.Intensity[p] + rise, travel = field.Travel[p] + step;
  const double candidate = intensity * inverse + lengthWeight * travel;
  if (candidate < distance[q])
  {
    distance[q] = candidate;
    field.Root[q] = field.Root[p];
    field.Intensity[q] = intensity;
    field.Travel[q] = travel;
    return true;
  }
  return false;
}

// Dijkstra into `field` from `seeds` (distance 0) and from `start` (nodes whose distances `field`
// already holds); every other distance it holds must be exact for the seeds it came from, or
// infinite. A field without distances is filled with infinity first. False when progress asks to
// abort (`field` is then partial).
bool Dijkstra(const GeodesicGraph& g, const Adjacency& adjacency, const std::vector<std::int64_t>& seeds,
  const std::vector<std::int64_t>& start, double scale, double lengthWeight, DistanceField& field,
  const ProgressFunction& progress)
{
  const std::int64_t n = g.Nodes();
  const double* value = g.Value.data();
  if (field.Distance.empty())
  {
    field.ChangeAll();
    field.Distance = std::vector<double>(n, std::numeric_limits<double>::infinity());
    field.Root.assign(n, -1);
    if (field.KeepsSums)
    {
      field.Intensity.assign(n, 0.0);
      field.Travel.assign(n, 0.0);
    }
  }
  field.Scale = scale;
  double* distance = field.Distance.Mutable().data();
  // Heap entries of 8 bytes: the distance rounded up to a float (non-negative floats order as
  // their bits, and a longer path never rounds to a smaller key) above the node. Equal keys may
  // pop a node before its last improvement; it is then pushed and expanded again, so the
  // distances stay exact.
  auto key = [](double d, std::int64_t p) {
    const float f = static_cast<float>(d);
    std::uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    // The next float up is the next bit pattern (d >= 0; a float never rounds below FLT_MAX's).
    bits += static_cast<double>(f) < d ? 1u : 0u;
    return (static_cast<std::uint64_t>(bits) << 32) | static_cast<std::uint64_t>(p);
  };
  RadixHeap heap;
  for (std::int64_t p : seeds)
  {
    distance[p] = 0.0;
    field.Root[p] = static_cast<std::int32_t>(p);
    field.Change(p);
    if (field.KeepsSums)
    {
      field.Intensity[p] = 0.0;
      field.Travel[p] = 0.0;
    }
    heap.Push(key(0.0, p));
  }
  for (std::int64_t p : start)
  {
    heap.Push(key(distance[p], p));
  }
  const double inverse = 1.0 / scale;
  std::int64_t popped = 0;
  while (!heap.Empty())
  {
    const std::uint64_t top = heap.Pop();
    const std::int64_t p = static_cast<std::int64_t>(top & 0xffffffffu);
    const double d = distance[p];
    if ((top >> 32) != (key(d, p) >> 32))
    {
      continue; // an older entry of a node improved since
    }
    if ((++popped & CheckEvery) == 0 && !progress(std::min(1.0, static_cast<double>(popped) / static_cast<double>(n))))
    {
      return false;
    }
    adjacency.ForEach(p, [&](std::int64_t q, double step) {
      if (Relax(field, distance, value, p, q, step, inverse, lengthWeight))
      {
        adjacency.Prefetch(q); // in cache by the time q pops
        field.Change(q);
        heap.Push(key(distance[q], q));
      }
    });
  }
  return true;
}

// `field` (exact at field.Scale) made exact at `scale` for the same seeds. Each node's kept path is
// weighed again from its sums: an upper bound, exact where the path stays shortest. Then every node
// that some edge now shortens starts Dijkstra. False when progress asks to abort. A field without
// sums is emptied, to start afresh.
bool Rescale(const GeodesicGraph& g, const Adjacency& adjacency, double scale, double lengthWeight,
  DistanceField& field, const ProgressFunction& progress)
{
  const std::int64_t n = g.Nodes();
  if (!field.KeepsSums)
  {
    field = DistanceField();
    return true;
  }
  const double* value = g.Value.data();
  const double inverse = 1.0 / scale;
  field.ChangeAll();
  std::vector<double>& distance = field.Distance.Mutable();
  for (std::int64_t p = 0; p < n; ++p)
  {
    if (std::isfinite(distance[p]))
    {
      distance[p] = field.Intensity[p] * inverse + lengthWeight * field.Travel[p];
    }
  }
  // Then every node some edge now shortens starts Dijkstra, once.
  std::vector<std::int64_t> start;
  std::vector<std::uint64_t> queued((n + 63) / 64, 0);
  for (std::int64_t p = 0; p < n; ++p)
  {
    if (!std::isfinite(distance[p]))
    {
      continue;
    }
    adjacency.ForEach(p, [&](std::int64_t q, double step) {
      if (Relax(field, distance.data(), value, p, q, step, inverse, lengthWeight) && !((queued[q >> 6] >> (q & 63)) & 1u))
      {
        queued[q >> 6] |= std::uint64_t(1) << (q & 63);
        start.push_back(q);
      }
    });
  }
  return Dijkstra(g, adjacency, {}, start, scale, lengthWeight, field, progress);
}

// `field` (exact for the sorted seed nodes `before` at field.Scale, or empty) made exact for `after`
// at `scale`: a new scale first (Rescale); then nodes whose path started at a removed seed start
// again from their neighbours that kept theirs (removing seeds cannot shorten any other path),
// added seeds start at 0.
bool UpdateField(const GeodesicGraph& g, const Adjacency& adjacency, const std::vector<std::int64_t>& before,
  const std::vector<std::int64_t>& after, double scale, double lengthWeight, DistanceField& field,
  const ProgressFunction& progress)
{
  if (!field.Distance.empty() && field.Scale != scale &&
    !Rescale(g, adjacency, scale, lengthWeight, field, SubProgress(progress, 0.0, 0.5)))
  {
    return false;
  }
  if (field.Distance.empty())
  {
    return Dijkstra(g, adjacency, after, {}, scale, lengthWeight, field, progress);
  }
  std::vector<std::int64_t> removed, added, start;
  std::set_difference(before.begin(), before.end(), after.begin(), after.end(), std::back_inserter(removed));
  std::set_difference(after.begin(), after.end(), before.begin(), before.end(), std::back_inserter(added));
  if (!removed.empty())
  {
    std::vector<std::uint8_t> gone(g.Nodes(), 0);
    for (std::int64_t r : removed)
    {
      gone[r] = 1;
    }
    std::vector<std::int64_t> orphans;
    double* distance = field.Distance.Mutable().data();
    for (std::int64_t p = 0; p < g.Nodes(); ++p)
    {
      if (field.Root[p] >= 0 && gone[field.Root[p]])
      {
        distance[p] = std::numeric_limits<double>::infinity();
        field.Root[p] = -1;
        field.Change(p);
        orphans.push_back(p);
      }
    }
    const double inverse = 1.0 / scale;
    const double* value = g.Value.data();
    for (std::int64_t p : orphans)
    {
      adjacency.ForEach(p, [&](std::int64_t q, double step) {
        if (field.Root[q] >= 0)
        {
          Relax(field, distance, value, q, p, step, inverse, lengthWeight);
        }
      });
      if (field.Root[p] >= 0)
      {
        start.push_back(p);
      }
    }
  }
  return Dijkstra(g, adjacency, added, start, scale, lengthWeight, field, progress);
}

double UsableScale(double scale)
{
  return scale > 0.0 && std::isfinite(scale) ? scale : 1.0;
}

std::vector<std::int64_t> SeedNodes(const std::vector<std::uint8_t>& hard, std::uint8_t kind)
{
  std::vector<std::int64_t> seeds;
  for (std::int64_t p = 0; p < static_cast<std::int64_t>(hard.size()); ++p)
  {
    if (hard[p] == kind)
    {
      seeds.push_back(p);
    }
  }
  return seeds;
}

// The seed nodes of each kind 1..kinds, ascending, from one pass over `hard`.
std::vector<std::vector<std::int64_t>> SeedNodesOfKinds(const std::vector<std::uint8_t>& hard, int kinds)
{
  std::vector<std::vector<std::int64_t>> seeds(kinds);
  for (std::int64_t p = 0; p < static_cast<std::int64_t>(hard.size()); ++p)
  {
    if (hard[p] >= 1 && hard[p] <= kinds)
    {
      seeds[hard[p] - 1].push_back(p);
    }
  }
  return seeds;
}

// What the first `kinds` fields changed since the last call; a kept record's fields then record
// afresh, a fresh record (no cache) changed All.
SeedDistanceChanges TakeChanges(std::vector<DistanceField>& fields, int kinds, bool kept)
{
  SeedDistanceChanges changes;
  changes.All = !kept;
  for (int k = 0; k < kinds; ++k)
  {
    changes.All = changes.All || fields[k].AllChanged;
  }
  for (int k = 0; k < kinds && kept; ++k)
  {
    changes.Nodes.push_back(fields[k].Settle());
  }
  if (changes.All)
  {
    changes.Nodes.clear();
  }
  return changes;
}
} // namespace

struct SeedGeodesicCache::Kept
{
  GraphEdges Edges;
  SharedArray<double> Value, Step; // shared with the cut's problem
  double LengthWeight = 0.0;
  // Depends on the graph alone: kept across a change of length weight. Each field keeps its own
  // scale and is rescaled to a new one (a seed sample beyond the range moves it).
  std::shared_ptr<const Adjacency> Neighbours;
  // Per seed kind (index kind - 1).
  std::vector<std::vector<std::int64_t>> Seeds;
  std::vector<DistanceField> Field;
  // SeedGeodesicCosts' costs at CostWeight, of the first two fields as they were at their Settle().
  SharedArray<double> CostObject, CostBackground;
  double CostWeight = -1.0;

  bool SameGraph(const GeodesicGraph& g) const
  {
    return this->Edges.Same(*g.Edges) && this->Value == g.Value && this->Step == g.Step;
  }
};

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
  const Adjacency adjacency(*graph.Edges, graph.Nodes(), graph.Step);
  DistanceField field;
  if (!Dijkstra(graph, adjacency, SeedNodes(hard, seedKind), {}, UsableScale(scale), lengthWeight, field, progress))
  {
    return {};
  }
  return std::move(field.Distance.Mutable());
}

// With the graph copied when there is a cache, and `kinds` fields at least.
std::shared_ptr<SeedGeodesicCache::Kept> SeedGeodesicCache::Take(const GeodesicGraph& graph, double lengthWeight, int kinds,
  SeedGeodesicCache* cache)
{
  std::shared_ptr<SeedGeodesicCache::Kept> kept = cache ? cache->State : nullptr;
  const bool sameGraph = kept && kept->SameGraph(graph);
  if (!sameGraph || kept->LengthWeight != lengthWeight)
  {
    std::shared_ptr<const Adjacency> neighbours =
      sameGraph ? kept->Neighbours : std::make_shared<const Adjacency>(*graph.Edges, graph.Nodes(), graph.Step);
    kept = std::make_shared<SeedGeodesicCache::Kept>();
    kept->Neighbours = std::move(neighbours);
    if (cache)
    {
      kept->Edges = graph.Edges->Keepable();
      kept->Value = graph.Value;
      kept->Step = graph.Step;
      kept->LengthWeight = lengthWeight;
    }
  }
  if (static_cast<int>(kept->Field.size()) < kinds)
  {
    kept->Field.resize(kinds);
    kept->Seeds.resize(kinds);
  }
  for (DistanceField& field : kept->Field)
  {
    field.KeepsSums = field.KeepsSums || cache != nullptr;
  }
  if (cache)
  {
    cache->State.reset();
  }
  return kept;
}

namespace
{
// `run(i, progress)` for i in [0, count) on `parallel`'s threads, started from a helper thread while
// this one reports the runs' mean progress every 50 ms over [0, 0.9] (VTK 9.2's STDThread backend
// does not run a loop on the calling thread, so a run there could not report) and, when progress asks to
// abort, makes every run's progress return false; false then. A run's progress is called on the
// thread it runs on and must only record. What the runs throw is rethrown here. A single run runs
// on this thread and reports through `progress` itself.
bool RunReportingHere(std::int64_t count, const ParallelFor& parallel, const ProgressFunction& progress,
  const std::function<bool(std::int64_t, const ProgressFunction&)>& run)
{
  if (count == 1)
  {
    // One run (a seed edit of one kind): on this thread, reporting itself, with no thread to start.
    return run(0, [&](double t) { return progress(0.9 * t); }) && progress(0.9);
  }
  std::unique_ptr<std::atomic<double>[]> fraction(new std::atomic<double>[count]);
  for (std::int64_t i = 0; i < count; ++i)
  {
    fraction[i] = 0.0;
  }
  std::atomic<bool> abort{ false };
  std::mutex lock;
  std::condition_variable done;
  bool finished = false;
  std::exception_ptr error;
  const auto keep = [&](std::exception_ptr e) {
    std::lock_guard<std::mutex> guard(lock);
    error = error ? error : e;
    abort = true;
  };
  std::thread helper([&]() {
    try
    {
      parallel(count, 1, [&](std::int64_t b, std::int64_t e) {
        for (std::int64_t i = b; i < e && !abort; ++i)
        {
          // Caught here: an exception must not leave a thread of the SMP backend.
          try
          {
            run(i, [&, i](double t) {
              fraction[i] = t;
              return !abort;
            });
          }
          catch (...)
          {
            keep(std::current_exception());
          }
        }
      });
    }
    catch (...)
    {
      keep(std::current_exception());
    }
    std::lock_guard<std::mutex> guard(lock);
    finished = true;
    done.notify_all();
  });
  std::unique_lock<std::mutex> wait(lock);
  while (!done.wait_for(wait, std::chrono::milliseconds(50), [&] { return finished; }))
  {
    wait.unlock();
    double sum = 0.0;
    for (std::int64_t i = 0; i < count; ++i)
    {
      sum += fraction[i];
    }
    if (!abort && !progress(0.9 * sum / static_cast<double>(count)))
    {
      abort = true;
    }
    wait.lock();
  }
  wait.unlock();
  helper.join();
  if (error)
  {
    std::rethrow_exception(error);
  }
  return !abort && progress(0.9);
}

// The kept distances of kinds 1..seeds.size() made exact for these seed nodes: kinds whose seeds
// changed are updated side by side on `parallel`'s threads from a helper thread while this one
// reports progress over [0, 0.9] (RunReportingHere). False when progress asks to abort.
bool UpdateKinds(const GeodesicGraph& graph, std::vector<std::vector<std::int64_t>> seeds, double scale,
  double lengthWeight, const ParallelFor& parallel, const ProgressFunction& progress, SeedGeodesicCache::Kept& kept)
{
  std::vector<int> update;
  for (int k = 0; k < static_cast<int>(seeds.size()); ++k)
  {
    if (kept.Seeds[k] != seeds[k] || kept.Field[k].Distance.empty() || kept.Field[k].Scale != scale)
    {
      update.push_back(k);
    }
  }
  const auto run = [&](std::int64_t i, const ProgressFunction& report) {
    const int k = update[i];
    return UpdateField(graph, *kept.Neighbours, kept.Seeds[k], seeds[k], scale, lengthWeight, kept.Field[k], report);
  };
  const std::int64_t count = static_cast<std::int64_t>(update.size());
  if (count == 0 ? !progress(0.9) : !RunReportingHere(count, parallel, progress, run))
  {
    return false;
  }
  for (std::size_t k = 0; k < seeds.size(); ++k)
  {
    kept.Seeds[k] = std::move(seeds[k]);
  }
  return true;
}
} // namespace

std::vector<SharedArray<double>> SeedKindDistances(const GeodesicGraph& graph, const std::vector<std::uint8_t>& hard,
  int kinds, double scale, double lengthWeight, const ProgressFunction& progress, SeedGeodesicCache* cache,
  const ParallelFor& parallel, SeedDistanceChanges* changes)
{
  scale = UsableScale(scale);
  std::shared_ptr<SeedGeodesicCache::Kept> kept = SeedGeodesicCache::Take(graph, lengthWeight, kinds, cache);
  std::vector<std::vector<std::int64_t>> seeds = SeedNodesOfKinds(hard, kinds);
  if (!UpdateKinds(graph, std::move(seeds), scale, lengthWeight, parallel, progress, *kept))
  {
    return {};
  }
  std::vector<SharedArray<double>> distance(kinds);
  for (int k = 0; k < kinds; ++k)
  {
    distance[k] = kept->Field[k].Distance;
  }
  if (changes)
  {
    *changes = TakeChanges(kept->Field, kinds, cache != nullptr);
  }
  if (cache)
  {
    cache->State = kept;
  }
  return distance;
}

bool SeedGeodesicCosts(const GeodesicGraph& graph, const std::vector<std::uint8_t>& hard, double scale,
  const SeedGeodesicParameters& par, const ParallelFor& parallel, SharedArray<double>& costObject,
  SharedArray<double>& costBackground, const ProgressFunction& progress, SeedGeodesicCache* cache)
{
  costObject = SharedArray<double>();
  costBackground = SharedArray<double>();
  std::vector<std::vector<std::int64_t>> seeds = SeedNodesOfKinds(hard, 2);
  if (par.Weight <= 0.0 || seeds[0].empty() || seeds[1].empty() || graph.Nodes() == 0)
  {
    return true;
  }
  scale = UsableScale(scale);
  std::shared_ptr<SeedGeodesicCache::Kept> kept = SeedGeodesicCache::Take(graph, par.LengthWeight, 2, cache);
  if (!UpdateKinds(graph, std::move(seeds), scale, par.LengthWeight, parallel, progress, *kept))
  {
    return false;
  }
  // Each node's costs from its two distances, redone where either changed.
  const std::vector<double>& toObject = kept->Field[0].Distance.Vector();
  const std::vector<double>& toBackground = kept->Field[1].Distance.Vector();
  std::vector<double>& keptObject = kept->CostObject.Mutable();
  std::vector<double>& keptBackground = kept->CostBackground.Mutable();
  constexpr double mix = 0.01;
  const auto cost = [&](std::int64_t p) {
    const double dO = toObject[p], dB = toBackground[p];
    // Unreachable from both (a separate component): no preference.
    double object = 0.5;
    if (std::isfinite(dO) || std::isfinite(dB))
    {
      object = !std::isfinite(dB) ? 1.0 : (!std::isfinite(dO) ? 0.0 : (dO + dB > 0.0 ? dB / (dO + dB) : 0.5));
    }
    keptObject[p] = -par.Weight * std::log(mix + (1.0 - 2.0 * mix) * object);
    keptBackground[p] = -par.Weight * std::log(mix + (1.0 - 2.0 * mix) * (1.0 - object));
  };
  const std::int64_t n = graph.Nodes();
  const SeedDistanceChanges changes = TakeChanges(kept->Field, 2, cache != nullptr);
  if (changes.All || kept->CostWeight != par.Weight || static_cast<std::int64_t>(keptObject.size()) != n)
  {
    keptObject.resize(n);
    keptBackground.resize(n);
    parallel(n, 65536, [&](std::int64_t p0, std::int64_t p1) {
      for (std::int64_t p = p0; p < p1; ++p)
      {
        cost(p);
      }
    });
  }
  else
  {
    ForEachChangedNode(changes, parallel, cost);
  }
  kept->CostWeight = par.Weight;
  costObject = kept->CostObject;
  costBackground = kept->CostBackground;
  if (cache)
  {
    cache->State = kept;
  }
  return progress(1.0);
}
} // namespace featuremesh
