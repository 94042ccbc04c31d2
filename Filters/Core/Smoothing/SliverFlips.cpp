#include "SliverFlips.h"

#include "ElementQuality.h"
#include "ExactPredicates.h"

#include <algorithm>
#include <numeric>

namespace featuremesh
{
namespace
{
using V3 = std::array<double, 3>;
using Tet = std::array<std::int64_t, 4>;

struct Flip
{
  double Quality = -2.0;         // SimplexAngleScore of the worst new tetrahedron
  std::vector<std::int64_t> Old; // the tetrahedra replaced
  std::vector<Tet> New;
};

class Flipper
{
public:
  Flipper(const ImageGeometry& g, const std::vector<V3>& points, std::vector<std::int64_t>& cells)
    : Points(points)
    , Cells(cells)
  {
    this->Frame.reserve(points.size());
    for (const V3& p : points)
    {
      this->Frame.push_back(g.IndexToFrame(p));
    }
  }

  // SimplexAngleScore: monotone in the smallest dihedral angle.
  double Quality(const Tet& t) const
  {
    const V3* v[4] = { &this->Frame[t[0]], &this->Frame[t[1]], &this->Frame[t[2]], &this->Frame[t[3]] };
    return SimplexAngleScore(v, 4);
  }
  Tet Cell(std::int64_t t) const
  {
    const std::int64_t* c = &this->Cells[4 * t];
    return { { c[0], c[1], c[2], c[3] } };
  }
  int Orientation(std::int64_t a, std::int64_t b, std::int64_t c, std::int64_t d) const
  {
    return Orientation3(this->Points[a], this->Points[b], this->Points[c], this->Points[d]);
  }

  // The stars (tetrahedra per point) of the slivers' vertices, of the cells as they are now.
  void BuildStars(const std::vector<std::pair<double, std::int64_t>>& slivers)
  {
    const std::int64_t n = static_cast<std::int64_t>(this->Cells.size() / 4);
    std::vector<std::uint8_t> wanted(this->Points.size(), 0);
    for (const auto& sliver : slivers)
    {
      for (std::int64_t v : this->Cell(sliver.second))
      {
        wanted[v] = 1;
      }
    }
    this->First.assign(this->Points.size() + 1, 0);
    for (std::int64_t i = 0; i < 4 * n; ++i)
    {
      this->First[this->Cells[i] + 1] += wanted[this->Cells[i]];
    }
    std::partial_sum(this->First.begin(), this->First.end(), this->First.begin());
    this->Star.resize(this->First.back());
    std::vector<std::int64_t> at(this->First.begin(), this->First.end() - 1);
    for (std::int64_t i = 0; i < 4 * n; ++i)
    {
      if (wanted[this->Cells[i]])
      {
        this->Star[at[this->Cells[i]]++] = i / 4;
      }
    }
    this->Touched.assign(n, 0);
  }

  // The tetrahedra of the stars holding every vertex in `with`; false when one was touched this
  // round (its star entry may be stale).
  bool Around(std::int64_t u, std::initializer_list<std::int64_t> with, std::vector<std::int64_t>& out) const
  {
    out.clear();
    for (std::int64_t j = this->First[u]; j < this->First[u + 1]; ++j)
    {
      const std::int64_t t = this->Star[j];
      const Tet c = this->Cell(t);
      if (std::all_of(with.begin(), with.end(), [&](std::int64_t w) { return std::find(c.begin(), c.end(), w) != c.end(); }))
      {
        if (this->Touched[t])
        {
          return false;
        }
        out.push_back(t);
      }
    }
    return true;
  }

  // 2-3: the face of tetrahedron t opposite its vertex k, shared with one other tetrahedron, becomes
  // three tetrahedra around the edge joining the two opposite vertices (valid when that edge
  // crosses the face's interior).
  void TwoThree(std::int64_t t, int k, Flip& best) const
  {
    const Tet c = this->Cell(t);
    const std::int64_t v = c[k], f[3] = { c[(k + 1) % 4], c[(k + 2) % 4], c[(k + 3) % 4] };
    std::vector<std::int64_t> shared;
    if (!this->Around(f[0], { f[1], f[2] }, shared) || shared.size() != 2)
    {
      return;
    }
    const std::int64_t other = shared[0] == t ? shared[1] : shared[0];
    const Tet o = this->Cell(other);
    std::int64_t e = -1;
    for (std::int64_t x : o)
    {
      e = x != f[0] && x != f[1] && x != f[2] ? x : e;
    }
    Flip flip;
    flip.Old = { t, other };
    int sign = 0;
    double quality = 1.0;
    for (int i = 0; i < 3; ++i)
    {
      const int s = this->Orientation(f[i], f[(i + 1) % 3], v, e);
      if (s == 0 || (sign != 0 && s != sign))
      {
        return;
      }
      sign = s;
      flip.New.push_back(s > 0 ? Tet{ { f[i], f[(i + 1) % 3], v, e } } : Tet{ { f[(i + 1) % 3], f[i], v, e } });
      quality = std::min(quality, this->Quality(flip.New.back()));
    }
    flip.Quality = quality;
    this->Consider(std::move(flip), best);
  }

  // 3-2: an interior edge of tetrahedron t with exactly three tetrahedra around it; they become two
  // tetrahedra sharing the triangle of the three ring vertices (valid when the edge's ends lie on
  // either side of it).
  void ThreeTwo(std::int64_t t, int i, int j, Flip& best) const
  {
    const Tet c = this->Cell(t);
    const std::int64_t u = c[i], w = c[j];
    std::vector<std::int64_t> ring;
    if (!this->Around(u, { w }, ring) || ring.size() != 3)
    {
      return;
    }
    // The ring vertices: each of three must lie in exactly two of the tetrahedra (a closed ring).
    std::vector<std::int64_t> vertices;
    for (std::int64_t r : ring)
    {
      for (std::int64_t x : this->Cell(r))
      {
        if (x != u && x != w)
        {
          vertices.push_back(x);
        }
      }
    }
    std::sort(vertices.begin(), vertices.end());
    if (vertices.size() != 6 || vertices[0] != vertices[1] || vertices[2] != vertices[3] || vertices[4] != vertices[5] ||
      vertices[1] == vertices[2] || vertices[3] == vertices[4])
    {
      return;
    }
    const std::int64_t a = vertices[0], b = vertices[2], d = vertices[4];
    const int su = this->Orientation(a, b, d, u), sw = this->Orientation(a, b, d, w);
    if (su == 0 || sw == 0 || su == sw)
    {
      return;
    }
    Flip flip;
    flip.Old = ring;
    flip.New = { su > 0 ? Tet{ { a, b, d, u } } : Tet{ { b, a, d, u } }, sw > 0 ? Tet{ { a, b, d, w } } : Tet{ { b, a, d, w } } };
    flip.Quality = std::min(this->Quality(flip.New[0]), this->Quality(flip.New[1]));
    this->Consider(std::move(flip), best);
  }

  // `flip` becomes the best when it raises the smallest angle of what it replaces, and more than
  // the best so far does.
  void Consider(Flip&& flip, Flip& best) const
  {
    double replaced = 1.0;
    for (std::int64_t o : flip.Old)
    {
      replaced = std::min(replaced, this->Quality(this->Cell(o)));
    }
    if (flip.Quality > replaced && flip.Quality > best.Quality)
    {
      best = std::move(flip);
    }
  }

  const std::vector<V3>& Points; // index space: orientations
  std::vector<V3> Frame;          // angles
  std::vector<std::int64_t>& Cells;
  std::vector<std::int64_t> First, Star;
  std::vector<std::uint8_t> Touched;
};
} // namespace

std::int64_t FlipSlivers(const ImageGeometry& geometry, const std::vector<V3>& points, std::vector<std::int64_t>& cells,
  double angle, int rounds, const std::vector<std::uint8_t>* movable)
{
  Flipper f(geometry, points, cells);
  const double threshold = AngleScoreAt(angle);
  std::int64_t flips = 0;
  for (int round = 0; round < rounds; ++round)
  {
    const std::int64_t n = static_cast<std::int64_t>(cells.size() / 4);
    std::vector<std::pair<double, std::int64_t>> slivers;
    for (std::int64_t t = 0; t < n; ++t)
    {
      const Tet c = f.Cell(t);
      if (movable && std::any_of(c.begin(), c.end(), [&](std::int64_t v) { return (*movable)[v] != 0; }))
      {
        continue;
      }
      const double q = f.Quality(c);
      if (q < threshold)
      {
        slivers.emplace_back(q, t);
      }
    }
    if (slivers.empty())
    {
      break;
    }
    std::sort(slivers.begin(), slivers.end());
    f.BuildStars(slivers);
    std::vector<std::uint8_t> dead(n, 0);
    std::int64_t made = 0;
    for (const auto& [quality, t] : slivers)
    {
      if (f.Touched[t])
      {
        continue;
      }
      Flip best;
      for (int k = 0; k < 4; ++k)
      {
        f.TwoThree(t, k, best);
      }
      for (int i = 0; i < 4; ++i)
      {
        for (int j = i + 1; j < 4; ++j)
        {
          f.ThreeTwo(t, i, j, best);
        }
      }
      if (best.Old.empty())
      {
        continue;
      }
      for (size_t i = 0; i < best.Old.size(); ++i)
      {
        const std::int64_t o = best.Old[i];
        f.Touched[o] = 1;
        if (i < best.New.size())
        {
          std::copy(best.New[i].begin(), best.New[i].end(), cells.begin() + 4 * o);
        }
        else
        {
          dead[o] = 1;
        }
      }
      for (size_t i = best.Old.size(); i < best.New.size(); ++i)
      {
        cells.insert(cells.end(), best.New[i].begin(), best.New[i].end());
        f.Touched.push_back(1);
        dead.push_back(0);
      }
      ++made;
    }
    // Drop the tetrahedra 3-2 flips emptied, keeping the others' order.
    if (std::find(dead.begin(), dead.end(), 1) != dead.end())
    {
      std::int64_t kept = 0;
      for (std::int64_t t = 0; t < static_cast<std::int64_t>(dead.size()); ++t)
      {
        if (!dead[t])
        {
          std::copy(cells.begin() + 4 * t, cells.begin() + 4 * t + 4, cells.begin() + 4 * kept++);
        }
      }
      cells.resize(4 * kept);
    }
    flips += made;
    if (!made)
    {
      break;
    }
  }
  return flips;
}
} // namespace featuremesh
