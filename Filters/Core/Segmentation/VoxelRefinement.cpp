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

// BinaryPottsCut on kept graphs: each graph emptied, then given its nodes' costs and edges in the
// problem's order (label 1 on the source side); returns the energy.
double CutOnGraphs(const PottsProblem& pr, std::array<std::unique_ptr<Flow>, 2>& graphs, std::vector<std::uint8_t>& label,
  const ParallelFor& parallel)
{
  const std::int64_t n = pr.Nodes;
  std::int64_t count = 0;
  const std::vector<std::int64_t> component = LabelComponents(std::vector<std::uint8_t>(n, 0), *pr.Edges, count);
  std::vector<std::int64_t> size(count, 0);
  for (std::int64_t c : component)
  {
    ++size[c];
  }
  const bool apart = count > 1 && 4 * *std::max_element(size.begin(), size.end()) <= 3 * n;
  // Each component's graph (all the first's unless apart), each node's graph and index in it.
  std::vector<std::uint8_t> side(count, 0);
  std::array<std::int64_t, 2> load{ { 0, 0 } };
  for (std::int64_t c = 0; c < count && apart; ++c)
  {
    side[c] = load[1] < load[0] ? 1 : 0;
    load[side[c]] += size[c];
  }
  std::vector<std::uint8_t> nodeSide(n);
  std::vector<std::int32_t> local(n);
  std::array<std::int32_t, 2> nodes{ { 0, 0 } };
  for (std::int64_t i = 0; i < n; ++i)
  {
    nodeSide[i] = side[component[i]];
    local[i] = nodes[nodeSide[i]]++;
  }
  std::array<double, 2> energy{ { 0.0, 0.0 } };
  label.resize(n);
  const auto cut = [&](int s) {
    // A kept graph grows as libmaxflow's do; a new one is made for this problem's share.
    std::unique_ptr<Flow>& kept = graphs[s];
    if (!kept)
    {
      const std::int64_t edges = pr.Edges->Size() * nodes[s] / std::max<std::int64_t>(n, 1);
      kept = std::make_unique<Flow>(nodes[s], static_cast<int>(edges), ThrowOutOfMemory);
    }
    Flow& g = *kept;
    g.reset();
    g.add_node(nodes[s]);
    for (std::int64_t i = 0; i < n; ++i)
    {
      if (nodeSide[i] == s)
      {
        // A node on the sink side (label 0) pays its source capacity.
        g.add_tweights(local[i], pr.Cost[2 * i], pr.Cost[2 * i + 1]);
      }
    }
    pr.Edges->ForEach([&](std::int64_t e, std::int64_t a, std::int64_t b) {
      if (nodeSide[a] == s)
      {
        g.add_edge(local[a], local[b], pr.Weight[e], pr.Weight[e]);
      }
    });
    energy[s] = g.maxflow();
    for (std::int64_t i = 0; i < n; ++i)
    {
      if (nodeSide[i] == s)
      {
        label[i] = g.what_segment(local[i]) == Flow::SOURCE ? 1 : 0;
      }
    }
  };
  if (!apart)
  {
    cut(0);
    return energy[0];
  }
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
  return energy[0] + energy[1];
}

// Elements within `rings` face steps of an element of another label, seed elements left out, and
// per element the labels within rings face steps of it (bit l; all ones beyond 64 labels).
void BandElements(const VoxelRefinementProblem& p, const FaceAdjacency& faces, std::vector<std::uint8_t>& band,
  std::vector<std::uint64_t>& near)
{
  const std::vector<std::uint8_t>& label = *p.Label;
  const std::int64_t n = static_cast<std::int64_t>(label.size());
  const std::int64_t m = static_cast<std::int64_t>(faces.A.size());
  band.assign(n, 0);
  for (std::int64_t f = 0; f < m; ++f)
  {
    if (label[faces.A[f]] != label[faces.B[f]])
    {
      band[faces.A[f]] = band[faces.B[f]] = 1;
    }
  }
  for (int r = 1; r < p.Rings; ++r)
  {
    std::vector<std::uint8_t> grown = band;
    for (std::int64_t f = 0; f < m; ++f)
    {
      grown[faces.A[f]] |= band[faces.B[f]];
      grown[faces.B[f]] |= band[faces.A[f]];
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
    for (std::int64_t f = 0; f < m; ++f)
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
  const int vpc = mesh.VerticesPerCell();
  constexpr std::int64_t chunk = 1024;
  const std::int64_t chunks = (static_cast<std::int64_t>(elements.size()) + chunk - 1) / chunk;
  std::vector<std::vector<std::int64_t>> found(chunks);
  parallel(chunks, 1, [&](std::int64_t c0, std::int64_t c1) {
    for (std::int64_t c = c0; c < c1; ++c)
    {
      const std::int64_t last = std::min(static_cast<std::int64_t>(elements.size()), (c + 1) * chunk);
      for (std::int64_t k = c * chunk; k < last; ++k)
      {
        const std::int64_t e = elements[k];
        const std::int64_t* cell = mesh.Cell(e);
        std::array<int, 3> low{ { 0, 0, 0 } }, high{ { 0, 0, 0 } };
        for (int d = 0; d < 3; ++d)
        {
          double lo = mesh.Points()[cell[0]][d], hi = lo;
          for (int j = 1; j < vpc; ++j)
          {
            lo = std::min(lo, mesh.Points()[cell[j]][d]);
            hi = std::max(hi, mesh.Points()[cell[j]][d]);
          }
          low[d] = std::max(0, static_cast<int>(std::ceil(lo)));
          high[d] = std::min(g.Dims[d] - 1, static_cast<int>(std::floor(hi)));
        }
        for (int z = low[2]; z <= high[2]; ++z)
          for (int y = low[1]; y <= high[1]; ++y)
            for (int x = low[0]; x <= high[0]; ++x)
            {
              const std::int64_t v = g.Index(x, y, z);
              if (owner[v] == e)
              {
                found[c].push_back(v);
              }
            }
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

// The band's voxels and what lies around them.
struct Band
{
  const VoxelRefinementProblem& P;
  const ImageGeometry& G;
  std::vector<std::int64_t> Voxel;
  std::vector<std::uint64_t> Around; // per voxel: the labels of its neighbours outside the band (bit l, l < 64)
  std::vector<std::int32_t>& Index;  // per image voxel: its band index, -1 outside the band
  std::int64_t Stride[3];
  int Axes;

  Band(const VoxelRefinementProblem& p, std::vector<std::int64_t> voxels, std::vector<std::int32_t>& index)
    : P(p)
    , G(p.Mesh->Geometry())
    , Voxel(std::move(voxels))
    , Around(Voxel.size(), 0)
    , Index(index)
    , Stride{ 1, G.Dims[0], G.SliceStride() }
    , Axes(G.Is2D() ? 2 : 3)
  {
    if (static_cast<std::int64_t>(this->Index.size()) != this->G.Size())
    {
      AssignFresh(this->Index, static_cast<std::size_t>(this->G.Size()), std::int32_t(-1));
    }
    for (std::size_t i = 0; i < this->Voxel.size(); ++i)
    {
      this->Index[this->Voxel[i]] = static_cast<std::int32_t>(i);
    }
  }
  // The index map is left as it was found: -1 everywhere.
  ~Band()
  {
    for (std::int64_t v : this->Voxel)
    {
      this->Index[v] = -1;
    }
  }
  Band(const Band&) = delete;
  Band& operator=(const Band&) = delete;
  std::int64_t Size() const { return static_cast<std::int64_t>(this->Voxel.size()); }
  std::uint8_t ElementLabel(std::int64_t v) const
  {
    const std::int32_t e = (*this->P.Owner)[v];
    return e >= 0 ? (*this->P.Label)[e] : std::uint8_t(0);
  }
  // The band index of voxel u, -1 outside the band.
  std::int64_t Find(std::int64_t u) const { return this->Index[u]; }
  // f(u, forward) for every face neighbour u of voxel v; `border` is set when v lies on the image's border.
  template <typename F>
  void Neighbours(std::int64_t v, F&& f, bool* border = nullptr) const
  {
    const std::array<int, 3> ijk = this->G.Coordinates(v);
    for (int d = 0; d < this->Axes; ++d)
    {
      if (ijk[d] + 1 < this->G.Dims[d])
      {
        f(v + this->Stride[d], true);
      }
      else if (border)
      {
        *border = true;
      }
      if (ijk[d] > 0)
      {
        f(v - this->Stride[d], false);
      }
      else if (border)
      {
        *border = true;
      }
    }
  }
};

// The band's Potts problem: costs from P.Cost, a label no element near the voxel's has priced out,
// and per voxel face an edge to a band voxel or its weight on every label but its neighbour's
// outside the band. Fixed chunks of voxels in parallel, their edges joined in chunk order.
void BuildProblem(Band& band, const std::vector<std::uint64_t>& near, PottsProblem& pr, std::vector<std::int64_t>& a,
  std::vector<std::int64_t>& b)
{
  const VoxelRefinementProblem& p = band.P;
  const int L = p.Labels;
  const std::int64_t nb = band.Size();
  pr.Nodes = nb;
  pr.Labels = L;
  pr.Cost.resize(nb * L);
  const double inv2s2 = 1.0 / (2.0 * p.Sigma * p.Sigma);
  constexpr double excluded = 1e9;
  constexpr std::int64_t chunk = 8192;
  const std::int64_t chunks = (nb + chunk - 1) / chunk;
  struct Part
  {
    std::vector<std::int64_t> A, B;
    std::vector<double> W;
  };
  std::vector<Part> parts(chunks);
  p.Parallel(chunks, 1, [&](std::int64_t c0, std::int64_t c1) {
    for (std::int64_t c = c0; c < c1; ++c)
    {
      Part& part = parts[c];
      const std::int64_t last = std::min(nb, (c + 1) * chunk);
      for (std::int64_t i = c * chunk; i < last; ++i)
      {
        const std::int64_t v = band.Voxel[i], e = (*p.Owner)[v];
        double* cost = &pr.Cost[i * L];
        p.Cost(v, e, cost);
        for (int l = 0; l < L && L > 2; ++l)
        {
          cost[l] += ((near[e] >> (l & 63)) & 1u) ? 0.0 : excluded;
        }
        band.Neighbours(v, [&](std::int64_t u, bool) {
          const std::int64_t j = band.Find(u);
          if (j >= 0 && j < i)
          {
            return; // the pair's edge comes from j
          }
          const double d2 = p.Distance2(v, u);
          const double w = d2 == 0.0 ? 1.0 : std::exp(-d2 * inv2s2);
          if (j >= 0)
          {
            part.A.push_back(i);
            part.B.push_back(j);
            part.W.push_back(w);
            return;
          }
          const std::uint8_t held = band.ElementLabel(u);
          band.Around[i] |= held < 64 ? std::uint64_t(1) << held : 0;
          for (int l = 0; l < L; ++l)
          {
            cost[l] += l == held ? 0.0 : w;
          }
        });
      }
    }
  });
  for (Part& part : parts)
  {
    a.insert(a.end(), part.A.begin(), part.A.end());
    b.insert(b.end(), part.B.begin(), part.B.end());
    pr.Weight.insert(pr.Weight.end(), part.W.begin(), part.W.end());
  }
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
  std::vector<std::int64_t> root(nb);
  std::iota(root.begin(), root.end(), std::int64_t(0));
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
      root[std::max(ra, rb)] = std::min(ra, rb);
    }
  });
  std::vector<std::uint8_t> anchored(nb, 0);
  for (std::int64_t i = 0; i < nb; ++i)
  {
    // Fill Holes keeps every object piece.
    bool keep = ((band.Around[i] >> x[i]) & 1u) || (x[i] != 0 && p.Connectivity == Connectivity::FillHoles);
    if (!keep && x[i] == 0)
    {
      band.Neighbours(band.Voxel[i], [](std::int64_t, bool) {}, &keep);
    }
    anchored[find(i)] |= keep;
  }
  // Faces each loose piece shares with each other label.
  std::vector<std::array<std::int64_t, 64>> shared;
  std::vector<std::int64_t> slot(nb, -1);
  for (std::int64_t i = 0; i < nb; ++i)
  {
    const std::int64_t r = find(i);
    if (anchored[r])
    {
      continue;
    }
    if (slot[r] < 0)
    {
      slot[r] = static_cast<std::int64_t>(shared.size());
      shared.emplace_back();
      shared.back().fill(0);
    }
    band.Neighbours(band.Voxel[i], [&](std::int64_t u, bool) {
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
    const std::uint8_t before = band.ElementLabel(band.Voxel[i]);
    if (x[i] != before)
    {
      band.Neighbours(band.Voxel[i], [&](std::int64_t u, bool) {
        if (band.ElementLabel(u) == before && band.Find(u) < 0)
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
  std::vector<std::int64_t> local;
  for (std::size_t f = 0; f < faces.A.size(); ++f)
  {
    if (inside(faces.A[f]) || inside(faces.B[f]))
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
  std::vector<std::int32_t> Index; // per image voxel: -1 between refinements
  std::array<std::unique_ptr<Flow>, 2> Graphs;
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
  std::vector<std::uint8_t> bandElement;
  std::vector<std::uint64_t> near;
  BandElements(p, *p.Mesh->SharedFaces(), bandElement, near);
  Band band(p, BandVoxels(*p.Mesh, *p.Owner, bandElement, p.Parallel), kept.Kept->Index);
  const std::int64_t nb = r.BandVoxels = band.Size();
  if (!progress(0.2))
  {
    r.Aborted = true;
    return r;
  }
  if (nb == 0)
  {
    r.Seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return r;
  }
  PottsProblem pr;
  std::vector<std::int64_t> a, b;
  BuildProblem(band, near, pr, a, b);
  const GraphEdges edges = GraphEdges::Owned(std::move(a), std::move(b));
  pr.Edges = &edges;
  if (!progress(0.4))
  {
    r.Aborted = true;
    return r;
  }
  // Two labels: one exact max-flow (source = label 1). More: alpha-expansion from the elements' labels.
  ExpansionResult x;
  if (p.Labels == 2)
  {
    try
    {
      x.Energy = CutOnGraphs(pr, kept.Kept->Graphs, x.Label, p.Parallel);
    }
    catch (const std::exception&)
    {
      r.Error = "not enough memory for the voxel refinement's max-flow (" + std::to_string(nb) + " voxels).";
      return r;
    }
  }
  else
  {
    std::vector<std::uint8_t> start(nb);
    for (std::int64_t i = 0; i < nb; ++i)
    {
      start[i] = band.ElementLabel(band.Voxel[i]);
    }
    // One cycle over the labels: from the elements' labels a second moved no case's Dice by more
    // than 0.001 and took as long again (docs/multilabel.md).
    x = AlphaExpansion(pr, std::move(start), SubProgress(progress, 0.4, 1.0), 1, nullptr, p.Parallel, &kept.Kept->Expansion);
    if (!x.Error.empty() || x.Aborted)
    {
      r.Error = x.Error;
      r.Aborted = x.Aborted;
      return r;
    }
  }
  r.Energy = x.Energy;
  VoxelConnectivity(band, edges, x.Label);
  std::vector<std::int64_t> loneVoxel;
  std::vector<std::uint8_t> loneLabel;
  LoneVoxelsAround(band, x.Label, loneVoxel, loneLabel);
  for (std::int64_t i = 0; i < nb; ++i)
  {
    if (x.Label[i] != band.ElementLabel(band.Voxel[i]))
    {
      r.Voxel.push_back(band.Voxel[i]);
      r.Label.push_back(x.Label[i]);
    }
  }
  // The lone voxels lie outside the band: no voxel twice.
  r.Voxel.insert(r.Voxel.end(), loneVoxel.begin(), loneVoxel.end());
  r.Label.insert(r.Label.end(), loneLabel.begin(), loneLabel.end());
  if (p.Component && p.Labels == 2 && p.Component->size() == p.Label->size() && !p.Component->empty())
  {
    r.ComponentChange = ComponentChanges(p, r, bandElement);
  }
  r.Seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return r;
}

double BinaryPottsCut(const PottsProblem& problem, std::vector<std::uint8_t>& label, const ParallelFor& parallel)
{
  std::array<std::unique_ptr<Flow>, 2> graphs;
  return CutOnGraphs(problem, graphs, label, parallel);
}

void ApplyRefinement(const VoxelRefinementResult& refinement, std::uint8_t* labels)
{
  for (std::size_t i = 0; i < refinement.Voxel.size(); ++i)
  {
    labels[refinement.Voxel[i]] = refinement.Label[i];
  }
}
} // namespace featuremesh
