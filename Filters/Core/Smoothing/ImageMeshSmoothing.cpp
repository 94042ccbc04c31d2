#include "ImageMeshSmoothing.h"
#include "Memory.h"

#include "DelaunayImageMesh.h"
#include "ElementQuality.h"
#include "ElementRasterizer.h"
#include "ExactPredicates.h"
#include "ImageFilters.h"
#include "SliverFlips.h"
#include "Vector3.h"

#include <algorithm>
#include <map>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

namespace featuremesh
{
namespace
{
using namespace vector3;

// Moved positions are multiples of 1 / Lattice voxel in index space.
constexpr double Lattice = 1024.0;
// A move is tried at these fractions of the step to its target, then rejected.
constexpr double StepFractions[] = { 1.0, 0.5, 0.25 };
// A cached value still to compute.
constexpr double Stale = std::numeric_limits<double>::quiet_NaN();

// Circumcentre of a triangle (xy) or tetrahedron in frame coordinates; false for a flat element.
bool Circumcentre(const V3* const* v, int vpc, V3& centre)
{
  if (vpc == 3)
  {
    const V3 b = Sub(*v[1], *v[0]), c = Sub(*v[2], *v[0]);
    const double d = 2.0 * (b[0] * c[1] - b[1] * c[0]);
    if (d == 0.0)
    {
      return false;
    }
    const double bb = b[0] * b[0] + b[1] * b[1], cc = c[0] * c[0] + c[1] * c[1];
    centre = { { (*v[0])[0] + (c[1] * bb - b[1] * cc) / d, (*v[0])[1] + (b[0] * cc - c[0] * bb) / d, 0.0 } };
    return true;
  }
  const V3 a = Sub(*v[1], *v[0]), b = Sub(*v[2], *v[0]), c = Sub(*v[3], *v[0]);
  const double det = 2.0 * Dot(a, Cross(b, c));
  if (det == 0.0)
  {
    return false;
  }
  const V3 x1 = Cross(b, c), x2 = Cross(c, a), x3 = Cross(a, b);
  const double la = Dot(a, a), lb = Dot(b, b), lc = Dot(c, c);
  for (int k = 0; k < 3; ++k)
  {
    centre[k] = (*v[0])[k] + (la * x1[k] + lb * x2[k] + lc * x3[k]) / det;
  }
  return true;
}

double Measure(const V3* const* v, int vpc)
{
  return std::fabs(SimplexMeasure(v, vpc));
}

int ExactOrientation(const V3* const* v, int vpc)
{
  return vpc == 3 ? Orientation2(*v[0], *v[1], *v[2]) : Orientation3(*v[0], *v[1], *v[2], *v[3]);
}

// The working state of a smoothing run: positions in index space, the current elements and the
// stars of their vertices.
class Smoother
{
public:
  Smoother(const SimplexMesh& mesh, const std::vector<std::uint8_t>& freeAxes)
    : Topology(mesh)
    , Points(mesh.Points())
    , Anchor(mesh.Points())
    , Free(freeAxes)
    , Vpc(mesh.VerticesPerCell())
  {
  }

  // The worst AngleScore over the elements of a star, in frame coordinates, with vertex `moved` at
  // `at` (index space); -2 when an element is not positively oriented (exactly, in index space).
  // Stops at the first element below `floor`, returning its score: callers that only ask whether
  // the star reaches `floor` need not score the rest.
  double StarQuality(const std::int64_t* star, std::int64_t n, std::int64_t moved, const V3& at,
    double floor = -std::numeric_limits<double>::infinity()) const
  {
    const ImageGeometry& g = this->Topology.Geometry();
    double q = 1.0;
    for (std::int64_t s = 0; s < n; ++s)
    {
      const std::int64_t* cell = this->Topology.Cell(star[s]);
      const V3* v[4];
      V3 frame[4];
      for (int k = 0; k < this->Vpc; ++k)
      {
        v[k] = cell[k] == moved ? &at : &this->Points[cell[k]];
      }
      if (ExactOrientation(v, this->Vpc) <= 0)
      {
        return -2.0;
      }
      const V3* f[4];
      for (int k = 0; k < this->Vpc; ++k)
      {
        frame[k] = g.IndexToFrame(*v[k]);
        f[k] = &frame[k];
      }
      q = std::min(q, SimplexAngleScore(f, this->Vpc));
      if (q < floor)
      {
        return q;
      }
    }
    return q;
  }

  // Rounds to the lattice and into the box, keeping locked axes where they were; a fixed node with
  // slack stays within Slack (frame units) of its anchor, in the plane normal to its edge normal.
  V3 Constrain(std::int64_t vertex, const V3& wanted) const
  {
    const ImageGeometry& g = this->Topology.Geometry();
    V3 target = wanted;
    if (!this->Normal.empty() && this->Normal[vertex] != V3{ { 0, 0, 0 } })
    {
      const V3 a = g.IndexToFrame(this->Anchor[vertex]);
      const V3 t = g.IndexToFrame(wanted);
      V3 d = Sub(t, a);
      const V3& n = this->Normal[vertex];
      const double along = Dot(d, n);
      for (int k = 0; k < 3; ++k)
      {
        d[k] -= along * n[k];
      }
      const double length = std::sqrt(Dot(d, d));
      const double scale = length > this->Slack ? this->Slack / length : 1.0;
      target = g.FrameToIndex({ { a[0] + scale * d[0], a[1] + scale * d[1], a[2] + scale * d[2] } });
    }
    V3 p = this->Points[vertex];
    for (int a = 0; a < 3; ++a)
    {
      if (this->Free[vertex] & (1 << a))
      {
        p[a] = std::min(std::max(std::round(target[a] * Lattice) / Lattice, 0.0), g.Dims[a] - 1.0);
      }
    }
    return p;
  }

  // StarQuality at the current positions, through a per-element cache (Score, NaN = stale).
  double CurrentStarQuality(const std::int64_t* star, std::int64_t n)
  {
    double q = 1.0;
    for (std::int64_t s = 0; s < n; ++s)
    {
      double& score = this->Score[star[s]];
      if (std::isnan(score))
      {
        score = this->StarQuality(star + s, 1, -1, V3{ { 0, 0, 0 } });
      }
      q = std::min(q, score);
    }
    return q;
  }

  // Tries to move `vertex` towards `target` (index space): the first of the step fractions whose
  // star stays positively oriented and at least as good as before. True when it moved. Touches
  // only the vertex and its star's cached scores: vertices that share no element may move at once.
  bool TryMove(std::int64_t vertex, const V3& target, const std::int64_t* star, std::int64_t n)
  {
    const V3 from = this->Points[vertex];
    const double before = this->CurrentStarQuality(star, n);
    for (const double t : StepFractions)
    {
      const V3 to = this->Constrain(vertex,
        { { from[0] + t * (target[0] - from[0]), from[1] + t * (target[1] - from[1]), from[2] + t * (target[2] - from[2]) } });
      if (to == from)
      {
        return false;
      }
      const double after = this->StarQuality(star, n, vertex, to, before);
      if (after > -2.0 && after >= before)
      {
        this->Points[vertex] = to;
        for (std::int64_t k = 0; k < n; ++k)
        {
          this->Score[star[k]] = Stale;
        }
        return true;
      }
    }
    return false;
  }

  SimplexMesh Topology;
  std::vector<V3> Points;
  // Where the nodes started; for fixed nodes with slack, their edge normal (unit, frame
  // coordinates; zero for every other node) and the slack radius (frame units).
  std::vector<V3> Anchor;
  std::vector<V3> Normal;
  double Slack = 0.0;
  std::vector<std::uint8_t> Free;
  // Cached AngleScore per element (NaN: to compute).
  std::vector<double> Score;
  int Vpc;
};

// Lawson flips to the Delaunay triangulation (frame coordinates, exact in-circle test): the
// Delaunay triangulation maximises the smallest angle over all triangulations of the nodes, the
// quantity this stage raises. Hull edges (the box) never flip. Returns the number of flips.
// nb[3t + k]: the triangle across the edge opposite local vertex k of t, -1 on the hull.
std::vector<std::int64_t> TriangleNeighbours(const SimplexMesh& mesh)
{
  std::vector<std::int64_t> nb(3 * mesh.NumberOfElements(), -1);
  const FaceAdjacency& faces = mesh.Faces();
  for (size_t i = 0; i < faces.A.size(); ++i)
  {
    nb[3 * faces.A[i] + faces.LocalA[i]] = faces.B[i];
    nb[3 * faces.B[i] + faces.LocalB[i]] = faces.A[i];
  }
  return nb;
}

// Lawson flips to the Delaunay triangulation (frame coordinates, exact in-circle test): the
// Delaunay triangulation maximises the smallest angle over all triangulations of the nodes, the
// quantity this stage raises. Hull edges (the box) never flip. Only edges of triangles with a
// moved vertex can have become non-Delaunay: they seed the flips. `nb` (TriangleNeighbours) is
// kept up to date. Returns the number of flips.
std::int64_t DelaunayFlips(const ImageGeometry& g, const std::vector<V3>& indexPoints, const std::vector<std::uint8_t>& moved,
  std::vector<std::int64_t>& cells, std::vector<std::int64_t>& nb)
{
  std::vector<V3> P(indexPoints.size());
  std::transform(indexPoints.begin(), indexPoints.end(), P.begin(), [&](const V3& p) { return g.IndexToFrame(p); });
  const std::int64_t m = static_cast<std::int64_t>(cells.size() / 3);
  auto local = [&](std::int64_t t, std::int64_t v) {
    return cells[3 * t] == v ? 0 : (cells[3 * t + 1] == v ? 1 : 2);
  };
  auto across = [&](std::int64_t t, std::int64_t other) {
    return nb[3 * t] == other ? 0 : (nb[3 * t + 1] == other ? 1 : 2);
  };
  std::vector<std::pair<std::int64_t, int>> stack;
  for (std::int64_t t = m - 1; t >= 0; --t)
  {
    if (!moved[cells[3 * t]] && !moved[cells[3 * t + 1]] && !moved[cells[3 * t + 2]])
    {
      continue;
    }
    for (int k = 2; k >= 0; --k)
    {
      if (nb[3 * t + k] >= 0)
      {
        stack.emplace_back(t, k);
      }
    }
  }
  std::int64_t flips = 0;
  while (!stack.empty())
  {
    const auto [t, k] = stack.back();
    stack.pop_back();
    const std::int64_t u = nb[3 * t + k];
    if (u < 0)
    {
      continue;
    }
    const std::int64_t a = cells[3 * t + k], p = cells[3 * t + (k + 1) % 3], q = cells[3 * t + (k + 2) % 3];
    const int m2 = across(u, t);
    const std::int64_t d = cells[3 * u + m2];
    if (InCircle(P[a], P[p], P[q], P[d]) <= 0 || Orientation2(P[a], P[p], P[d]) <= 0 ||
      Orientation2(P[a], P[d], P[q]) <= 0)
    {
      continue;
    }
    // Outer neighbours: of t across (a, p) and (q, a); of u across (p, d) and (d, q).
    const std::int64_t tAP = nb[3 * t + (k + 2) % 3], tQA = nb[3 * t + (k + 1) % 3];
    const std::int64_t uPD = nb[3 * u + local(u, q)], uDQ = nb[3 * u + local(u, p)];
    // t becomes (a, p, d), u becomes (a, d, q).
    cells[3 * t] = a, cells[3 * t + 1] = p, cells[3 * t + 2] = d;
    cells[3 * u] = a, cells[3 * u + 1] = d, cells[3 * u + 2] = q;
    nb[3 * t] = uPD, nb[3 * t + 1] = u, nb[3 * t + 2] = tAP;
    nb[3 * u] = uDQ, nb[3 * u + 1] = tQA, nb[3 * u + 2] = t;
    if (uPD >= 0)
    {
      nb[3 * uPD + across(uPD, u)] = t;
    }
    if (tQA >= 0)
    {
      nb[3 * tQA + across(tQA, t)] = u;
    }
    ++flips;
    // The four outer edges may have become non-Delaunay.
    stack.emplace_back(t, 0);
    stack.emplace_back(t, 2);
    stack.emplace_back(u, 0);
    stack.emplace_back(u, 1);
  }
  return flips;
}

// Nodes within this many voxels of a box face (along its normal) are moved onto it before the 3D
// refinement, which keeps the box faces as they are: a node one voxel off the box leaves a slab one
// voxel thick between it and the face, and nodes spread several voxels along the face can only fill
// it with flat tetrahedra (the liver's worst, 8.1 degrees, all stood there).
constexpr double BoxSnapVoxels = 1.5;

// Moves the nodes within BoxSnapVoxels of box faces onto them (index space; near two faces, onto
// their edge), unless a box node already lies within a quarter voxel of where it would land. Along
// an axis thinner than the other two both distances are in its median-axis voxels (m of its own),
// as Feature Nodes spaces its nodes there. Returns how many moved.
std::int64_t SnapNodesToBox(const ImageGeometry& g, std::vector<V3>& points)
{
  const std::array<int, 3> m = g.MedianVoxelFactors();
  // Box nodes by median-axis voxel, for the quarter-voxel test.
  std::map<std::array<std::int64_t, 3>, std::vector<V3>> boxNodes;
  auto voxel = [&](const V3& q) {
    return std::array<std::int64_t, 3>{ { std::llround(q[0] / m[0]), std::llround(q[1] / m[1]),
      std::llround(q[2] / m[2]) } };
  };
  auto onBox = [&](const V3& q) {
    for (int a = 0; a < 3; ++a)
    {
      if (g.Dims[a] > 1 && (q[a] == 0.0 || q[a] == g.Dims[a] - 1.0))
      {
        return true;
      }
    }
    return false;
  };
  for (const V3& q : points)
  {
    if (onBox(q))
    {
      boxNodes[voxel(q)].push_back(q);
    }
  }
  auto crowded = [&](const V3& to) {
    const std::array<std::int64_t, 3> at = voxel(to);
    for (int d0 = -1; d0 <= 1; ++d0)
    {
      for (int d1 = -1; d1 <= 1; ++d1)
      {
        for (int d2 = -1; d2 <= 1; ++d2)
        {
          const auto it = boxNodes.find({ { at[0] + d0, at[1] + d1, at[2] + d2 } });
          if (it == boxNodes.end())
          {
            continue;
          }
          for (const V3& q : it->second)
          {
            if (std::fabs(q[0] - to[0]) < 0.25 * m[0] && std::fabs(q[1] - to[1]) < 0.25 * m[1] &&
              std::fabs(q[2] - to[2]) < 0.25 * m[2])
            {
              return true;
            }
          }
        }
      }
    }
    return false;
  };
  std::int64_t moved = 0;
  for (V3& q : points)
  {
    if (onBox(q))
    {
      continue;
    }
    V3 to = q;
    for (int a = 0; a < 3; ++a)
    {
      const double last = g.Dims[a] - 1.0, snap = BoxSnapVoxels * m[a];
      if (g.Dims[a] > 1 && to[a] <= snap)
      {
        to[a] = 0.0;
      }
      else if (g.Dims[a] > 1 && last - to[a] <= snap)
      {
        to[a] = last;
      }
    }
    if (to != q && !crowded(to))
    {
      q = to;
      boxNodes[voxel(to)].push_back(to);
      ++moved;
    }
  }
  return moved;
}

// Raises the minimum dihedral angle of slivers, keeping the topology: each free vertex of a
// tetrahedron whose minimum dihedral angle is below `sliverAngle` tries steps along the normals of
// its slivers' opposite faces (the directions that open a flat tetrahedron) and along the axes,
// of 1/4, 1/8 and 1/16 of its shortest edge, and takes the one that most improves its star's worst
// element. Vertices in id order, passes until none moves. Returns the moves made.
// A tetrahedron's vertices in frame coordinates, and pointers to them.
void ElementFrame(const Smoother& s, std::int64_t e, V3* frame, const V3** v)
{
  const std::int64_t* cell = s.Topology.Cell(e);
  for (int k = 0; k < 4; ++k)
  {
    frame[k] = s.Topology.Geometry().IndexToFrame(s.Points[cell[k]]);
    v[k] = &frame[k];
  }
}

// SimplexAngleScore of tetrahedron e as the points stand.
double ElementScore(const Smoother& s, std::int64_t e)
{
  V3 frame[4];
  const V3* v[4];
  ElementFrame(s, e, frame, v);
  return SimplexAngleScore(v, 4);
}

// One free vertex of a sliver: the best of short steps (1/4, 1/8, 1/16 of its shortest edge) along
// the slivers' opposite-face normals and the axes, taken when it raises its star's quality; true
// when the vertex moved.
bool PerturbVertex(Smoother& s, std::int64_t vertex, double threshold)
{
  const ImageGeometry& g = s.Topology.Geometry();
  const CompressedRows& stars = s.Topology.Stars();
  const std::int64_t* star = stars.Begin(vertex);
  const std::int64_t size = stars.Size(vertex);
  const V3 from = s.Points[vertex];
  const V3 at = g.IndexToFrame(from);
  // Directions (frame coordinates): the slivers' opposite-face normals, then the axes.
  std::vector<V3> directions;
  double shortest = 1e300;
  for (std::int64_t k = 0; k < size; ++k)
  {
    V3 frame[4];
    const V3* v[4];
    ElementFrame(s, star[k], frame, v);
    const std::int64_t* cell = s.Topology.Cell(star[k]);
    for (int l = 0; l < 4; ++l)
    {
      if (cell[l] != vertex)
      {
        const V3 d = Sub(frame[l], at);
        shortest = std::min(shortest, std::sqrt(Dot(d, d)));
      }
    }
    if (SimplexAngleScore(v, 4) >= threshold)
    {
      continue;
    }
    const int self = cell[0] == vertex ? 0 : (cell[1] == vertex ? 1 : (cell[2] == vertex ? 2 : 3));
    V3 n = Cross(Sub(frame[(self + 2) % 4], frame[(self + 1) % 4]), Sub(frame[(self + 3) % 4], frame[(self + 1) % 4]));
    if (Dot(n, Sub(at, frame[(self + 1) % 4])) < 0)
    {
      n = { { -n[0], -n[1], -n[2] } };
    }
    const double length = std::sqrt(Dot(n, n));
    if (length > 0.0)
    {
      directions.push_back({ { n[0] / length, n[1] / length, n[2] / length } });
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    for (const double sign : { 1.0, -1.0 })
    {
      V3 d = { { 0, 0, 0 } };
      d[a] = sign;
      directions.push_back(d);
    }
  }
  double best = s.StarQuality(star, size, -1, from);
  V3 bestAt = from;
  for (const double fraction : { 0.25, 0.125, 0.0625 })
  {
    for (const V3& d : directions)
    {
      V3 to = from;
      for (int a = 0; a < 3; ++a)
      {
        to[a] += fraction * shortest * d[a] / std::fabs(g.Spacing[a]);
      }
      to = s.Constrain(vertex, to);
      if (to == from)
      {
        continue;
      }
      // Only a star better than the best so far counts.
      const double q = s.StarQuality(star, size, vertex, to, std::nextafter(best, 2.0));
      if (q > best)
      {
        best = q;
        bestAt = to;
      }
    }
  }
  if (bestAt == from)
  {
    return false;
  }
  s.Points[vertex] = bestAt;
  return true;
}

std::int64_t PerturbSlivers(Smoother& s, double sliverAngle, int passes, const ParallelFor& parallel, const ProgressFunction& progress,
  bool& aborted)
{
  const std::int64_t m = s.Topology.NumberOfElements();
  const std::int64_t nPts = static_cast<std::int64_t>(s.Points.size());
  const CompressedRows& stars = s.Topology.Stars();
  const double threshold = AngleScoreAt(sliverAngle);
  // Sliver flags per element, kept current: only the stars of moved vertices change.
  auto isSliver = [&](std::int64_t e) { return ElementScore(s, e) < threshold; };
  std::vector<std::uint8_t> sliver(m);
  parallel(m, 4096, [&](std::int64_t b, std::int64_t e) {
    for (std::int64_t c = b; c < e; ++c)
    {
      sliver[c] = isSliver(c) ? 1 : 0;
    }
  });
  std::vector<std::int64_t> movedVertices;
  std::int64_t moved = 0;
  for (int pass = 0; pass < passes; ++pass)
  {
    for (const std::int64_t vertex : movedVertices)
    {
      for (const std::int64_t* e = stars.Begin(vertex); e != stars.End(vertex); ++e)
      {
        sliver[*e] = isSliver(*e) ? 1 : 0;
      }
    }
    movedVertices.clear();
    // Free vertices of slivers, in id order.
    std::vector<std::uint8_t> candidate(nPts, 0);
    for (std::int64_t e = 0; e < m; ++e)
    {
      if (sliver[e])
      {
        for (int k = 0; k < 4; ++k)
        {
          candidate[s.Topology.Cell(e)[k]] = 1;
        }
      }
    }
    std::int64_t movedThisPass = 0;
    for (std::int64_t vertex = 0; vertex < nPts; ++vertex)
    {
      if ((vertex & 4095) == 0 && !progress((pass + static_cast<double>(vertex) / nPts) / passes))
      {
        aborted = true;
        return moved;
      }
      if (candidate[vertex] && s.Free[vertex] && PerturbVertex(s, vertex, threshold))
      {
        movedVertices.push_back(vertex);
        ++movedThisPass;
      }
    }
    moved += movedThisPass;
    if (!movedThisPass)
    {
      break;
    }
  }
  return moved;
}
} // namespace

std::string ValidateParameters(const ImageMeshSmoothingParameters& p)
{
  if (p.Iterations < 0 || p.Iterations > 100)
  {
    return "the number of iterations must be in [0, 100].";
  }
  if (!(p.Sigma > 0.0 && p.Sigma <= 20.0))
  {
    return "the smoothing sigma must be in (0, 20] voxels.";
  }
  if (!(p.FeatureWeight >= 0.0 && p.FeatureWeight <= 1e6))
  {
    return "the feature weight must be in [0, 1e6].";
  }
  if (!(p.FixedNodeSlack >= 0.0 && p.FixedNodeSlack <= 2.0))
  {
    return "the fixed-node slack must be in [0, 2] voxels.";
  }
  if (!(p.MinAngle >= 0.0 && p.MinAngle <= 20.7))
  {
    return "the refinement's minimum angle must be in [0, 20.7] degrees (beyond it refinement may not end).";
  }
  if (!(p.MinDihedralAngle >= 0.0 && p.MinDihedralAngle < 30.0))
  {
    return "the refinement's minimum dihedral angle must be in [0, 30) degrees.";
  }
  if (!(p.DihedralFloor >= 0.0 && p.DihedralFloor < 30.0))
  {
    return "the dihedral floor must be in [0, 30) degrees.";
  }
  if (!(p.MaxDihedralAngle >= 120.0 && p.MaxDihedralAngle <= 179.0))
  {
    return "the optimisation's maximum dihedral angle must be in [120, 179] degrees.";
  }
  if (!(p.SliverAngle >= 0.0 && p.SliverAngle <= 30.0))
  {
    return "the sliver angle must be in [0, 30] degrees.";
  }
  return std::string();
}

double ElementDensity(const SimplexMesh& mesh, const std::vector<V3>& points, std::int64_t element, const float* gradient,
  double meanGradient, double featureWeight)
{
  if (!(meanGradient > 0.0) || featureWeight == 0.0)
  {
    return 1.0;
  }
  const int vpc = mesh.VerticesPerCell();
  const std::int64_t* cell = mesh.Cell(element);
  double centroid[3] = { 0, 0, 0 };
  for (int k = 0; k < vpc; ++k)
  {
    for (int a = 0; a < 3; ++a)
    {
      centroid[a] += points[cell[k]][a] / vpc;
    }
  }
  // The centroid, then the centroid of the sub-simplex joining it to face f (opposite vertex f):
  // (centroid + sum of the face's vertices) / vpc.
  double g = InterpolateAt(gradient, mesh.Geometry(), centroid);
  for (int f = 0; f < vpc; ++f)
  {
    double sample[3];
    for (int a = 0; a < 3; ++a)
    {
      double sum = centroid[a];
      for (int k = 0; k < vpc; ++k)
      {
        sum += k == f ? 0.0 : points[cell[k]][a];
      }
      sample[a] = sum / vpc;
    }
    g += InterpolateAt(gradient, mesh.Geometry(), sample);
  }
  return 1.0 + featureWeight * (g / (vpc + 1)) / meanGradient;
}

V3 SmoothingTarget(const SimplexMesh& mesh, const std::vector<V3>& points, const std::int64_t* star,
  std::int64_t starSize, const double* density, SmoothingMethod method)
{
  const ImageGeometry& g = mesh.Geometry();
  const int vpc = mesh.VerticesPerCell();
  const V3 boxHigh = g.IndexToFrame({ { g.Dims[0] - 1.0, g.Dims[1] - 1.0, g.Dims[2] - 1.0 } });
  double weightSum = 0.0;
  V3 sum = { { 0, 0, 0 } };
  for (std::int64_t s = 0; s < starSize; ++s)
  {
    const std::int64_t* cell = mesh.Cell(star[s]);
    V3 frame[4];
    const V3* v[4];
    for (int k = 0; k < vpc; ++k)
    {
      frame[k] = g.IndexToFrame(points[cell[k]]);
      v[k] = &frame[k];
    }
    V3 centre = { { 0, 0, 0 } };
    if (method == SmoothingMethod::ODT && Circumcentre(v, vpc, centre))
    {
      for (int a = 0; a < 3; ++a)
      {
        centre[a] = std::min(std::max(centre[a], 0.0), boxHigh[a]);
      }
    }
    else
    {
      for (int k = 0; k < vpc; ++k)
      {
        for (int a = 0; a < 3; ++a)
        {
          centre[a] += frame[k][a] / vpc;
        }
      }
    }
    const double w = density[s] * Measure(v, vpc);
    weightSum += w;
    for (int a = 0; a < 3; ++a)
    {
      sum[a] += w * centre[a];
    }
  }
  if (!(weightSum > 0.0))
  {
    return { { Stale, Stale, Stale } };
  }
  return g.FrameToIndex({ { sum[0] / weightSum, sum[1] / weightSum, sum[2] / weightSum } });
}

namespace
{
// Step 1: the smoothed image (the fixed nodes' slide normals) and its gradient magnitude (the
// density), each made only when a parameter asks for it. False when progress asked to abort.
struct FeatureImages
{
  std::vector<float> Smoothed, Gradient;
  double MeanGradient = 0.0;
};
bool MakeFeatureImages(const float* values, const ImageGeometry& g, const ImageMeshSmoothingParameters& p,
  const ParallelFor& parallel, const ProgressFunction& progress, FeatureImages& out)
{
  if ((p.FeatureWeight != 0.0 || p.FixedNodeSlack > 0.0) && p.Iterations > 0)
  {
    AssignFresh(out.Smoothed, static_cast<size_t>(g.Size()));
    GaussianSmooth(values, out.Smoothed.data(), g, p.Sigma, parallel);
    if (!progress(0.0))
    {
      return false;
    }
  }
  if (p.FeatureWeight != 0.0 && p.Iterations > 0)
  {
    AssignFresh(out.Gradient, out.Smoothed.size());
    GradientMagnitude(out.Smoothed.data(), g, out.Gradient.data(), parallel);
    out.MeanGradient = std::accumulate(out.Gradient.begin(), out.Gradient.end(), 0.0) / static_cast<double>(out.Gradient.size());
  }
  return true;
}

// Step 2: fixed nodes that may slide (FixedNodeSlack) move only across the image's edge: each gets
// the smoothed image's gradient direction as its normal; without one it stays.
void SetSlideNormals(Smoother& s, const std::vector<std::uint8_t>& fixed, const std::vector<std::uint8_t>& freeAxes,
  const std::vector<float>& smoothed, const ImageGeometry& g, double slack)
{
  const std::int64_t n = static_cast<std::int64_t>(s.Points.size());
  const int vpc = s.Topology.VerticesPerCell();
  // Voxels to frame units: the finest spacing of the image's axes.
  s.Slack = slack * g.FinestSpacing();
  s.Normal.assign(n, V3{ { 0, 0, 0 } });
  for (std::int64_t v = 0; v < n; ++v)
  {
    if (v >= static_cast<std::int64_t>(fixed.size()) || !fixed[v] || !freeAxes[v])
    {
      continue;
    }
    // Central differences of the smoothed image at the node, per frame unit.
    V3 normal = { { 0, 0, 0 } };
    for (int a = 0; a < vpc - 1; ++a)
    {
      double lo[3] = { s.Anchor[v][0], s.Anchor[v][1], s.Anchor[v][2] }, hi[3] = { lo[0], lo[1], lo[2] };
      lo[a] -= 0.5;
      hi[a] += 0.5;
      normal[a] = (InterpolateAt(smoothed.data(), g, hi) - InterpolateAt(smoothed.data(), g, lo)) / std::fabs(g.Spacing[a]);
    }
    const double length = std::sqrt(Dot(normal, normal));
    if (length > 0.0)
    {
      s.Normal[v] = { { normal[0] / length, normal[1] / length, normal[2] / length } };
    }
    else
    {
      s.Free[v] = 0; // no edge direction: stays fixed
    }
  }
}

// Step 3a: multicolour Gauss-Seidel classes. Nodes of one colour share no element, so they move at
// once (any thread count gives the same result); colours greedily in node order, classes in colour
// order: class c is byColour[start[c] .. start[c + 1]).
void ColourClasses(const Smoother& s, std::vector<std::int64_t>& start, std::vector<std::int64_t>& byColour)
{
  const CompressedRows& stars = s.Topology.Stars();
  const std::int64_t n = static_cast<std::int64_t>(s.Points.size());
  const int vpc = s.Topology.VerticesPerCell();
  std::vector<int> colour(n, -1);
  std::vector<int> lastSeen;
  int colours = 0;
  for (std::int64_t v = 0; v < n; ++v)
  {
    if (!s.Free[v] || stars.Size(v) == 0)
    {
      continue;
    }
    // Neighbours through the star (cheaper than building the vertex-neighbour rows).
    for (const std::int64_t* e = stars.Begin(v); e != stars.End(v); ++e)
    {
      const std::int64_t* cell = s.Topology.Cell(*e);
      for (int k = 0; k < vpc; ++k)
      {
        if (colour[cell[k]] >= 0)
        {
          lastSeen[colour[cell[k]]] = static_cast<int>(v);
        }
      }
    }
    int c = 0;
    while (c < colours && lastSeen[c] == v)
    {
      ++c;
    }
    if (c == colours)
    {
      ++colours;
      lastSeen.push_back(-1);
    }
    colour[v] = c;
  }
  start.assign(colours + 1, 0);
  for (std::int64_t v = 0; v < n; ++v)
  {
    start[colour[v] + 1] += colour[v] >= 0 ? 1 : 0;
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  byColour.resize(start[colours]);
  std::vector<std::int64_t> fill(start.begin(), start.end() - 1);
  for (std::int64_t v = 0; v < n; ++v)
  {
    if (colour[v] >= 0)
    {
      byColour[fill[colour[v]]++] = v;
    }
  }
}

// Step 3b: one sweep, every free node moved towards its star's CVT/ODT target (the elements'
// densities computed when a node first needs them). `progress` spans the sweep; false when it
// asked to abort.
bool Sweep(Smoother& s, const FeatureImages& images, const ImageMeshSmoothingParameters& p, const ParallelFor& parallel,
  const ProgressFunction& progress, std::vector<std::uint8_t>& moved)
{
  const CompressedRows& stars = s.Topology.Stars();
  std::vector<double> elementDensity(s.Topology.NumberOfElements(), -1.0);
  std::fill(moved.begin(), moved.end(), 0);
  std::vector<std::int64_t> classStart, byColour;
  ColourClasses(s, classStart, byColour);
  const int colours = static_cast<int>(classStart.size()) - 1;
  s.Score.assign(s.Topology.NumberOfElements(), Stale);
  for (int c = 0; c < colours; ++c)
  {
    if (!progress(0.9 * c / static_cast<double>(colours)))
    {
      return false;
    }
    parallel(classStart[c + 1] - classStart[c], 256, [&](std::int64_t b, std::int64_t e) {
      std::vector<double> density;
      for (std::int64_t i = classStart[c] + b; i < classStart[c] + e; ++i)
      {
        const std::int64_t v = byColour[i];
        const std::int64_t* star = stars.Begin(v);
        const std::int64_t size = stars.Size(v);
        density.resize(size);
        for (std::int64_t k = 0; k < size; ++k)
        {
          double& rho = elementDensity[star[k]];
          if (rho < 0.0)
          {
            rho = images.Gradient.empty()
              ? 1.0
              : ElementDensity(s.Topology, s.Points, star[k], images.Gradient.data(), images.MeanGradient, p.FeatureWeight);
          }
          density[k] = rho;
        }
        const V3 target = SmoothingTarget(s.Topology, s.Points, star, size, density.data(), p.Method);
        if (std::isfinite(target[0]) && s.TryMove(v, target, star, size))
        {
          moved[v] = 1;
        }
      }
    });
  }
  return true;
}

// Step 3c: the Delaunay property back after a sweep: flips in 2D, CGAL's triangulation of the moved
// nodes in 3D (the same ids, so node arrays still apply). False with `error` or when aborted.
bool RestoreDelaunay(Smoother& s, const std::vector<std::uint8_t>& moved, std::vector<std::int64_t>& neighbours,
  const ProgressFunction& progress, std::int64_t& flips, bool& aborted, std::string& error)
{
  const ImageGeometry& g = s.Topology.Geometry();
  const int vpc = s.Topology.VerticesPerCell();
  std::vector<std::int64_t> cells;
  if (vpc == 3)
  {
    cells = s.Topology.Cells();
    flips += DelaunayFlips(g, s.Points, moved, cells, neighbours);
  }
  else
  {
    std::vector<V3> frame(s.Points.size());
    std::transform(s.Points.begin(), s.Points.end(), frame.begin(), [&](const V3& q) { return g.IndexToFrame(q); });
    const std::size_t nodes = frame.size();
    DelaunayImageMeshParameters o;
    o.Backend = DelaunayBackend::CGAL;
    // CGAL has no progress or abort of its own: it runs beside a heartbeat.
    DelaunayResult d;
    if (!RunWithHeartbeat<DelaunayResult>([frame = std::move(frame), o]() { return Tetrahedralize(frame, o); }, progress, d))
    {
      aborted = true;
      return false;
    }
    if (!d.Error.empty() || d.Points.size() != nodes)
    {
      error = "re-tetrahedralising the moved nodes failed: " + d.Error;
      return false;
    }
    cells = std::move(d.Cells);
  }
  // Positive orientation in frame coordinates is positive in index space (positive scales).
  s.Topology = SimplexMesh(g, s.Points, std::move(cells), vpc);
  return true;
}

// Step 4: quality refinement to the angle bounds (CGAL's 2D mesher, TetGen in 3D after snapping
// nodes near the box onto it); the added nodes are free. False with result.Error or when aborted.
bool RefineQuality(Smoother& s, const std::vector<std::uint8_t>& fixed, const ImageMeshSmoothingParameters& p,
  double maxDihedralAngle, const ProgressFunction& progress, ImageMeshSmoothingResult& result)
{
  const ImageGeometry& g = s.Topology.Geometry();
  const int vpc = s.Topology.VerticesPerCell();
  if (vpc == 4)
  {
    result.SnappedNodes = SnapNodesToBox(g, s.Points);
  }
  std::vector<V3> frame(s.Points.size());
  std::transform(s.Points.begin(), s.Points.end(), frame.begin(), [&](const V3& q) { return g.IndexToFrame(q); });
  DelaunayImageMeshParameters o;
  o.QualityRefinement = true;
  o.MinDihedralAngle = p.MinDihedralAngle;
  o.RadiusEdgeRatio = p.RadiusEdgeRatio;
  o.MaxDihedralAngle = maxDihedralAngle;
  o.PreserveBoundary = true;
  const double minAngle = p.MinAngle;
  const bool planar = vpc == 3;
  const std::size_t nodes = frame.size();
  // TetGen and CGAL's mesher have no progress or abort of their own: they run beside a heartbeat.
  DelaunayResult d;
  if (!RunWithHeartbeat<DelaunayResult>(
        [frame = std::move(frame), o, minAngle, planar]() {
          return planar ? RefineQuality2D(frame, minAngle) : Tetrahedralize(frame, o);
        },
        progress, d))
  {
    result.Aborted = true;
    return false;
  }
  if (!d.Error.empty() || d.Points.size() < nodes)
  {
    result.Error = "quality refinement failed: " + d.Error;
    return false;
  }
  ++result.RefinementRuns;
  result.AddedNodes = static_cast<std::int64_t>(d.Points.size() - nodes);
  std::vector<V3> index = s.Points;
  for (size_t i = nodes; i < d.Points.size(); ++i)
  {
    index.push_back(g.FrameToIndex(d.Points[i]));
  }
  SimplexMesh refined(g, std::move(index), std::move(d.Cells), vpc);
  refined.OrientPositively();
  std::vector<std::uint8_t> fixedAll(fixed);
  fixedAll.resize(refined.NumberOfPoints(), 0);
  Smoother r(refined, FreeAxes(refined, fixedAll));
  s = std::move(r);
  return true;
}

// Step 5: 2-3 / 3-2 flips around the slivers no vertex of which may move (Canny nodes: only the
// connectivity can change there), then perturbation of the others' free vertices. False when
// progress asked to abort.
bool RemoveSlivers(Smoother& s, double sliverAngle, const ParallelFor& parallel, const ProgressFunction& progress,
  ImageMeshSmoothingResult& result)
{
  std::vector<std::int64_t> cells = s.Topology.Cells();
  const std::int64_t flips = FlipSlivers(s.Topology.Geometry(), s.Points, cells, sliverAngle, 4, &s.Free);
  result.SliverFlips += flips;
  if (flips > 0)
  {
    Smoother flipped(SimplexMesh(s.Topology.Geometry(), s.Points, std::move(cells), 4), s.Free);
    s = std::move(flipped);
  }
  result.Perturbed += PerturbSlivers(s, sliverAngle, 10, parallel, progress, result.Aborted);
  if (result.Aborted)
  {
    return false;
  }
  s.Topology.SetPoints(s.Points);
  return true;
}

// The last resort for a few tetrahedra still under `degrees` after flips and perturbation: four fixed
// (feature) nodes that no flip improves. Their vertices, fixed ones included (off the image box's
// faces only within them), take perturbation's short steps, up to three rounds. True when every
// element then reaches `degrees`; false at once when more than `most` miss it (for those steps 4-5
// run again); true at once, nothing moved, when none is under it. Far cheaper than running steps
// 4-5 again for one tetrahedron of millions.
bool MoveFixedAroundSlivers(Smoother& s, double degrees, std::int64_t most, std::int64_t& moved)
{
  const double threshold = AngleScoreAt(degrees);
  const ImageGeometry& g = s.Topology.Geometry();
  auto below = [&]() {
    std::vector<std::int64_t> bad;
    for (std::int64_t e = 0; e < s.Topology.NumberOfElements(); ++e)
    {
      if (ElementScore(s, e) < threshold)
      {
        bad.push_back(e);
      }
    }
    return bad;
  };
  std::vector<std::int64_t> bad = below();
  if (bad.empty() || static_cast<std::int64_t>(bad.size()) > most)
  {
    return bad.empty();
  }
  for (int round = 0; round < 3 && !bad.empty(); ++round)
  {
    for (const std::int64_t e : bad)
    {
      for (int k = 0; k < 4 && ElementScore(s, e) < threshold; ++k)
      {
        const std::int64_t v = s.Topology.Cell(e)[k];
        const std::uint8_t free = s.Free[v];
        for (int a = 0; a < 3; ++a)
        {
          if (s.Points[v][a] != 0.0 && s.Points[v][a] != g.Dims[a] - 1.0)
          {
            s.Free[v] |= static_cast<std::uint8_t>(1 << a);
          }
        }
        moved += PerturbVertex(s, v, threshold) ? 1 : 0;
        s.Free[v] = free;
      }
    }
    bad = below();
  }
  s.Topology.SetPoints(s.Points);
  return bad.empty();
}

// True when every element's smallest dihedral angle is at least `degrees`.
bool ReachesAngle(const Smoother& s, double degrees)
{
  const double threshold = AngleScoreAt(degrees);
  for (std::int64_t e = 0; e < s.Topology.NumberOfElements(); ++e)
  {
    if (ElementScore(s, e) < threshold)
    {
      return false;
    }
  }
  return true;
}
} // namespace

bool PerturbSliverVertices(SimplexMesh& mesh, double degrees, std::int64_t most, std::int64_t& moved)
{
  // Every node counts as fixed: the last resort frees what it moves.
  Smoother s(mesh, std::vector<std::uint8_t>(mesh.NumberOfPoints(), 0));
  const bool reached = MoveFixedAroundSlivers(s, degrees, most, moved);
  mesh = std::move(s.Topology);
  return reached;
}

ImageMeshSmoothingResult SmoothImageMesh(const SimplexMesh& mesh, const std::vector<std::uint8_t>& fixed, const float* values,
  const ImageMeshSmoothingParameters& p, const ParallelFor& parallel, const ProgressFunction& progress)
{
  ImageMeshSmoothingResult result;
  using Clock = std::chrono::steady_clock;
  auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  auto t0 = Clock::now();
  const ImageGeometry& g = mesh.Geometry();
  const int vpc = mesh.VerticesPerCell();
  // 1-2. The feature images; the free nodes, and the normals of fixed nodes that may slide.
  FeatureImages images;
  if (!MakeFeatureImages(values, g, p, parallel, progress, images))
  {
    result.Aborted = true;
    return result;
  }
  const bool slide = p.FixedNodeSlack > 0.0;
  const std::vector<std::uint8_t> freeAxes = FreeAxes(mesh, fixed, slide);
  Smoother s(mesh, freeAxes);
  if (slide && !images.Smoothed.empty())
  {
    SetSlideNormals(s, fixed, freeAxes, images.Smoothed, g, p.FixedNodeSlack);
  }
  // Only the gradient magnitude is read from here on: 4 bytes per voxel less while the mesher runs.
  std::vector<float>().swap(images.Smoothed);
  const int sweeps = std::max(0, p.Iterations);
  const bool perturb = vpc == 4 && p.SliverRemoval && sweeps > 0;
  // Progress: sweeps, then refinement, then slivers.
  const bool refine = p.QualityRefinement && sweeps > 0;
  const double sweepShare = refine ? 0.6 : (perturb ? 0.8 : 1.0);
  const double refineEnd = perturb ? 0.8 : 1.0;
  // 3. The sweeps, each followed by the Delaunay property's restoration.
  std::vector<std::int64_t> neighbours = vpc == 3 && p.Flips && sweeps > 0 ? TriangleNeighbours(mesh) : std::vector<std::int64_t>();
  std::vector<std::uint8_t> moved(mesh.NumberOfPoints());
  for (int it = 0; it < sweeps; ++it)
  {
    if (!Sweep(s, images, p, parallel, SubProgress(progress, sweepShare * it / sweeps, sweepShare * (it + 1) / sweeps), moved))
    {
      result.Aborted = true;
      return result;
    }
    result.Moves += std::count(moved.begin(), moved.end(), 1);
    // 3D refinement re-tetrahedralises the nodes itself: the last sweep need not.
    const bool refinedNext = vpc == 4 && p.QualityRefinement && it + 1 == sweeps;
    if (p.Flips && !refinedNext)
    {
      const double at = sweepShare * (it + 0.95) / sweeps;
      if (!RestoreDelaunay(s, moved, neighbours, [&](double) { return progress(at); }, result.Flips, result.Aborted, result.Error))
      {
        return result;
      }
    }
    else
    {
      s.Topology.SetPoints(s.Points);
    }
    result.IterationsRun = it + 1;
  }
  std::vector<float>().swap(images.Gradient);
  result.SweepSeconds = since(t0);
  // TetGen's optimisation flips by the largest dihedral angle and can undercut the smallest: when
  // the finished mesh misses DihedralFloor and the last resort cannot mend it, steps 4-5 run again
  // on the swept nodes with TetGen's own optimisation target.
  const double tetgenOwn = DelaunayImageMeshParameters().MaxDihedralAngle;
  const std::vector<V3> swept = vpc == 4 && refine && p.MaxDihedralAngle < tetgenOwn ? s.Points : std::vector<V3>();
  for (double maxDihedral = p.MaxDihedralAngle;; maxDihedral = tetgenOwn)
  {
    // 4. Quality refinement.
    t0 = Clock::now();
    if (refine && !RefineQuality(s, fixed, p, maxDihedral, SubProgress(progress, sweepShare, refineEnd), result))
    {
      return result;
    }
    result.RefinementSeconds += since(t0);
    // 5. Sliver removal: flips where no vertex may move, then perturbation.
    t0 = Clock::now();
    if (perturb && !RemoveSlivers(s, p.SliverAngle, parallel, SubProgress(progress, refine ? refineEnd : sweepShare, 1.0), result))
    {
      return result;
    }
    result.SliverSeconds += since(t0);
    // One scan of the elements: the last resort returns at once when none is under the floor.
    if (swept.empty() || maxDihedral == tetgenOwn ||
      (perturb ? MoveFixedAroundSlivers(s, p.DihedralFloor, 64, result.Perturbed) : ReachesAngle(s, p.DihedralFloor)))
    {
      break;
    }
    s.Points = swept;
  }
  result.Mesh = std::move(s.Topology);
  result.Mesh.SortElementsSpatially();
  return result;
}
} // namespace featuremesh
