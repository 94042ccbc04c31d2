#include "VoxelRefinement.h"
#include "FlowGraph.h"
#include "Memory.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <exception>
#include <memory>
#include <numeric>
#include <stdexcept>

namespace featuremesh
{
namespace
{
using Clock = std::chrono::steady_clock;
using Flow = FlowGraph;

// A two-label problem's max-flow graphs (label 1 on the source side). Its face-connected components
// are dealt to two graphs, solved side by side, unless one holds more than three quarters of the
// nodes (then all lie on the first); each node's graph and id in it; the costs the graphs hold.
struct BinaryGraphs
{
  std::array<std::unique_ptr<Flow>, 2> Graph;
  std::vector<std::uint8_t> Side;
  std::vector<std::int32_t> Local;
  std::array<std::int32_t, 2> Nodes{ { 0, 0 } };
  std::vector<double> Cost; // node i's cost of label 0 at 2 i, of label 1 at 2 i + 1
};

void DealComponents(std::int64_t n, const GraphEdges& edges, BinaryGraphs& g)
{
  std::int64_t count = 0;
  const std::vector<std::int64_t> component = LabelComponents(std::vector<std::uint8_t>(n, 0), edges, count);
  std::vector<std::int64_t> size(count, 0);
  for (std::int64_t c : component)
  {
    ++size[c];
  }
  const bool apart = count > 1 && 4 * *std::max_element(size.begin(), size.end()) <= 3 * n;
  std::vector<std::uint8_t> side(count, 0);
  std::array<std::int64_t, 2> load{ { 0, 0 } };
  for (std::int64_t c = 0; c < count && apart; ++c)
  {
    side[c] = load[1] < load[0] ? 1 : 0;
    load[side[c]] += size[c];
  }
  g.Side.resize(n);
  g.Local.resize(n);
  g.Nodes = { { 0, 0 } };
  for (std::int64_t i = 0; i < n; ++i)
  {
    g.Side[i] = side[component[i]];
    g.Local[i] = g.Nodes[g.Side[i]]++;
  }
}

// Nodes appended to a one-graph problem solved before (from `first` on, on the first graph) with
// the edges from `firstEdge` on; each edge's ends marked for the next flow to run on.
void ExtendGraph(BinaryGraphs& g, std::int64_t first, std::int64_t n, const GraphEdges& edges, std::int64_t firstEdge,
  const std::vector<double>& weight)
{
  Flow& graph = *g.Graph[0];
  if (n > first)
  {
    graph.add_node(static_cast<int>(n - first));
  }
  g.Side.resize(n, 0);
  g.Local.resize(n);
  for (std::int64_t i = first; i < n; ++i)
  {
    g.Local[i] = g.Nodes[0]++;
  }
  g.Cost.resize(2 * n, 0.0); // a new node's terminal capacities are 0
  const std::int64_t* a = edges.First();
  const std::int64_t* b = edges.Second();
  for (std::int64_t e = firstEdge; e < edges.Size(); ++e)
  {
    graph.add_edge(g.Local[a[e]], g.Local[b[e]], weight[e], weight[e]);
    graph.mark_node(g.Local[a[e]]);
    graph.mark_node(g.Local[b[e]]);
  }
}

// The max-flows of `cost` (node i's label 0 at 2 i, label 1 at 2 i + 1): on fresh graphs of the
// edges' weights, or (reuse) on the kept graphs, their terminal capacities moved to `cost` and each
// flow run on from the last (Kohli & Torr; edges added since, ExtendGraph). A node takes label 1 unless it
// reaches the sink in the final residual graph, which every maximum flow leaves the same. Returns
// the flow.
double SolveGraphs(std::vector<double> cost, const GraphEdges& edges, const std::vector<double>& weight,
  BinaryGraphs& g, bool reuse, std::vector<std::uint8_t>& label, const ParallelFor& parallel)
{
  const std::int64_t n = static_cast<std::int64_t>(g.Side.size());
  std::array<double, 2> energy{ { 0.0, 0.0 } };
  label.resize(n);
  const auto cut = [&](int s) {
    std::unique_ptr<Flow>& kept = g.Graph[s];
    if (!reuse)
    {
      // A kept graph grows as libmaxflow's do; a new one is made for this problem's share.
      if (!kept)
      {
        const std::int64_t m = edges.Size() * g.Nodes[s] / std::max<std::int64_t>(n, 1);
        kept = std::make_unique<Flow>(g.Nodes[s], static_cast<int>(m), ThrowOutOfMemory);
      }
      kept->reset();
      kept->add_node(g.Nodes[s]);
      for (std::int64_t i = 0; i < n; ++i)
      {
        if (g.Side[i] == s)
        {
          // A node on the sink side (label 0) pays its source capacity.
          kept->add_tweights(g.Local[i], cost[2 * i], cost[2 * i + 1]);
        }
      }
      edges.ForEach([&](std::int64_t e, std::int64_t a, std::int64_t b) {
        if (g.Side[a] == s)
        {
          kept->add_edge(g.Local[a], g.Local[b], weight[e], weight[e]);
        }
      });
    }
    else
    {
      for (std::int64_t i = 0; i < n; ++i)
      {
        const double ds = g.Side[i] == s ? cost[2 * i] - g.Cost[2 * i] : 0.0;
        const double dt = g.Side[i] == s ? cost[2 * i + 1] - g.Cost[2 * i + 1] : 0.0;
        if (ds != 0.0 || dt != 0.0)
        {
          // Only a node whose terminal residual changes sign (or leaves or reaches 0) needs its
          // search tree redone.
          const double before = kept->get_trcap(g.Local[i]);
          kept->add_tweights(g.Local[i], ds, dt);
          const double after = kept->get_trcap(g.Local[i]);
          if ((before > 0) != (after > 0) || (before < 0) != (after < 0))
          {
            kept->mark_node(g.Local[i]);
          }
        }
      }
    }
    energy[s] = kept->maxflow(reuse);
    for (std::int64_t i = 0; i < n; ++i)
    {
      if (g.Side[i] == s)
      {
        label[i] = kept->what_segment(g.Local[i]) == Flow::SOURCE ? 1 : 0;
      }
    }
  };
  if (g.Nodes[1] == 0)
  {
    cut(0);
  }
  else
  {
    // Out of memory on a worker thread is rethrown on the caller's.
    std::array<std::exception_ptr, 2> error;
    parallel(2, 1, [&](std::int64_t s0, std::int64_t s1) {
      for (std::int64_t s = s0; s < s1; ++s)
      {
        try
        {
          cut(static_cast<int>(s));
        }
        catch (...)
        {
          error[s] = std::current_exception();
        }
      }
    });
    for (const std::exception_ptr& e : error)
    {
      if (e)
      {
        std::rethrow_exception(e);
      }
    }
  }
  g.Cost = std::move(cost); // kept for the next flow's terminal changes
  return energy[0] + energy[1];
}

// Elements within `rings` face steps of an element of another label, seed elements left out, and
// per element the labels within rings face steps of it (bit l; all ones beyond 64 labels).
void BandElements(const VoxelRefinementProblem& p, const FaceAdjacency& faces, std::vector<std::uint8_t>& band,
  std::vector<std::uint64_t>& near)
{
  const std::vector<std::uint8_t>& label = *p.Label;
  const std::int64_t n = static_cast<std::int64_t>(label.size());
  band.assign(n, 0);
  // Through the elements' own faces: every face between two labels has an end of a label other
  // than 0, and each ring adds the band's face neighbours.
  const std::vector<std::int32_t>& faceOf = p.Mesh->ElementFaces();
  const int vpc = p.Mesh->VerticesPerCell();
  const auto other = [&](std::int64_t e, std::int32_t f) { return faces.A[f] == e ? faces.B[f] : faces.A[f]; };
  for (std::int64_t e = 0; e < n; ++e)
  {
    if (!label[e])
    {
      continue;
    }
    for (int k = 0; k < vpc; ++k)
    {
      const std::int32_t f = faceOf[e * vpc + k];
      if (f >= 0 && label[other(e, f)] != label[e])
      {
        band[e] = band[other(e, f)] = 1;
      }
    }
  }
  for (int r = 1; r < p.Rings; ++r)
  {
    std::vector<std::uint8_t> grown = band;
    for (std::int64_t e = 0; e < n; ++e)
    {
      if (!band[e])
      {
        continue;
      }
      for (int k = 0; k < vpc; ++k)
      {
        const std::int32_t f = faceOf[e * vpc + k];
        if (f >= 0)
        {
          grown[other(e, f)] = 1;
        }
      }
    }
    band.swap(grown);
  }
  for (std::int64_t e = 0; e < n && !p.Fixed.empty(); ++e)
  {
    band[e] = band[e] && !p.Fixed[e];
  }
  // Two labels need no restriction.
  if (p.Labels == 2)
  {
    return;
  }
  near.assign(n, ~std::uint64_t(0));
  if (p.Labels > 64)
  {
    return;
  }
  for (std::int64_t e = 0; e < n; ++e)
  {
    near[e] = std::uint64_t(1) << label[e];
  }
  for (int r = 0; r < p.Rings; ++r)
  {
    std::vector<std::uint64_t> grown = near;
    for (std::size_t f = 0; f < faces.A.size(); ++f)
    {
      grown[faces.A[f]] |= near[faces.B[f]];
      grown[faces.B[f]] |= near[faces.A[f]];
    }
    near.swap(grown);
  }
}

// The band's voxels, each element's found among the voxel centres of its bounding box (an element
// owns centres it contains only; fixed chunks of elements in parallel).
std::vector<std::int64_t> BandVoxels(const SimplexMesh& mesh, const VoxelOwnerMap& owner,
  const std::vector<std::uint8_t>& band, const ParallelFor& parallel)
{
  std::vector<std::int64_t> elements;
  for (std::int64_t e = 0; e < static_cast<std::int64_t>(band.size()); ++e)
  {
    if (band[e])
    {
      elements.push_back(e);
    }
  }
  const ImageGeometry& g = mesh.Geometry();
  constexpr std::int64_t chunk = 1024;
  const std::int64_t chunks = (static_cast<std::int64_t>(elements.size()) + chunk - 1) / chunk;
  std::vector<std::vector<std::int64_t>> found(chunks);
  parallel(chunks, 1, [&](std::int64_t c0, std::int64_t c1) {
    for (std::int64_t c = c0; c < c1; ++c)
    {
      const std::int64_t last = std::min(static_cast<std::int64_t>(elements.size()), (c + 1) * chunk);
      for (std::int64_t k = c * chunk; k < last; ++k)
      {
        ForEachVoxelOf(mesh, owner, elements[k], [&](std::int64_t v) { found[c].push_back(v); });
      }
    }
  });
  // By slice (2D: by row), keeping the elements' order within one: a voxel's neighbours then lie
  // within three slices of the image's arrays, which stay in cache.
  const std::int64_t slice = g.Is2D() ? g.Dims[0] : g.SliceStride();
  const std::int64_t slices = g.Size() / slice;
  std::vector<std::int64_t> start(slices + 1, 0);
  for (const std::vector<std::int64_t>& f : found)
  {
    for (std::int64_t v : f)
    {
      ++start[v / slice + 1];
    }
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::int64_t> voxels(start.back());
  for (const std::vector<std::int64_t>& f : found)
  {
    for (std::int64_t v : f)
    {
      voxels[start[v / slice]++] = v;
    }
  }
  return voxels;
}

// Which face neighbours voxel v has on the grid: bit 2 d for +axis d, 2 d + 1 for -axis d.
unsigned GridSides(const ImageGeometry& g, std::int64_t v)
{
  const std::array<int, 3> ijk = g.Coordinates(v);
  unsigned sides = 0;
  for (int d = 0; d < 3; ++d)
  {
    sides |= (ijk[d] + 1 < g.Dims[d] ? 1u : 0u) << (2 * d);
    sides |= (ijk[d] > 0 ? 1u : 0u) << (2 * d + 1);
  }
  return sides;
}

// The kept domain's voxels and what lies around them: the band's voxels, and those held at their
// elements' labels (Held).
struct Band
{
  const VoxelRefinementProblem& P;
  const ImageGeometry& G;
  const std::vector<std::int64_t>& Voxel;
  std::vector<std::uint64_t> Around; // per voxel: the labels of its neighbours outside the domain (bit l, l < 64)
  const std::vector<std::int32_t>& Index; // the domain's index map (State::Index), from voxel IndexFirst on
  std::int64_t IndexFirst;
  const std::vector<std::uint8_t>& Sides;  // per voxel: its GridSides (DescribeDomain)
  const std::vector<std::int32_t>& Element; // per voxel: its element (-1 none)
  std::vector<std::uint8_t> Held, Own;    // per voxel: held, and its element's label (ReadElements)
  std::int64_t Stride[3];
  int Axes;

  Band(const VoxelRefinementProblem& p, const std::vector<std::int64_t>& voxels, const std::vector<std::int32_t>& index,
    std::int64_t indexFirst, const std::vector<std::uint8_t>& sides, const std::vector<std::int32_t>& element)
    : P(p)
    , G(p.Mesh->Geometry())
    , Voxel(voxels)
    , Around(Voxel.size(), 0)
    , Index(index)
    , IndexFirst(indexFirst)
    , Sides(sides)
    , Element(element)
    , Held(Voxel.size(), 0)
    , Own(Voxel.size(), 0)
    , Stride{ 1, G.Dims[0], G.SliceStride() }
    , Axes(G.Is2D() ? 2 : 3)
  {
  }
  // Each voxel's element label, and whether its element lies outside the band (it is held); the
  // band's voxel count. Fixed chunks of voxels in parallel.
  std::int64_t ReadElements(const std::vector<std::uint8_t>& bandElement)
  {
    constexpr std::int64_t chunk = 16384;
    const std::int64_t n = this->Size(), chunks = (n + chunk - 1) / chunk;
    std::vector<std::int64_t> free(chunks, 0);
    this->P.Parallel(chunks, 1, [&](std::int64_t c0, std::int64_t c1) {
      for (std::int64_t c = c0; c < c1; ++c)
      {
        for (std::int64_t i = c * chunk; i < std::min(n, (c + 1) * chunk); ++i)
        {
          const std::int32_t e = this->Element[i];
          this->Own[i] = this->LabelOf(e);
          this->Held[i] = e < 0 || !bandElement[e];
          free[c] += !this->Held[i];
        }
      }
    });
    return std::accumulate(free.begin(), free.end(), std::int64_t(0));
  }
  Band(const Band&) = delete;
  Band& operator=(const Band&) = delete;
  std::int64_t Size() const { return static_cast<std::int64_t>(this->Voxel.size()); }
  std::uint8_t LabelOf(std::int32_t e) const { return e >= 0 ? (*this->P.Label)[e] : std::uint8_t(0); }
  std::uint8_t ElementLabel(std::int64_t v) const { return this->LabelOf((*this->P.Owner)[v]); }
  // The domain index of voxel u, -1 outside the domain.
  std::int64_t Find(std::int64_t u) const
  {
    const std::uint64_t k = static_cast<std::uint64_t>(u - this->IndexFirst);
    return k < this->Index.size() ? this->Index[k] : -1;
  }
  bool IsHeld(std::int64_t i) const { return this->Held[i] != 0; }
  // f(u, forward) for every face neighbour u of voxel v; `border` is set when v lies on the image's border.
  template <typename F>
  void Neighbours(std::int64_t v, F&& f, bool* border = nullptr) const
  {
    this->VisitSides(v, GridSides(this->G, v), f, border);
  }
  // Neighbours() of the domain's voxel i, from its Sides instead of its coordinates.
  template <typename F>
  void DomainNeighbours(std::int64_t i, F&& f, bool* border = nullptr) const
  {
    this->VisitSides(this->Voxel[i], this->Sides[i], f, border);
  }
  // f(u, forward) for the face neighbours of voxel v that `sides` (GridSides) names.
  template <typename F>
  void VisitSides(std::int64_t v, unsigned sides, F& f, bool* border) const
  {
    for (int d = 0; d < this->Axes; ++d)
    {
      if ((sides >> (2 * d)) & 1u)
      {
        f(v + this->Stride[d], true);
      }
      else if (border)
      {
        *border = true;
      }
      if ((sides >> (2 * d + 1)) & 1u)
      {
        f(v - this->Stride[d], false);
      }
      else if (border)
      {
        *border = true;
      }
    }
  }
  // Whether the domain's voxel i lies on the image's border.
  bool OnBorder(std::int64_t i) const { return this->Sides[i] != (1u << (2 * this->Axes)) - 1u; }
};

// The band's voxel faces with their Potts weights, and per voxel its faces to voxels outside the
// band (neighbour, weight) in compressed rows: they depend on the image alone.
struct BandFaces
{
  std::vector<std::int64_t> A, B, OutFirst, OutVoxel;
  std::vector<std::int32_t> OutElement; // each outside voxel's element (-1 none)
  std::vector<double> W, OutWeight;
};

// The faces of the band's voxels from index `first` on: all of them (0), or those appended to a kept
// domain, whose faces to the voxels before become edges (those voxels' entries for them marked -1).
// Fixed chunks of voxels in parallel, joined in chunk order.
void BuildBandFaces(const Band& band, std::int64_t first, BandFaces& f)
{
  const VoxelRefinementProblem& p = band.P;
  const std::int64_t nb = band.Size();
  const double inv2s2 = 1.0 / (2.0 * p.Sigma * p.Sigma);
  constexpr std::int64_t chunk = 8192;
  const std::int64_t chunks = (nb - first + chunk - 1) / chunk;
  struct Part
  {
    std::vector<std::int64_t> A, B, OutVoxel;
    std::vector<std::int32_t> OutElement;
    std::vector<double> W, OutWeight;
  };
  std::vector<Part> parts(chunks);
  if (first == 0)
  {
    // Emptied, their memory kept.
    for (std::vector<std::int64_t>* list : { &f.A, &f.B, &f.OutFirst, &f.OutVoxel })
    {
      list->clear();
    }
    f.W.clear();
    f.OutWeight.clear();
    f.OutElement.clear();
    f.OutFirst.push_back(0);
  }
  f.OutFirst.resize(nb + 1, 0);
  p.Parallel(chunks, 1, [&](std::int64_t c0, std::int64_t c1) {
    for (std::int64_t c = c0; c < c1; ++c)
    {
      Part& part = parts[c];
      const std::int64_t last = std::min(nb, first + (c + 1) * chunk);
      for (std::int64_t i = first + c * chunk; i < last; ++i)
      {
        const std::int64_t v = band.Voxel[i];
        band.DomainNeighbours(i, [&](std::int64_t u, bool) {
          const std::int64_t j = band.Find(u);
          if (j >= first && j < i)
          {
            return; // the pair's edge comes from j
          }
          const double d2 = p.Distance2(v, u);
          const double w = d2 == 0.0 ? 1.0 : std::exp(-d2 * inv2s2);
          if (j < 0)
          {
            part.OutVoxel.push_back(u);
            part.OutElement.push_back((*p.Owner)[u]);
            part.OutWeight.push_back(w);
            ++f.OutFirst[i + 1];
            return;
          }
          if (j < first)
          {
            // v lay outside the domain for j: their face is an edge now (each pair once, so no
            // two threads write one entry).
            for (std::int64_t k = f.OutFirst[j]; k < f.OutFirst[j + 1]; ++k)
            {
              f.OutVoxel[k] = f.OutVoxel[k] == v ? -1 : f.OutVoxel[k];
            }
          }
          part.A.push_back(i);
          part.B.push_back(j);
          part.W.push_back(w);
        });
      }
    }
  });
  for (Part& part : parts)
  {
    f.A.insert(f.A.end(), part.A.begin(), part.A.end());
    f.B.insert(f.B.end(), part.B.begin(), part.B.end());
    f.W.insert(f.W.end(), part.W.begin(), part.W.end());
    f.OutVoxel.insert(f.OutVoxel.end(), part.OutVoxel.begin(), part.OutVoxel.end());
    f.OutElement.insert(f.OutElement.end(), part.OutElement.begin(), part.OutElement.end());
    f.OutWeight.insert(f.OutWeight.end(), part.OutWeight.begin(), part.OutWeight.end());
  }
  std::partial_sum(f.OutFirst.begin() + first, f.OutFirst.end(), f.OutFirst.begin() + first);
}

// Each domain voxel's cost of every label (voxel i's label l at i * Labels + l): P.Cost, a label no
// element near its element's has priced out, then the weight of each face to a voxel outside the
// domain whose element's label differs (those labels recorded in Around). A held voxel pays 0 for
// its element's label and more than all its faces' weights (each at most 1) for any other (the
// expansion also makes it a hard node). Fixed chunks of voxels in parallel.
void BandCosts(Band& band, const BandFaces& f, const std::vector<std::uint64_t>& near, std::vector<double>& cost)
{
  const VoxelRefinementProblem& p = band.P;
  const int L = p.Labels;
  const std::int64_t nb = band.Size();
  cost.resize(nb * L);
  const double hold = 2.0 * band.Axes + 1.0;
  constexpr double excluded = 1e9;
  constexpr std::int64_t chunk = 8192;
  p.Parallel((nb + chunk - 1) / chunk, 1, [&](std::int64_t c0, std::int64_t c1) {
    for (std::int64_t i = c0 * chunk; i < std::min(nb, c1 * chunk); ++i)
    {
      const std::int64_t v = band.Voxel[i], e = band.Element[i];
      double* c = &cost[i * L];
      band.Around[i] = 0;
      if (band.IsHeld(i))
      {
        const std::uint8_t held = band.Own[i];
        for (int l = 0; l < L; ++l)
        {
          c[l] = l == held ? 0.0 : hold;
        }
        continue;
      }
      p.Cost(v, e, c);
      for (int l = 0; l < L && L > 2; ++l)
      {
        c[l] += ((near[e] >> (l & 63)) & 1u) ? 0.0 : excluded;
      }
      for (std::int64_t k = f.OutFirst[i]; k < f.OutFirst[i + 1]; ++k)
      {
        if (f.OutVoxel[k] < 0)
        {
          continue; // a face into the domain since it grew (ExtendBandFaces)
        }
        const std::uint8_t held = band.LabelOf(f.OutElement[k]);
        band.Around[i] |= held < 64 ? std::uint64_t(1) << held : 0;
        for (int l = 0; l < L; ++l)
        {
          c[l] += l == held ? 0.0 : f.OutWeight[k];
        }
      }
    }
  });
}

// The cut's connectivity rule on the refined voxels: a piece of the band (voxels of one label,
// face-connected) that reaches no voxel of its label outside the band holds no seed of it (the
// seeds' elements stay out of the band); it takes the label it shares most voxel faces with. With
// Fill Holes only background pieces that touch no image border; with Seeded Object every label's.
// Beyond 64 labels the pieces are kept as they are.
void VoxelConnectivity(const Band& band, const GraphEdges& edges, std::vector<std::uint8_t>& x)
{
  const VoxelRefinementProblem& p = band.P;
  if (p.Connectivity == Connectivity::Off || p.Connectivity == Connectivity::FromTask || p.Labels > 64)
  {
    return;
  }
  const std::int64_t nb = band.Size();
  std::vector<std::int32_t> root(nb); // the domain's indices are 32-bit (State::Index)
  std::iota(root.begin(), root.end(), std::int32_t(0));
  const auto find = [&](std::int64_t c) {
    while (root[c] != c)
    {
      c = root[c] = root[root[c]];
    }
    return c;
  };
  edges.ForEach([&](std::int64_t, std::int64_t a, std::int64_t b) {
    if (x[a] == x[b])
    {
      const std::int64_t ra = find(a), rb = find(b);
      root[std::max(ra, rb)] = static_cast<std::int32_t>(std::min(ra, rb));
    }
  });
  std::vector<std::uint8_t> anchored(nb, 0);
  for (std::int64_t i = 0; i < nb; ++i)
  {
    // Fill Holes keeps every object piece.
    bool keep = band.IsHeld(i) || ((band.Around[i] >> x[i]) & 1u) || (x[i] != 0 && p.Connectivity == Connectivity::FillHoles);
    keep = keep || (x[i] == 0 && band.OnBorder(i));
    anchored[find(i)] |= keep;
  }
  // Faces each loose piece shares with each other label.
  std::vector<std::array<std::int64_t, 64>> shared;
  std::vector<std::int32_t> slot(nb, -1);
  for (std::int64_t i = 0; i < nb; ++i)
  {
    const std::int64_t r = find(i);
    if (anchored[r])
    {
      continue;
    }
    if (slot[r] < 0)
    {
      slot[r] = static_cast<std::int32_t>(shared.size());
      shared.emplace_back();
      shared.back().fill(0);
    }
    band.DomainNeighbours(i, [&](std::int64_t u, bool) {
      const std::int64_t j = band.Find(u);
      const std::uint8_t other = j >= 0 ? x[j] : band.ElementLabel(u);
      shared[slot[r]][other] += other != x[i];
    });
  }
  if (shared.empty())
  {
    return;
  }
  std::vector<std::uint8_t> to(shared.size(), 0);
  std::vector<bool> any(shared.size(), false);
  for (std::size_t s = 0; s < shared.size(); ++s)
  {
    const auto best = std::max_element(shared[s].begin(), shared[s].end());
    to[s] = static_cast<std::uint8_t>(best - shared[s].begin());
    any[s] = *best > 0;
  }
  for (std::int64_t i = 0; i < nb; ++i)
  {
    const std::int64_t s = slot[find(i)];
    if (s >= 0 && any[s])
    {
      x[i] = to[s];
    }
  }
}

// A voxel just outside the band beside a band voxel that left its label may have lost its last
// neighbour of that label: it would be a piece of its own, and takes the label most of its
// neighbours have (the lowest on a tie). Returned in ascending order.
void LoneVoxelsAround(const Band& band, const std::vector<std::uint8_t>& x, std::vector<std::int64_t>& voxel,
  std::vector<std::uint8_t>& label)
{
  const VoxelRefinementProblem& p = band.P;
  if (p.Connectivity == Connectivity::Off || p.Connectivity == Connectivity::FromTask)
  {
    return;
  }
  std::vector<std::int64_t> halo;
  for (std::int64_t i = 0; i < band.Size(); ++i)
  {
    const std::uint8_t before = band.Own[i];
    if (x[i] != before)
    {
      band.DomainNeighbours(i, [&](std::int64_t u, bool) {
        // Not refined and of the label left: a held voxel's label is at hand.
        const std::int64_t j = band.Find(u);
        if (j >= 0 ? band.IsHeld(j) && band.Own[j] == before : band.ElementLabel(u) == before)
        {
          halo.push_back(u);
        }
      });
    }
  }
  std::sort(halo.begin(), halo.end());
  halo.erase(std::unique(halo.begin(), halo.end()), halo.end());
  for (std::int64_t u : halo)
  {
    const std::uint8_t own = band.ElementLabel(u);
    bool border = false, keep = own != 0 && p.Connectivity == Connectivity::FillHoles;
    std::array<int, 6> seen{}, times{};
    int kinds = 0;
    band.Neighbours(u, [&](std::int64_t w, bool) {
      const std::int64_t j = band.Find(w);
      const int l = j >= 0 ? x[j] : band.ElementLabel(w);
      keep = keep || l == own;
      int k = 0;
      while (k < kinds && seen[k] != l)
      {
        ++k;
      }
      seen[k] = l;
      kinds = std::max(kinds, k + 1);
      ++times[k];
    }, &border);
    // A background voxel on the image's border is not a hole.
    if (keep || (own == 0 && border) || kinds == 0)
    {
      continue;
    }
    int best = 0;
    for (int k = 1; k < kinds; ++k)
    {
      best = times[k] > times[best] || (times[k] == times[best] && seen[k] < seen[best]) ? k : best;
    }
    voxel.push_back(u);
    label.push_back(static_cast<std::uint8_t>(seen[best]));
  }
}
// Each component's change in voxels: a voxel of an object element with its element's component, a
// voxel of a background element with that of the object element fewest face steps away (the band
// lies within Rings steps of one; a lone voxel one more). A shortest such path runs through band or
// seed elements only, so only their faces are walked, in the mesh's face order (its ties too).
std::vector<double> ComponentChanges(const VoxelRefinementProblem& p, const VoxelRefinementResult& r,
  const std::vector<std::uint8_t>& bandElement)
{
  const std::vector<std::int64_t>& component = *p.Component;
  const std::vector<std::uint8_t>& label = *p.Label;
  std::vector<double> change(1 + *std::max_element(component.begin(), component.end()), 0.0);
  const FaceAdjacency& faces = *p.Mesh->SharedFaces();
  const auto inside = [&](std::int64_t e) { return bandElement[e] || (!p.Fixed.empty() && p.Fixed[e]); };
  // The faces of the band and seed elements, in face order.
  std::vector<std::int64_t> local;
  const std::vector<std::int32_t>& faceOf = p.Mesh->ElementFaces();
  const int vpc = p.Mesh->VerticesPerCell();
  std::vector<std::uint8_t> mark(faces.A.size(), 0);
  for (std::size_t e = 0; e < label.size(); ++e)
  {
    if (!inside(static_cast<std::int64_t>(e)))
    {
      continue;
    }
    for (int k = 0; k < vpc; ++k)
    {
      const std::int32_t f = faceOf[e * vpc + k];
      if (f >= 0)
      {
        mark[f] = 1;
      }
    }
  }
  for (std::size_t f = 0; f < mark.size(); ++f)
  {
    if (mark[f])
    {
      local.push_back(static_cast<std::int64_t>(f));
    }
  }
  std::vector<std::int64_t> nearest = component;
  std::vector<std::pair<std::int64_t, std::int64_t>> set;
  for (int step = 0; step <= p.Rings; ++step)
  {
    set.clear();
    for (std::int64_t f : local)
    {
      const std::int64_t a = faces.A[f], b = faces.B[f];
      if (nearest[a] < 0 && nearest[b] >= 0)
      {
        set.emplace_back(a, nearest[b]);
      }
      if (nearest[b] < 0 && nearest[a] >= 0)
      {
        set.emplace_back(b, nearest[a]);
      }
    }
    // The first face in order that reaches an element gives it its component.
    for (auto it = set.rbegin(); it != set.rend(); ++it)
    {
      nearest[it->first] = it->second;
    }
  }
  for (std::size_t k = 0; k < r.Voxel.size(); ++k)
  {
    const std::int32_t e = (*p.Owner)[r.Voxel[k]];
    const bool was = e >= 0 && label[e] != 0, is = r.Label[k] != 0;
    const std::int64_t c = e >= 0 ? nearest[e] : -1;
    if (was != is && c >= 0)
    {
      change[c] += is ? 1.0 : -1.0;
    }
  }
  return change;
}
} // namespace

struct VoxelRefinementCache::State
{
  // Per voxel of the slices (2D: rows) the domain spans, from voxel IndexFirst on: its index in the
  // kept domain, else -1 (a 512^3 volume's band spans a part of its slices). The image's voxel count.
  std::vector<std::int32_t> Index;
  std::int64_t IndexFirst = 0, Voxels = -1;
  // The kept domain (its voxels and elements), its faces, the sigma of their weights and the label
  // count it was solved for; two labels: its max-flow graphs holding the last flow; more: the
  // expansion's memory, which keeps its rows of edges while the faces stay (FacesVersion).
  std::vector<std::int64_t> Domain;
  std::vector<std::uint8_t> DomainElement, Sides;
  std::vector<std::int32_t> Element;
  BandFaces Faces;
  std::uint64_t FacesVersion = 0;
  BinaryGraphs Binary;
  double Sigma = 0.0;
  int Labels = 0;
  bool Solved = false;
  ExpansionWorkspace Expansion;
};
VoxelRefinementCache::VoxelRefinementCache() = default;
VoxelRefinementCache::~VoxelRefinementCache() = default;
VoxelRefinementCache::VoxelRefinementCache(VoxelRefinementCache&&) noexcept = default;
VoxelRefinementCache& VoxelRefinementCache::operator=(VoxelRefinementCache&&) noexcept = default;
void VoxelRefinementCache::Clear()
{
  this->Kept.reset();
}

namespace
{
// The index map back to -1 everywhere, the kept domain gone.
void DropDomain(VoxelRefinementCache::State& st)
{
  for (std::int64_t v : st.Domain)
  {
    st.Index[v - st.IndexFirst] = -1;
  }
  st.Domain.clear();
  st.DomainElement.clear();
  st.Sides.clear();
  st.Element.clear();
  st.Solved = false;
}

// The refinement's last steps on the band's labels x: the connectivity rule, the lone voxels around,
// the voxels whose label differs from their element's, the components' changes.
void Finish(const VoxelRefinementProblem& p, const Band& band, const GraphEdges& edges, std::vector<std::uint8_t>& x,
  const std::vector<std::uint8_t>& bandElement, VoxelRefinementResult& r)
{
  VoxelConnectivity(band, edges, x);
  std::vector<std::int64_t> loneVoxel;
  std::vector<std::uint8_t> loneLabel;
  LoneVoxelsAround(band, x, loneVoxel, loneLabel);
  for (std::int64_t i = 0; i < band.Size(); ++i)
  {
    if (x[i] != band.Own[i])
    {
      r.Voxel.push_back(band.Voxel[i]);
      r.Label.push_back(x[i]);
    }
  }
  // The lone voxels lie outside the band: no voxel twice.
  r.Voxel.insert(r.Voxel.end(), loneVoxel.begin(), loneVoxel.end());
  r.Label.insert(r.Label.end(), loneLabel.begin(), loneLabel.end());
  if (p.Component && p.Labels == 2 && p.Component->size() == p.Label->size() && !p.Component->empty())
  {
    r.ComponentChange = ComponentChanges(p, r, bandElement);
  }
}

// The index map of the domain's voxels from `from` on. The map covers the slices (2D: rows) from the
// domain's lowest to its highest voxel; a domain beyond it gets a map of both spans, every voxel
// written again.
void IndexDomain(VoxelRefinementCache::State& st, const ImageGeometry& g, std::int64_t from)
{
  const std::int64_t n = static_cast<std::int64_t>(st.Domain.size());
  if (from >= n)
  {
    return;
  }
  const std::int64_t slice = g.Is2D() ? g.Dims[0] : g.SliceStride();
  const auto [low, high] = std::minmax_element(st.Domain.begin() + from, st.Domain.end());
  std::int64_t first = *low / slice * slice, last = (*high / slice + 1) * slice;
  const std::int64_t mapped = st.IndexFirst + static_cast<std::int64_t>(st.Index.size());
  if (first < st.IndexFirst || last > mapped)
  {
    if (from > 0)
    {
      first = std::min(first, st.IndexFirst);
      last = std::max(last, mapped);
    }
    AssignFresh(st.Index, static_cast<std::size_t>(last - first), std::int32_t(-1));
    st.IndexFirst = first;
    from = 0;
  }
  for (std::int64_t i = from; i < n; ++i)
  {
    st.Index[st.Domain[i] - st.IndexFirst] = static_cast<std::int32_t>(i);
  }
}

// Each domain voxel's element and GridSides from `from` on: read once while the domain stays, not
// from the image-sized owner map and the voxel's coordinates at every visit.
void DescribeDomain(VoxelRefinementCache::State& st, const ImageGeometry& g, const VoxelOwnerMap& owner, std::int64_t from)
{
  const std::int64_t n = static_cast<std::int64_t>(st.Domain.size());
  st.Sides.resize(n);
  st.Element.resize(n);
  for (std::int64_t i = from; i < n; ++i)
  {
    st.Element[i] = owner[st.Domain[i]];
    st.Sides[i] = static_cast<std::uint8_t>(GridSides(g, st.Domain[i]));
  }
}

// Two labels: the domain's max-flow, on the kept graphs (`inside`), on the kept graph grown by the
// voxels from `first` and the edges from `firstEdge` on (`extend`), else on new graphs. False with
// r.Error when memory runs out.
bool SolveTwoLabels(const Band& domain, const GraphEdges& edges, bool inside, bool extend, std::int64_t first,
  std::int64_t firstEdge, std::vector<double> cost, VoxelRefinementCache::State& st, std::vector<std::uint8_t>& x,
  VoxelRefinementResult& r)
{
  try
  {
    if (extend)
    {
      ExtendGraph(st.Binary, first, domain.Size(), edges, firstEdge, st.Faces.W);
    }
    else if (!inside)
    {
      DealComponents(domain.Size(), edges, st.Binary);
    }
    r.Energy = SolveGraphs(std::move(cost), edges, st.Faces.W, st.Binary, inside || extend, x, domain.P.Parallel);
    return true;
  }
  catch (const std::exception&)
  {
    r.Error = "not enough memory for the voxel refinement's max-flow (" + std::to_string(domain.Size()) + " voxels).";
    return false;
  }
}

// More labels: one cycle of alpha-expansion from the elements' labels, held voxels as hard nodes, on
// the domain's faces (their rows of edges kept while FacesVersion stays). False with r.Error or
// r.Aborted.
bool ExpandOnDomain(const Band& domain, const GraphEdges& edges, std::vector<double> cost, const ProgressFunction& progress,
  VoxelRefinementCache::State& st, std::vector<std::uint8_t>& x, VoxelRefinementResult& r)
{
  PottsProblem pr;
  pr.Nodes = domain.Size();
  pr.Labels = domain.P.Labels;
  pr.Cost = std::move(cost);
  pr.Edges = &edges;
  pr.Hard.resize(pr.Nodes);
  for (std::int64_t i = 0; i < pr.Nodes; ++i)
  {
    pr.Hard[i] = domain.Held[i] ? domain.Own[i] : std::int16_t(-1);
  }
  st.Expansion.GraphKey = st.FacesVersion;
  ExpansionResult e;
  {
    // The weights are lent to the expansion and given back, whatever it throws.
    struct GiveBack
    {
      std::vector<double>& Lent;
      std::vector<double>& Owner;
      ~GiveBack() { this->Lent.swap(this->Owner); }
    };
    pr.Weight.swap(st.Faces.W);
    const GiveBack back{ pr.Weight, st.Faces.W };
    e = AlphaExpansion(pr, domain.Own, SubProgress(progress, 0.4, 1.0), 1, nullptr, domain.P.Parallel, &st.Expansion);
  }
  r.Error = e.Error;
  r.Aborted = e.Aborted;
  r.Energy = e.Energy;
  x = std::move(e.Label);
  return r.Error.empty() && !r.Aborted;
}

// The refinement over the kept domain (State): the band's voxels, and those of elements in an earlier
// band held at their elements' labels. The domain grows by the band's new voxels; it is built afresh
// when it would grow past 1.5 times the band's elements, when its two-label band lay on two graphs, or
// when its weights or the label count changed. Two labels: one exact max-flow, the last one's run on
// with the new costs. More: one cycle of alpha-expansion from the elements' labels (a second moved no
// case's Dice by more than 0.001 and took as long again, docs/multilabel.md), held voxels as hard
// nodes, on the kept faces.
void RefineOnDomain(const VoxelRefinementProblem& p, const ProgressFunction& progress, VoxelRefinementCache::State& st,
  const std::vector<std::uint8_t>& bandElement, const std::vector<std::uint64_t>& near, VoxelRefinementResult& r)
{
  const bool binary = p.Labels == 2;
  const std::int64_t n = static_cast<std::int64_t>(bandElement.size());
  const bool same =
    st.Solved && st.Sigma == p.Sigma && st.Labels == p.Labels && static_cast<std::int64_t>(st.DomainElement.size()) == n;
  bool inside = same;
  std::int64_t band = 0, joined = 0;
  for (std::int64_t e = 0; e < n; ++e)
  {
    band += bandElement[e];
    joined += bandElement[e] || (same && st.DomainElement[e]);
    inside = inside && (!bandElement[e] || st.DomainElement[e]);
  }
  // A band that leaves the domain (with two labels, a one-graph domain) joins it while the two stay
  // within 1.5 times the band's elements: the new voxels join the graph (and the flow runs on).
  const bool extend = !inside && same && (!binary || st.Binary.Nodes[1] == 0) && 2 * joined <= 3 * band;
  const std::int64_t first = static_cast<std::int64_t>(st.Domain.size());
  const std::int64_t firstEdge = static_cast<std::int64_t>(st.Faces.A.size());
  st.Solved = st.Solved && inside; // until the grown or new domain is solved
  if (extend)
  {
    std::vector<std::uint8_t> added(n, 0);
    for (std::int64_t e = 0; e < n; ++e)
    {
      added[e] = bandElement[e] && !st.DomainElement[e];
      st.DomainElement[e] = st.DomainElement[e] || added[e];
    }
    const std::vector<std::int64_t> voxels = BandVoxels(*p.Mesh, *p.Owner, added, p.Parallel);
    st.Domain.insert(st.Domain.end(), voxels.begin(), voxels.end());
  }
  else if (!inside)
  {
    // A band that differs from the domain in a few elements (a seed moved back and forth) joins it,
    // and the next such edit stays inside; one that moved further replaces it.
    std::vector<std::uint8_t> element = bandElement;
    for (std::int64_t e = 0; e < n && same && 100 * joined <= 101 * band; ++e)
    {
      element[e] = element[e] || st.DomainElement[e];
    }
    DropDomain(st);
    st.Domain = BandVoxels(*p.Mesh, *p.Owner, element, p.Parallel);
    st.DomainElement = std::move(element);
  }
  const std::int64_t fresh = inside ? static_cast<std::int64_t>(st.Domain.size()) : extend ? first : 0;
  IndexDomain(st, p.Mesh->Geometry(), fresh);
  DescribeDomain(st, p.Mesh->Geometry(), *p.Owner, fresh);
  Band domain(p, st.Domain, st.Index, st.IndexFirst, st.Sides, st.Element);
  r.BandVoxels = domain.ReadElements(bandElement);
  const bool held = r.BandVoxels < domain.Size();
  if (!progress(0.2))
  {
    r.Aborted = true;
    return;
  }
  if (domain.Size() == 0)
  {
    return;
  }
  if (!inside)
  {
    BuildBandFaces(domain, extend ? first : 0, st.Faces);
    ++st.FacesVersion;
  }
  const GraphEdges edges(st.Faces.A, st.Faces.B);
  std::vector<double> cost;
  BandCosts(domain, st.Faces, near, cost);
  if (!progress(0.4))
  {
    r.Aborted = true;
    return;
  }
  std::vector<std::uint8_t> x;
  if (binary)
  {
    st.Solved = false; // until the flow has run
    if (!SolveTwoLabels(domain, edges, inside, extend, first, firstEdge, std::move(cost), st, x, r))
    {
      return;
    }
  }
  else if (!ExpandOnDomain(domain, edges, std::move(cost), progress, st, x, r))
  {
    return;
  }
  st.Solved = true;
  st.Sigma = p.Sigma;
  st.Labels = p.Labels;
  // The domain's energy holds the faces between held voxels of two labels, which the band's does not.
  for (std::size_t e = 0; e < st.Faces.A.size() && held; ++e)
  {
    const std::int64_t i = st.Faces.A[e], j = st.Faces.B[e];
    r.Energy -= domain.Held[i] && domain.Held[j] && x[i] != x[j] ? st.Faces.W[e] : 0.0;
  }
  Finish(p, domain, edges, x, bandElement, r);
}
} // namespace

VoxelRefinementResult RefineOnVoxels(const VoxelRefinementProblem& p, const ProgressFunction& progress,
  VoxelRefinementCache* cache)
{
  VoxelRefinementCache own;
  VoxelRefinementCache& kept = cache ? *cache : own;
  if (!kept.Kept)
  {
    kept.Kept = std::make_unique<VoxelRefinementCache::State>();
  }
  const auto t0 = Clock::now();
  VoxelRefinementResult r;
  if (!p.Mesh || !p.Owner || !p.Label || !p.Cost || !p.Distance2 || p.Labels < 2 || p.Labels > 256 || p.Rings < 1 ||
    static_cast<std::int64_t>(p.Label->size()) != p.Mesh->NumberOfElements() ||
    p.Owner->size() != p.Mesh->Geometry().Size() || !(p.Sigma > 0.0) ||
    (!p.Fixed.empty() && p.Fixed.size() != p.Label->size()))
  {
    r.Error = "the voxel refinement's inputs do not match the mesh.";
    return r;
  }
  VoxelRefinementCache::State& st = *kept.Kept;
  if (st.Voxels != p.Mesh->Geometry().Size())
  {
    st.Domain.clear();
    st.Solved = false;
    std::vector<std::int32_t>().swap(st.Index);
    st.IndexFirst = 0;
    st.Voxels = p.Mesh->Geometry().Size();
  }
  std::vector<std::uint8_t> bandElement;
  std::vector<std::uint64_t> near;
  BandElements(p, *p.Mesh->SharedFaces(), bandElement, near);
  RefineOnDomain(p, progress, st, bandElement, near, r);
  // A large image's band leaves tens of MB of freed blocks (512^3: ~55 MB) under the label image
  // the cut writes next.
  constexpr std::int64_t LargeImage = std::int64_t(1) << 26;
  if (p.Mesh->Geometry().Size() >= LargeImage)
  {
    ReturnFreedMemory();
  }
  r.Seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return r;
}

double BinaryPottsCut(const PottsProblem& problem, std::vector<std::uint8_t>& label, const ParallelFor& parallel)
{
  BinaryGraphs graphs;
  DealComponents(problem.Nodes, *problem.Edges, graphs);
  return SolveGraphs(problem.Cost, *problem.Edges, problem.Weight, graphs, false, label, parallel);
}

void ApplyRefinement(const VoxelRefinementResult& refinement, std::uint8_t* labels)
{
  for (std::size_t i = 0; i < refinement.Voxel.size(); ++i)
  {
    labels[refinement.Voxel[i]] = refinement.Label[i];
  }
}
} // namespace featuremesh
