// The edges of a cut's graph, as the cut and the connectivity rule walk them: explicit node pairs
// (A[e], B[e]), viewed and not copied (mesh elements sharing a face) or owned, or the face neighbours of a
// voxel grid, enumerated without being stored (a 9 M-voxel volume has 27 M of them: two 8-byte ids
// each would be 424 MB). Grid order: voxels in raster order, each with its +x, +y, then +z neighbour.
// Either kind is walked in blocks of about BlockEdges edges, so that loops can split across threads
// and check for an abort between blocks.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace featuremesh
{
class GraphEdges
{
public:
  static constexpr std::int64_t BlockEdges = 16384;

  GraphEdges() = default;
  // A view: the lists must outlive it and keep their size.
  GraphEdges(const std::vector<std::int64_t>& a, const std::vector<std::int64_t>& b)
    : A(a.data())
    , B(b.data())
    , M(static_cast<std::int64_t>(std::min(a.size(), b.size())))
    , Mismatch(a.size() != b.size())
  {
  }
  // A view of immutable lists that `keep` holds: copies of this GraphEdges keep them alive, and two
  // views with the same holder compare equal without reading the lists.
  GraphEdges(const std::vector<std::int64_t>& a, const std::vector<std::int64_t>& b, std::shared_ptr<const void> keep)
    : GraphEdges(a, b)
  {
    this->Keep = std::move(keep);
  }
  // Lists the edges own: copies of this GraphEdges share them.
  static GraphEdges Owned(std::vector<std::int64_t> a, std::vector<std::int64_t> b)
  {
    auto lists = std::make_shared<const std::array<std::vector<std::int64_t>, 2>>(
      std::array<std::vector<std::int64_t>, 2>{ { std::move(a), std::move(b) } });
    GraphEdges g((*lists)[0], (*lists)[1]);
    g.Keep = std::move(lists);
    return g;
  }
  // The face neighbours of an nx x ny x nz grid (nz = 1: a 2D image, 4-neighbours).
  static GraphEdges Grid(int nx, int ny, int nz)
  {
    GraphEdges g;
    g.Dims = { { std::max(nx, 1), std::max(ny, 1), std::max(nz, 1) } };
    const std::int64_t x = g.Dims[0], y = g.Dims[1], z = g.Dims[2];
    g.M = z * (y * (x - 1) + (y - 1) * x) + (z - 1) * x * y;
    g.RowsPerBlock = std::max<std::int64_t>(1, BlockEdges / (3 * x));
    return g;
  }

  std::int64_t Size() const { return this->M; }
  bool IsGrid() const { return this->Dims[0] > 0; }
  const std::array<int, 3>& GridDims() const { return this->Dims; }
  // Explicit lists of different lengths: the graph is malformed.
  bool Malformed() const { return this->Mismatch; }
  // Explicit lists only (null for a grid).
  const std::int64_t* First() const { return this->A; }
  const std::int64_t* Second() const { return this->B; }

  // Lists that a holder keeps unchanged (owned, or held): safe to keep instead of copying.
  bool Held() const { return this->Keep != nullptr; }
  // The same edges for a record that outlives the lists it views: grids and held lists as they are,
  // viewed lists copied.
  GraphEdges Keepable() const
  {
    if (this->IsGrid() || this->Held())
    {
      return *this;
    }
    return Owned(std::vector<std::int64_t>(this->A, this->A + this->M), std::vector<std::int64_t>(this->B, this->B + this->M));
  }
  // The same edges in the same order.
  bool Same(const GraphEdges& o) const
  {
    if (this->IsGrid() || o.IsGrid())
    {
      return this->Dims == o.Dims;
    }
    if (this->Keep && this->Keep == o.Keep && this->A == o.A && this->B == o.B && this->M == o.M)
    {
      return true;
    }
    return this->M == o.M && std::equal(this->A, this->A + this->M, o.A) && std::equal(this->B, this->B + this->M, o.B);
  }

  std::int64_t Blocks() const
  {
    if (!this->IsGrid())
    {
      return (this->M + BlockEdges - 1) / BlockEdges;
    }
    const std::int64_t rows = static_cast<std::int64_t>(this->Dims[1]) * this->Dims[2];
    return (rows + this->RowsPerBlock - 1) / this->RowsPerBlock;
  }
  // The first edge of block `block` (Blocks() gives Size()).
  std::int64_t BlockStart(std::int64_t block) const
  {
    if (!this->IsGrid())
    {
      return std::min(this->M, block * BlockEdges);
    }
    const std::int64_t rows = static_cast<std::int64_t>(this->Dims[1]) * this->Dims[2];
    return this->RowStart(std::min(rows, block * this->RowsPerBlock));
  }
  // f(e, a, b) for every edge of blocks [first, last), in edge order.
  template <typename F>
  void ForEach(std::int64_t first, std::int64_t last, F&& f) const
  {
    if (!this->IsGrid())
    {
      for (std::int64_t e = this->BlockStart(first), end = this->BlockStart(last); e < end; ++e)
      {
        f(e, this->A[e], this->B[e]);
      }
      return;
    }
    const std::int64_t x = this->Dims[0], y = this->Dims[1], z = this->Dims[2];
    const std::int64_t rows = y * z;
    std::int64_t e = this->BlockStart(first);
    for (std::int64_t r = first * this->RowsPerBlock, end = std::min(rows, last * this->RowsPerBlock); r < end; ++r)
    {
      const std::int64_t j = r % y, k = r / y;
      const bool up = j + 1 < y, above = k + 1 < z;
      for (std::int64_t i = 0, v = r * x; i < x; ++i, ++v)
      {
        if (i + 1 < x)
        {
          f(e++, v, v + 1);
        }
        if (up)
        {
          f(e++, v, v + x);
        }
        if (above)
        {
          f(e++, v, v + x * y);
        }
      }
    }
  }
  template <typename F>
  void ForEach(F&& f) const
  {
    this->ForEach(0, this->Blocks(), f);
  }
  // ForEach over every edge, asking keepGoing(fraction done) every 16 blocks (~2^18 edges); false
  // when it answered false.
  template <typename F, typename KeepGoing>
  bool ForEachUntil(F&& f, KeepGoing&& keepGoing) const
  {
    const std::int64_t blocks = this->Blocks();
    for (std::int64_t k = 0; k < blocks; ++k)
    {
      if ((k & 15) == 15 && !keepGoing(static_cast<double>(k) / static_cast<double>(blocks)))
      {
        return false;
      }
      this->ForEach(k, k + 1, f);
    }
    return true;
  }

private:
  // The first edge of grid row r (voxel row j of slice k): slices before k and rows before j all
  // have their +y and +z neighbours.
  std::int64_t RowStart(std::int64_t r) const
  {
    const std::int64_t x = this->Dims[0], y = this->Dims[1], z = this->Dims[2];
    if (r >= y * z)
    {
      return this->M;
    }
    const std::int64_t j = r % y, k = r / y;
    const std::int64_t slice = y * (x - 1) + (y - 1) * x + x * y;
    const std::int64_t row = (x - 1) + x + (k + 1 < z ? x : 0);
    return k * slice + j * row;
  }

  const std::int64_t* A = nullptr;
  const std::int64_t* B = nullptr;
  std::int64_t M = 0;
  bool Mismatch = false;
  std::array<int, 3> Dims = { { 0, 0, 0 } };
  std::int64_t RowsPerBlock = 1;
  std::shared_ptr<const void> Keep;
};

// Empty when a graph of `nodes` nodes and `edges` edges fits the 32-bit ids of the max-flow
// library and of the geodesic term's adjacency, else a sentence.
inline std::string GraphSizeProblem(std::int64_t nodes, std::int64_t edges)
{
  constexpr std::int64_t most = 2000000000;
  return nodes > most || 2 * edges > most ? "the graph is too large for the max-flow library (node ids are 32-bit)."
                                          : std::string();
}
} // namespace featuremesh
