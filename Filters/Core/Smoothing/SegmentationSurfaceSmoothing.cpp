#include "SegmentationSurfaceSmoothing.h"
#include "Vector3.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <unordered_map>

namespace featuremesh
{
namespace
{
using namespace vector3;
using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since)
{
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// Rows of ids from (row, id) pairs: each row sorted, duplicates dropped (a counting sort by row).
CompressedRows RowsFromPairs(std::int64_t rows, const std::vector<std::pair<std::int64_t, std::int64_t>>& pairs)
{
  std::vector<std::int64_t> offsets(rows + 1, 0), ids(pairs.size());
  for (const auto& p : pairs)
  {
    ++offsets[p.first + 1];
  }
  for (std::int64_t i = 0; i < rows; ++i)
  {
    offsets[i + 1] += offsets[i];
  }
  std::vector<std::int64_t> fill(offsets.begin(), offsets.end() - 1);
  for (const auto& p : pairs)
  {
    ids[fill[p.first]++] = p.second;
  }
  CompressedRows r;
  r.Offsets.assign(rows + 1, 0);
  r.Ids.reserve(ids.size());
  for (std::int64_t i = 0; i < rows; ++i)
  {
    const auto begin = ids.begin() + offsets[i], end = ids.begin() + offsets[i + 1];
    std::sort(begin, end);
    r.Ids.insert(r.Ids.end(), begin, std::unique(begin, end));
    r.Offsets[i + 1] = static_cast<std::int64_t>(r.Ids.size());
  }
  return r;
}

// The boundary as a graph on its own nodes (local ids): neighbours, and the nodes where it is not a
// manifold.
struct Boundary
{
  std::vector<std::int64_t> Node;  // local -> mesh point id
  std::vector<std::int64_t> Faces; // local ids, vpc - 1 per face
  // Neighbours over all faces, and over the interface faces alone (the first `interfaceFaces`).
  CompressedRows Neighbours, InterfaceNeighbours;
  std::vector<std::uint8_t> Pinched;
  std::int64_t NonManifoldEdges = 0;
};

Boundary BoundaryGraph(std::int64_t nPoints, const std::vector<std::int64_t>& faces, int faceSize, std::int64_t interfaceFaces)
{
  Boundary b;
  std::vector<std::int64_t> local(nPoints, -1);
  b.Faces.resize(faces.size());
  for (std::size_t i = 0; i < faces.size(); ++i)
  {
    std::int64_t& l = local[faces[i]];
    if (l < 0)
    {
      l = static_cast<std::int64_t>(b.Node.size());
      b.Node.push_back(faces[i]);
    }
    b.Faces[i] = l;
  }
  const std::int64_t n = static_cast<std::int64_t>(b.Node.size());
  const std::int64_t nFaces = static_cast<std::int64_t>(faces.size()) / faceSize;
  b.Pinched.assign(n, 0);
  std::vector<std::pair<std::int64_t, std::int64_t>> pairs;
  pairs.reserve(faces.size() * 2);
  if (faceSize == 2)
  {
    std::vector<int> degree(n, 0);
    for (std::int64_t f = 0; f < nFaces; ++f)
    {
      const std::int64_t a = b.Faces[2 * f], c = b.Faces[2 * f + 1];
      pairs.emplace_back(a, c);
      pairs.emplace_back(c, a);
      ++degree[a];
      ++degree[c];
    }
    for (std::int64_t i = 0; i < n; ++i)
    {
      b.Pinched[i] = degree[i] != 2;
    }
    b.Neighbours = RowsFromPairs(n, pairs);
    pairs.resize(2 * interfaceFaces);
    b.InterfaceNeighbours = RowsFromPairs(n, pairs);
    return b;
  }
  // 3D: directed edges a -> c of the faces (each face's three, in its orientation).
  std::vector<std::pair<std::int64_t, std::int64_t>> directed;
  directed.reserve(faces.size());
  for (std::int64_t f = 0; f < nFaces; ++f)
  {
    for (int k = 0; k < 3; ++k)
    {
      const std::int64_t a = b.Faces[3 * f + k], c = b.Faces[3 * f + (k + 1) % 3];
      directed.emplace_back(a, c);
      pairs.emplace_back(a, c);
      pairs.emplace_back(c, a);
    }
  }
  // An edge of other than two faces (each side once) pinches both its ends.
  std::vector<std::pair<std::int64_t, std::int64_t>> undirected(directed.size());
  std::transform(directed.begin(), directed.end(), undirected.begin(),
    [](const std::pair<std::int64_t, std::int64_t>& e) { return std::minmax(e.first, e.second); });
  std::sort(undirected.begin(), undirected.end());
  for (std::size_t i = 0; i < undirected.size();)
  {
    std::size_t j = i;
    while (j < undirected.size() && undirected[j] == undirected[i])
    {
      ++j;
    }
    if (j - i != 2)
    {
      ++b.NonManifoldEdges;
      b.Pinched[undirected[i].first] = b.Pinched[undirected[i].second] = 1;
    }
    i = j;
  }
  // A vertex whose faces make several fans: its link (the edge opposite it in each face) is not one
  // cycle.
  std::vector<std::pair<std::int64_t, std::int64_t>> incidence;
  incidence.reserve(faces.size());
  for (std::int64_t f = 0; f < nFaces; ++f)
  {
    for (int k = 0; k < 3; ++k)
    {
      incidence.emplace_back(b.Faces[3 * f + k], f);
    }
  }
  const CompressedRows star = RowsFromPairs(n, incidence);
  std::unordered_map<std::int64_t, std::int64_t> next;
  for (std::int64_t v = 0; v < n; ++v)
  {
    if (b.Pinched[v])
    {
      continue;
    }
    next.clear();
    for (const std::int64_t* f = star.Begin(v); f != star.End(v); ++f)
    {
      const std::int64_t* t = &b.Faces[3 * *f];
      const int k = t[0] == v ? 0 : t[1] == v ? 1 : 2;
      next[t[(k + 1) % 3]] = t[(k + 2) % 3];
    }
    std::int64_t steps = 0;
    std::int64_t x = next.begin()->first;
    do
    {
      const auto it = next.find(x);
      if (it == next.end())
      {
        break;
      }
      x = it->second;
      ++steps;
    } while (x != next.begin()->first && steps <= star.Size(v));
    b.Pinched[v] = !(x == next.begin()->first && steps == star.Size(v) && static_cast<std::int64_t>(next.size()) == steps);
  }
  b.Neighbours = RowsFromPairs(n, pairs);
  pairs.resize(6 * interfaceFaces);
  b.InterfaceNeighbours = RowsFromPairs(n, pairs);
  return b;
}

// With several labels, where three or more meet. Each interface face carries the pair of labels it
// separates; a boundary edge (3D) whose interface faces carry two or more pairs lies on a junction
// curve. A node on exactly two junction edges moves along the curve (the mean of those two
// neighbours); a node on one or more than two is a junction point (a curve's end, a branching, a
// curve meeting the box) and stays. In 2D a node where interfaces of two or more pairs meet is a
// junction point. Box faces carry no pair: where an interface meets the box its rim moves within
// the box as in the binary case.
struct Junctions
{
  std::vector<std::uint8_t> Fixed, OnCurve;
  CompressedRows Curve;
};

Junctions JunctionGraph(const SimplexMesh& mesh, const std::vector<std::uint8_t>& label, const Boundary& b,
  std::int64_t interfaceFaces)
{
  const std::int64_t n = static_cast<std::int64_t>(b.Node.size());
  const int vpc = mesh.VerticesPerCell(), faceSize = vpc - 1;
  // The label pair of every interface face, by its sorted mesh point ids.
  std::map<std::array<std::int64_t, 3>, int> pairOf;
  const FaceAdjacency& adj = mesh.Faces();
  for (std::size_t f = 0; f < adj.A.size(); ++f)
  {
    const int la = label[adj.A[f]], lb = label[adj.B[f]];
    if (la != lb)
    {
      std::array<std::int64_t, 3> key{ { -1, -1, -1 } };
      for (int k = 1; k < vpc; ++k)
      {
        key[k - 1] = mesh.Cell(adj.A[f])[(adj.LocalA[f] + k) % vpc];
      }
      std::sort(key.begin(), key.begin() + faceSize);
      pairOf[key] = 256 * std::min(la, lb) + std::max(la, lb);
    }
  }
  // (edge, pair) of each interface face's edges (3D) or nodes (2D), in local ids.
  std::vector<std::array<std::int64_t, 3>> incidence;
  for (std::int64_t f = 0; f < interfaceFaces; ++f)
  {
    const std::int64_t* local = &b.Faces[faceSize * f];
    std::array<std::int64_t, 3> key{ { -1, -1, -1 } };
    for (int k = 0; k < faceSize; ++k)
    {
      key[k] = b.Node[local[k]];
    }
    std::sort(key.begin(), key.begin() + faceSize);
    const auto it = pairOf.find(key);
    if (it == pairOf.end())
    {
      continue; // an unshared face off the box
    }
    for (int k = 0; k < faceSize; ++k)
    {
      if (faceSize == 2)
      {
        incidence.push_back({ { local[k], -1, it->second } });
      }
      else
      {
        const auto e = std::minmax(local[k], local[(k + 1) % 3]);
        incidence.push_back({ { e.first, e.second, it->second } });
      }
    }
  }
  std::sort(incidence.begin(), incidence.end());
  Junctions j;
  j.Fixed.assign(n, 0);
  j.OnCurve.assign(n, 0);
  std::vector<std::pair<std::int64_t, std::int64_t>> pairs;
  for (std::size_t i = 0; i < incidence.size();)
  {
    std::size_t k = i;
    int distinct = 0;
    for (; k < incidence.size() && incidence[k][0] == incidence[i][0] && incidence[k][1] == incidence[i][1]; ++k)
    {
      distinct += k == i || incidence[k][2] != incidence[k - 1][2];
    }
    if (distinct >= 2)
    {
      if (faceSize == 2)
      {
        j.Fixed[incidence[i][0]] = 1;
      }
      else
      {
        pairs.emplace_back(incidence[i][0], incidence[i][1]);
        pairs.emplace_back(incidence[i][1], incidence[i][0]);
      }
    }
    i = k;
  }
  j.Curve = RowsFromPairs(n, pairs);
  for (std::int64_t v = 0; v < n && faceSize == 3; ++v)
  {
    j.OnCurve[v] = j.Curve.Size(v) == 2;
    j.Fixed[v] = j.Curve.Size(v) > 0 && j.Curve.Size(v) != 2;
  }
  return j;
}

// Measure (area 2D, volume 3D; frame units) of the elements with a label other than 0.
double LabelledMeasure(const SimplexMesh& mesh, const std::vector<V3>& frame, const std::vector<std::uint8_t>& label)
{
  double sum = 0.0;
  const int vpc = mesh.VerticesPerCell();
  for (std::int64_t e = 0; e < mesh.NumberOfElements(); ++e)
  {
    if (label[e])
    {
      sum += std::fabs(ElementMeasure(frame, mesh.Cell(e), vpc));
    }
  }
  return sum;
}

// Enclosed measure of the boundary (frame coordinates): the divergence theorem over its faces.
double EnclosedMeasure(const std::vector<V3>& frame, const std::vector<std::int64_t>& faces, int faceSize)
{
  double sum = 0.0;
  for (std::size_t f = 0; f < faces.size(); f += faceSize)
  {
    const V3 &a = frame[faces[f]], &b = frame[faces[f + 1]];
    sum += faceSize == 2 ? a[0] * b[1] - a[1] * b[0] : Dot(a, Cross(b, frame[faces[f + 2]]));
  }
  return std::fabs(sum) / (faceSize == 2 ? 2.0 : 6.0);
}

// The labelled mesh while its nodes move: each move is taken only when the node's star stays
// positively oriented and above its floors.
struct VolumeMover
{
  const SimplexMesh& Mesh;
  const CompressedRows& Stars;
  std::vector<V3>& Frame;
  std::vector<double> CosFloor; // cosine of each element's quality floor
  int Vpc;

  // The largest cosine of the element's angles (2D) or dihedral angles (3D): its smallest angle,
  // compared without an inverse cosine.
  double MaxCosine(std::int64_t e) const
  {
    const std::int64_t* c = this->Mesh.Cell(e);
    double largest = -1.0;
    if (this->Vpc == 3)
    {
      for (int k = 0; k < 3; ++k)
      {
        const V3 u = Sub(this->Frame[c[(k + 1) % 3]], this->Frame[c[k]]);
        const V3 w = Sub(this->Frame[c[(k + 2) % 3]], this->Frame[c[k]]);
        largest = std::max(largest, Dot(u, w) / std::sqrt(Dot(u, u) * Dot(w, w)));
      }
      return largest;
    }
    // Outward face normals; the dihedral angle at the edge of faces k and l has cosine -n_k.n_l.
    V3 normal[4];
    for (int f = 0; f < 4; ++f)
    {
      const V3& a = this->Frame[c[(f + 1) % 4]];
      normal[f] = Cross(Sub(this->Frame[c[(f + 2) % 4]], a), Sub(this->Frame[c[(f + 3) % 4]], a));
      const double length = Norm(normal[f]) * (Dot(normal[f], Sub(this->Frame[c[f]], a)) > 0 ? -1.0 : 1.0);
      normal[f] = { { normal[f][0] / length, normal[f][1] / length, normal[f][2] / length } };
    }
    for (int k = 0; k < 4; ++k)
    {
      for (int l = k + 1; l < 4; ++l)
      {
        largest = std::max(largest, -Dot(normal[k], normal[l]));
      }
    }
    return largest;
  }

  bool Valid(std::int64_t e) const
  {
    return ElementMeasure(this->Frame, this->Mesh.Cell(e), this->Vpc) > 0.0 && this->MaxCosine(e) <= this->CosFloor[e];
  }

  // The star's largest cosine (lower is better), 2 when an element is inverted or flat.
  double StarCosine(std::int64_t node) const
  {
    double largest = -1.0;
    for (const std::int64_t* e = this->Stars.Begin(node); e != this->Stars.End(node); ++e)
    {
      if (!(ElementMeasure(this->Frame, this->Mesh.Cell(*e), this->Vpc) > 0.0))
      {
        return 2.0;
      }
      largest = std::max(largest, this->MaxCosine(*e));
    }
    return largest;
  }

  // Moves `node` to `to` when its star allows it; `improve` also asks for a better star minimum.
  bool TryMove(std::int64_t node, const V3& to, bool improve = false)
  {
    const V3 from = this->Frame[node];
    const double before = improve ? this->StarCosine(node) : 0.0;
    this->Frame[node] = to;
    bool ok = true;
    for (const std::int64_t* e = this->Stars.Begin(node); ok && e != this->Stars.End(node); ++e)
    {
      ok = this->Valid(*e);
    }
    if (ok && improve)
    {
      ok = this->StarCosine(node) < before;
    }
    if (!ok)
    {
      this->Frame[node] = from;
    }
    return ok;
  }
};

// The mean position of row `i`'s neighbours (a non-empty row).
V3 NeighbourMean(const CompressedRows& rows, std::int64_t i, const std::vector<V3>& positions)
{
  V3 mean = { { 0, 0, 0 } };
  const std::int64_t k = rows.Size(i);
  for (const std::int64_t* j = rows.Begin(i); j != rows.End(i); ++j)
  {
    for (int a = 0; a < 3; ++a)
    {
      mean[a] += positions[*j][a] / k;
    }
  }
  return mean;
}

V3 Masked(const V3& from, const V3& to, std::uint8_t axes)
{
  V3 r = from;
  for (int a = 0; a < 3; ++a)
  {
    if (axes & (1 << a))
    {
      r[a] = to[a];
    }
  }
  return r;
}

V3 Lerp(const V3& a, const V3& b, double t)
{
  return { { a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2]) } };
}
} // namespace

std::string ValidateParameters(const SegmentationSurfaceSmoothingParameters& p)
{
  if (p.Method != SurfaceSmoothingMethod::Laplacian && p.Method != SurfaceSmoothingMethod::Taubin)
  {
    return "Method must be 0 (Laplacian) or 1 (Taubin).";
  }
  if (p.Iterations < 0 || p.Iterations > 1000)
  {
    return "Iterations must be between 0 and 1000.";
  }
  if (!(p.Relaxation > 0.0 && p.Relaxation <= 1.0))
  {
    return "Relaxation must be in (0, 1].";
  }
  if (!(p.PassBand > 0.0 && p.PassBand < 1.0 / p.Relaxation))
  {
    return "PassBand must be positive and below 1 / Relaxation (Taubin's mu must be negative).";
  }
  if (!(p.MinAngle >= 0.0 && p.MinAngle <= 60.0) || !(p.MinDihedralAngle >= 0.0 && p.MinDihedralAngle <= 70.0))
  {
    return "MinAngle must be in [0, 60] and MinDihedralAngle in [0, 70] degrees.";
  }
  if (p.RelaxationRings < 0 || p.RelaxationRings > 20)
  {
    return "RelaxationRings must be between 0 and 20.";
  }
  return std::string();
}

namespace
{
// Step 1: the boundary nodes' smoothed positions (frame units): Laplacian or Taubin passes, each
// node along its free axes and over its rows (a junction curve's node along the curve, a node on
// the image box over its interface neighbours only); pinched and junction points stay. Counts the
// pinched nodes into r.
std::vector<V3> SmoothedBoundary(const SimplexMesh& mesh, const std::vector<std::uint8_t>& label, const Boundary& b,
  const std::vector<V3>& frame, const std::vector<std::uint8_t>& freeAxes, bool several,
  const SegmentationSurfaceSmoothingParameters& p, const ParallelFor& parallel, SegmentationSurfaceSmoothingResult& r)
{
  const std::int64_t n = static_cast<std::int64_t>(b.Node.size());
  std::vector<std::uint8_t> axes(n);
  std::vector<V3> x(n), next(n);
  // A node where the interface meets the image box averages its interface neighbours only: the
  // object's faces on the box would pull the rim inwards (a free-boundary condition instead).
  const std::uint8_t allAxes = mesh.VerticesPerCell() == 3 ? 3 : 7;
  std::vector<const CompressedRows*> rows(n, &b.Neighbours);
  const Junctions junctions = several ? JunctionGraph(mesh, label, b, r.InterfaceFaces) : Junctions();
  for (std::int64_t i = 0; i < n; ++i)
  {
    // A junction curve's node is not a manifold point of one surface; it moves along the curve.
    const bool curve = several && junctions.OnCurve[i];
    const bool pinched = several ? (junctions.Fixed[i] || (!curve && b.Pinched[i])) : b.Pinched[i];
    axes[i] = pinched ? 0 : freeAxes[b.Node[i]];
    r.PinchedNodes += pinched;
    x[i] = frame[b.Node[i]];
    if (curve)
    {
      rows[i] = &junctions.Curve;
    }
    else if (axes[i] && axes[i] != allAxes && b.InterfaceNeighbours.Size(i) > 0)
    {
      rows[i] = &b.InterfaceNeighbours;
    }
  }
  std::vector<double> factors{ p.Relaxation };
  if (p.Method == SurfaceSmoothingMethod::Taubin)
  {
    factors.push_back(1.0 / (p.PassBand - 1.0 / p.Relaxation));
  }
  for (int it = 0; it < p.Iterations; ++it)
  {
    for (const double factor : factors)
    {
      parallel(n, 4096, [&](std::int64_t begin, std::int64_t end) {
        for (std::int64_t i = begin; i < end; ++i)
        {
          next[i] = x[i];
          if (axes[i] && rows[i]->Size(i) > 0)
          {
            next[i] = Masked(x[i], Lerp(x[i], NeighbourMean(*rows[i], i, x), factor), axes[i]);
          }
        }
      });
      std::swap(x, next);
    }
  }
  return x;
}

// Step 2: the band the volume mesh relaxes in: rings of nodes around the boundary (ring 0 the
// boundary, each next ring one pass over the elements), the elements they touch, and the band
// nodes' stars and neighbours.
struct Band
{
  std::vector<int> Ring;                        // per mesh node; -1 outside the band
  std::vector<std::vector<std::int64_t>> Rings; // each ring's nodes, sorted
  std::vector<std::int64_t> Elements;
  CompressedRows Stars, Neighbours;
};
Band BoundaryBand(const SimplexMesh& mesh, const std::vector<std::int64_t>& boundaryNodes, int relaxationRings)
{
  const std::int64_t nPoints = mesh.NumberOfPoints(), nElements = mesh.NumberOfElements();
  const int vpc = mesh.VerticesPerCell();
  Band band;
  std::vector<int>& ring = band.Ring;
  ring.assign(nPoints, -1);
  for (const std::int64_t v : boundaryNodes)
  {
    ring[v] = 0;
  }
  band.Rings.push_back(boundaryNodes);
  std::sort(band.Rings[0].begin(), band.Rings[0].end());
  for (int k = 1; k <= relaxationRings; ++k)
  {
    band.Rings.emplace_back();
    for (std::int64_t e = 0; e < nElements; ++e)
    {
      const std::int64_t* c = mesh.Cell(e);
      if (std::any_of(c, c + vpc, [&](std::int64_t v) { return ring[v] == k - 1; }))
      {
        for (int j = 0; j < vpc; ++j)
        {
          if (ring[c[j]] < 0)
          {
            ring[c[j]] = k;
            band.Rings[k].push_back(c[j]);
          }
        }
      }
    }
    std::sort(band.Rings[k].begin(), band.Rings[k].end());
  }
  std::vector<std::pair<std::int64_t, std::int64_t>> starPairs, neighbourPairs;
  for (std::int64_t e = 0; e < nElements; ++e)
  {
    const std::int64_t* c = mesh.Cell(e);
    if (std::none_of(c, c + vpc, [&](std::int64_t v) { return ring[v] >= 0; }))
    {
      continue;
    }
    band.Elements.push_back(e);
    for (int j = 0; j < vpc; ++j)
    {
      if (ring[c[j]] >= 0)
      {
        starPairs.emplace_back(c[j], e);
        for (int l = 0; l < vpc; ++l)
        {
          if (l != j)
          {
            neighbourPairs.emplace_back(c[j], c[l]);
          }
        }
      }
    }
  }
  band.Stars = RowsFromPairs(nPoints, starPairs);
  band.Neighbours = RowsFromPairs(nPoints, neighbourPairs);
  return band;
}

// Step 3: each band node's target: the boundary's smoothed positions, and for each ring the mean of
// the inner ring's moves, fading linearly to zero past the last ring.
std::vector<V3> BandTargets(const Band& band, const std::vector<std::int64_t>& boundaryNodes, const std::vector<V3>& x,
  const std::vector<V3>& frame, const std::vector<std::uint8_t>& freeAxes, int relaxationRings)
{
  const std::int64_t nPoints = static_cast<std::int64_t>(frame.size());
  std::vector<V3> move(nPoints, V3{ { 0, 0, 0 } });
  for (std::size_t i = 0; i < boundaryNodes.size(); ++i)
  {
    move[boundaryNodes[i]] = Sub(x[i], frame[boundaryNodes[i]]);
  }
  for (int k = 1; k <= relaxationRings; ++k)
  {
    const double share = 1.0 - 1.0 / (relaxationRings + 2 - k);
    for (const std::int64_t v : band.Rings[k])
    {
      V3 mean = { { 0, 0, 0 } };
      int count = 0;
      for (const std::int64_t* w = band.Neighbours.Begin(v); w != band.Neighbours.End(v); ++w)
      {
        if (band.Ring[*w] == k - 1)
        {
          for (int a = 0; a < 3; ++a)
          {
            mean[a] += move[*w][a];
          }
          ++count;
        }
      }
      for (int a = 0; a < 3; ++a)
      {
        mean[a] *= share / count;
      }
      move[v] = Masked(V3{ { 0, 0, 0 } }, mean, freeAxes[v]);
    }
  }
  std::vector<V3> target(nPoints);
  for (std::int64_t v = 0; v < nPoints; ++v)
  {
    target[v] = band.Ring[v] < 0 ? frame[v] : V3{ { frame[v][0] + move[v][0], frame[v][1] + move[v][1], frame[v][2] + move[v][2] } };
  }
  return target;
}

// Step 5: boundary nodes that stopped short of their targets x: their neighbours off the boundary
// make room (moves that raise their star's quality), then they try again; at most three rounds.
void MakeRoom(VolumeMover& mover, const Band& band, const std::vector<std::int64_t>& boundaryNodes, const std::vector<V3>& x,
  std::vector<V3>& frame, const std::vector<std::uint8_t>& freeAxes, double tolerance)
{
  const std::int64_t n = static_cast<std::int64_t>(boundaryNodes.size());
  auto shortfall = [&](std::int64_t i) { return Norm(Sub(frame[boundaryNodes[i]], x[i])); };
  for (int round = 0; round < 3; ++round)
  {
    std::vector<std::int64_t> stuck;
    for (std::int64_t i = 0; i < n; ++i)
    {
      if (shortfall(i) > tolerance)
      {
        stuck.push_back(i);
      }
    }
    if (stuck.empty())
    {
      break;
    }
    std::int64_t progressMade = 0;
    for (const std::int64_t i : stuck)
    {
      const std::int64_t v = boundaryNodes[i];
      for (const std::int64_t* w = band.Neighbours.Begin(v); w != band.Neighbours.End(v); ++w)
      {
        if (band.Ring[*w] > 0 && freeAxes[*w])
        {
          mover.TryMove(*w, Masked(frame[*w], NeighbourMean(band.Neighbours, *w, frame), freeAxes[*w]), true);
        }
      }
      const double before = shortfall(i);
      if (mover.TryMove(v, x[i]) || mover.TryMove(v, Lerp(frame[v], x[i], 0.5)) ||
        mover.TryMove(v, Lerp(frame[v], x[i], 0.25)))
      {
        progressMade += shortfall(i) < before;
      }
    }
    if (!progressMade)
    {
      break;
    }
  }
}
} // namespace

SegmentationSurfaceSmoothingResult SmoothSegmentationSurface(const SimplexMesh& mesh, const std::vector<std::uint8_t>& label,
  const SegmentationSurfaceSmoothingParameters& p, const ParallelFor& parallel, const ProgressFunction& progress)
{
  SegmentationSurfaceSmoothingResult r;
  r.Error = ValidateParameters(p);
  const std::int64_t nElements = mesh.NumberOfElements();
  if (r.Error.empty() && static_cast<std::int64_t>(label.size()) != nElements)
  {
    r.Error = "there must be one label per element.";
  }
  if (!r.Error.empty())
  {
    return r;
  }
  auto start = Clock::now();
  const int vpc = mesh.VerticesPerCell();
  const int faceSize = vpc - 1;
  r.Points = mesh.Points();
  r.Faces = LabelBoundaryFaces(mesh, label, &r.InterfaceFaces);
  std::vector<V3> frame = mesh.FramePoints();
  // Several labels: interfaces between objects are inside the labelled region, so its measure is
  // summed over elements rather than enclosed by the boundary.
  const bool several = std::any_of(label.begin(), label.end(), [](std::uint8_t l) { return l > 1; });
  auto measure = [&](const std::vector<V3>& points) {
    return several ? LabelledMeasure(mesh, points, label) : EnclosedMeasure(points, r.Faces, faceSize);
  };
  r.ObjectMeasureBefore = measure(frame);
  r.Shortfall.assign(frame.size(), 0.0);
  if (r.Faces.empty())
  {
    r.ObjectMeasureAfter = r.ObjectMeasureBefore;
    r.BoundaryPoints = r.Points;
    r.SurfaceSeconds = Seconds(start);
    return r;
  }

  // 1. The boundary's targets.
  const Boundary b = BoundaryGraph(mesh.NumberOfPoints(), r.Faces, faceSize, r.InterfaceFaces);
  const std::int64_t n = static_cast<std::int64_t>(b.Node.size());
  r.BoundaryNodes = n;
  r.NonManifoldEdges = b.NonManifoldEdges;
  const std::vector<std::uint8_t> freeAxes = FreeAxes(mesh, std::vector<std::uint8_t>());
  const std::vector<V3> x = SmoothedBoundary(mesh, label, b, frame, freeAxes, several, p, parallel, r);
  r.SurfaceSeconds = Seconds(start);
  if (!progress(0.2))
  {
    r.Aborted = true;
    return r;
  }

  start = Clock::now();
  const ImageGeometry& g = mesh.Geometry();
  auto toIndex = [&](std::int64_t node, const V3& f) {
    // Axes a node may not move along keep their index value exactly (box faces stay planar).
    const V3 moved = g.FrameToIndex(f);
    return Masked(mesh.Points()[node], moved, freeAxes[node]);
  };
  if (!p.VolumeMesh)
  {
    r.BoundaryPoints = r.Points;
    std::vector<V3> smoothed = frame;
    for (std::int64_t i = 0; i < n; ++i)
    {
      r.BoundaryPoints[b.Node[i]] = toIndex(b.Node[i], x[i]);
      smoothed[b.Node[i]] = x[i];
    }
    r.ObjectMeasureAfter = several ? r.ObjectMeasureBefore : EnclosedMeasure(smoothed, r.Faces, faceSize);
    return r;
  }

  // 2-3. The band around the boundary and its nodes' targets.
  const std::int64_t nPoints = mesh.NumberOfPoints();
  const Band band = BoundaryBand(mesh, b.Node, p.RelaxationRings);
  if (!progress(0.3))
  {
    r.Aborted = true;
    return r;
  }
  const std::vector<V3> target = BandTargets(band, b.Node, x, frame, freeAxes, p.RelaxationRings);

  // 4. Passes over the boundary, then ring by ring: a node moves the whole way when its star allows
  // it, else to the pass's step along its move, else half-way there; no element falls below its
  // angle floor (its own angle when lower, a hair below, so that rounding never blocks a move that
  // keeps it).
  VolumeMover mover{ mesh, band.Stars, frame, std::vector<double>(nElements, 1.0), vpc };
  const double cosFloor = std::cos((faceSize == 2 ? p.MinAngle : p.MinDihedralAngle) * 3.14159265358979323846 / 180.0);
  for (const std::int64_t e : band.Elements)
  {
    mover.CosFloor[e] = std::max(mover.MaxCosine(e) + 1e-12, cosFloor);
  }
  const std::vector<V3> start0 = frame;
  const int steps = 4;
  for (int s = 1; s <= steps; ++s)
  {
    const double t = static_cast<double>(s) / steps;
    for (const auto& nodes : band.Rings)
    {
      for (const std::int64_t v : nodes)
      {
        if (frame[v] == target[v] || mover.TryMove(v, target[v]))
        {
          continue;
        }
        const V3 to = Lerp(start0[v], target[v], t);
        if (s == steps || !mover.TryMove(v, to))
        {
          mover.TryMove(v, Lerp(frame[v], to, 0.5));
        }
      }
    }
    if (!progress(0.2 + 0.5 * t))
    {
      r.Aborted = true;
      return r;
    }
  }
  // 5. Boundary nodes that stopped short.
  const double tolerance = 1e-9 * std::max({ std::fabs(g.Spacing[0]), std::fabs(g.Spacing[1]), std::fabs(g.Spacing[2]) });
  MakeRoom(mover, band, b.Node, x, frame, freeAxes, tolerance);
  if (!progress(0.9))
  {
    r.Aborted = true;
    return r;
  }
  // 6. The moved points and what the move reached.
  for (std::int64_t v = 0; v < nPoints; ++v)
  {
    r.RelaxedNodes += band.Ring[v] > 0 && frame[v] != start0[v];
    r.Points[v] = frame[v] == start0[v] ? mesh.Points()[v] : toIndex(v, frame[v]);
  }
  double total = 0.0, missed = 0.0;
  for (std::int64_t i = 0; i < n; ++i)
  {
    const double d = Norm(Sub(frame[b.Node[i]], x[i]));
    total += Norm(Sub(x[i], start0[b.Node[i]]));
    missed += d;
    r.Shortfall[b.Node[i]] = d;
    r.ShortNodes += d > tolerance;
    r.MaxShortfall = std::max(r.MaxShortfall, d);
  }
  r.ReachedFraction = total > 0 ? 1.0 - missed / total : 1.0;
  r.BoundaryPoints = r.Points;
  r.ObjectMeasureAfter = measure(frame);
  r.VolumeSeconds = Seconds(start);
  return r;
}
} // namespace featuremesh
