#include "SimplexMesh.h"
#include "Vector3.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <stdexcept>

namespace featuremesh
{
namespace
{
double FaceMeasure(const std::vector<std::array<double, 3>>& P, const std::int64_t* f, int n)
{
  const auto& a = P[f[0]];
  const auto& b = P[f[1]];
  const double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
  if (n == 2)
  {
    return std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  }
  const auto& c = P[f[2]];
  const double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
  const double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2], z = u[0] * v[1] - u[1] * v[0];
  return 0.5 * std::sqrt(x * x + y * y + z * z);
}
} // namespace

void OutwardFace(const std::vector<std::array<double, 3>>& P, const std::int64_t* cell, int vpc, int f,
  std::int64_t* face)
{
  if (vpc == 3)
  {
    // Counter-clockwise triangle: edge (f+1 -> f+2) has the triangle on its left.
    face[0] = cell[(f + 1) % 3];
    face[1] = cell[(f + 2) % 3];
    return;
  }
  face[0] = cell[(f + 1) % 4];
  face[1] = cell[(f + 2) % 4];
  face[2] = cell[(f + 3) % 4];
  const auto& a = P[face[0]];
  const auto& b = P[face[1]];
  const auto& c = P[face[2]];
  const auto& o = P[cell[f]];
  const double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
  const double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
  const double n[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0] };
  if (n[0] * (o[0] - a[0]) + n[1] * (o[1] - a[1]) + n[2] * (o[2] - a[2]) > 0)
  {
    std::swap(face[1], face[2]);
  }
}

namespace
{
FaceAdjacency BuildFaces(
  const std::vector<std::array<double, 3>>& P, const std::vector<std::int64_t>& cells, int vpc)
{
  FaceAdjacency adj;
  const std::int64_t m = static_cast<std::int64_t>(cells.size()) / vpc;
  const int fv = vpc - 1; // vertices per face
  const std::int64_t nFaces = m * vpc;
  // Face `local` of element e (its vertices but that one), sorted.
  const auto faceOf = [&](std::int64_t e, int local, std::int64_t* v) {
    int k = 0;
    for (int j = 0; j < vpc; ++j)
    {
      if (j != local)
      {
        v[k++] = cells[e * vpc + j];
      }
    }
    v[2] = fv == 2 ? -1 : v[2];
    std::sort(v, v + fv);
  };
  // Faces bucketed by their smallest vertex; within a bucket by the other two, then by face id
  // (e * vpc + local): the two faces of an interior face meet. The records are written in bucket
  // order, so that the sorts and the matching read them in sequence.
  std::vector<std::int64_t> bucketStart(P.size() + 1, 0);
  for (std::int64_t e = 0; e < m; ++e)
  {
    for (int f = 0; f < vpc; ++f)
    {
      std::int64_t least = -1;
      for (int j = 0; j < vpc; ++j)
      {
        const std::int64_t v = cells[e * vpc + j];
        least = j != f && (least < 0 || v < least) ? v : least;
      }
      ++bucketStart[least + 1];
    }
  }
  for (size_t i = 1; i < bucketStart.size(); ++i)
  {
    bucketStart[i] += bucketStart[i - 1];
  }
  struct Face
  {
    std::int64_t V1, V2, Id;
  };
  std::unique_ptr<Face[]> faces(new Face[nFaces]); // every record is written below
  {
    std::vector<std::int64_t> fill(bucketStart.begin(), bucketStart.end() - 1);
    for (std::int64_t e = 0; e < m; ++e)
    {
      for (int f = 0; f < vpc; ++f)
      {
        std::int64_t v[3];
        faceOf(e, f, v);
        faces[fill[v[0]]++] = Face{ v[1], v[2], e * vpc + f };
      }
    }
  }
  // At most half the element faces are interior: no doubling growth (a 4 M-element mesh's lists
  // would hold 5 % more than they use).
  adj.A.reserve(nFaces / 2);
  adj.B.reserve(nFaces / 2);
  adj.Measure.reserve(nFaces / 2);
  adj.LocalA.reserve(nFaces / 2);
  adj.LocalB.reserve(nFaces / 2);
  for (size_t b = 0; b + 1 < bucketStart.size(); ++b)
  {
    Face* first = faces.get() + bucketStart[b];
    Face* last = faces.get() + bucketStart[b + 1];
    std::sort(first, last, [](const Face& p, const Face& q) {
      return p.V1 != q.V1 ? p.V1 < q.V1 : (p.V2 != q.V2 ? p.V2 < q.V2 : p.Id < q.Id);
    });
    for (Face* it = first; it != last;)
    {
      const Face& p = *it;
      const std::int64_t pe = p.Id / vpc;
      const int pl = static_cast<int>(p.Id % vpc);
      if (it + 1 != last && (it + 1)->V1 == p.V1 && (it + 1)->V2 == p.V2)
      {
        const Face& q = *(it + 1);
        const std::int64_t qe = q.Id / vpc;
        const int ql = static_cast<int>(q.Id % vpc);
        const bool pFirst = pe < qe;
        adj.A.push_back(pFirst ? pe : qe);
        adj.B.push_back(pFirst ? qe : pe);
        adj.LocalA.push_back(static_cast<std::uint8_t>(pFirst ? pl : ql));
        adj.LocalB.push_back(static_cast<std::uint8_t>(pFirst ? ql : pl));
        const std::int64_t v[3] = { static_cast<std::int64_t>(b), p.V1, p.V2 };
        adj.Measure.push_back(FaceMeasure(P, v, fv));
        it += 2;
      }
      else
      {
        adj.HullElement.push_back(pe);
        adj.HullFace.push_back(static_cast<std::uint8_t>(pl));
        ++it;
      }
    }
  }
  return adj;
}
} // namespace

double SimplexMeasure(const std::array<double, 3>* const* v, int vpc)
{
  using namespace vector3;
  const V3 b = Sub(*v[1], *v[0]), d = Sub(*v[2], *v[0]);
  return vpc == 3 ? 0.5 * (b[0] * d[1] - b[1] * d[0]) : Dot(b, Cross(d, Sub(*v[3], *v[0]))) / 6.0;
}

double ElementMeasure(const std::vector<std::array<double, 3>>& P, const std::int64_t* c, int vpc)
{
  const std::array<double, 3>* v[4] = { &P[c[0]], &P[c[1]], &P[c[2]], vpc == 4 ? &P[c[3]] : nullptr };
  return SimplexMeasure(v, vpc);
}

SimplexMesh::SimplexMesh(const ImageGeometry& geometry, std::vector<std::array<double, 3>> indexPoints,
  std::vector<std::int64_t> cells, int verticesPerCell)
  : Frame(geometry)
  , IndexPoints(std::move(indexPoints))
  , CellIds(std::move(cells))
  , Vpc(verticesPerCell)
{
}

std::vector<std::array<double, 3>> SimplexMesh::FramePoints() const
{
  std::vector<std::array<double, 3>> frame(this->IndexPoints.size());
  for (std::size_t i = 0; i < frame.size(); ++i)
  {
    frame[i] = this->Frame.IndexToFrame(this->IndexPoints[i]);
  }
  return frame;
}

std::vector<std::array<double, 3>> SimplexMesh::WorldPoints() const
{
  std::vector<std::array<double, 3>> world(this->IndexPoints.size());
  for (std::size_t i = 0; i < world.size(); ++i)
  {
    world[i] = this->Frame.IndexToWorld(this->IndexPoints[i]);
  }
  return world;
}

std::string SimplexMesh::Validate() const
{
  if (this->Vpc != 3 && this->Vpc != 4)
  {
    return "the mesh must consist of triangles (2D) or tetrahedra (3D).";
  }
  if ((this->Vpc == 3) != this->Frame.Is2D())
  {
    return std::string("a ") + (this->Vpc == 3 ? "triangle mesh needs a 2D image." : "tetrahedral mesh needs a 3D image.");
  }
  if (this->CellIds.empty())
  {
    return "the mesh has no elements.";
  }
  const std::int64_t n = this->NumberOfPoints();
  std::int64_t bad = 0;
  for (std::int64_t id : this->CellIds)
  {
    bad += (id < 0 || id >= n) ? 1 : 0;
  }
  if (bad)
  {
    return std::to_string(bad) + " cell point ids lie outside the mesh's " + std::to_string(n) + " points.";
  }
  return std::string();
}

void SimplexMesh::OrientPositively()
{
  bool flipped = false;
  for (std::int64_t e = 0; e < this->NumberOfElements(); ++e)
  {
    std::int64_t* cell = this->CellIds.data() + e * this->Vpc;
    if (ElementMeasure(this->IndexPoints, cell, this->Vpc) < 0)
    {
      std::swap(cell[this->Vpc - 2], cell[this->Vpc - 1]);
      flipped = true;
    }
  }
  if (flipped)
  {
    this->Cached = std::make_shared<Cache>();
  }
}

void SimplexMesh::SetPoints(std::vector<std::array<double, 3>> indexPoints)
{
  this->IndexPoints = std::move(indexPoints);
  this->SpatiallySorted = false;
  // Topology caches stay valid; face measures do not. A fresh cache keeps copies that share the
  // old one unaffected.
  auto fresh = std::make_shared<Cache>();
  {
    std::lock_guard<std::mutex> lock(this->Cached->Lock);
    fresh->Stars = this->Cached->Stars;
    fresh->Neighbours = this->Cached->Neighbours;
  }
  this->Cached = fresh;
}

void SimplexMesh::SortElementsSpatially()
{
  // In place, cycle by cycle (element i takes the cells of order[i]): no second copy of the cells,
  // 134 MB at 512^3.
  const std::vector<std::int64_t> order = SpatialElementOrder(*this);
  const int vpc = this->Vpc;
  std::vector<bool> placed(order.size(), false);
  for (std::size_t start = 0; start < order.size(); ++start)
  {
    if (placed[start] || order[start] == static_cast<std::int64_t>(start))
    {
      continue;
    }
    std::array<std::int64_t, 4> first{};
    std::copy_n(this->CellIds.data() + start * vpc, vpc, first.begin());
    std::size_t i = start;
    for (;;)
    {
      placed[i] = true;
      const auto from = static_cast<std::size_t>(order[i]);
      if (from == start)
      {
        std::copy_n(first.begin(), vpc, this->CellIds.data() + i * vpc);
        break;
      }
      std::copy_n(this->CellIds.data() + from * vpc, vpc, this->CellIds.data() + i * vpc);
      i = from;
    }
  }
  this->SpatiallySorted = true;
  this->Cached = std::make_shared<Cache>();
}

std::vector<std::int64_t> SpatialElementOrder(const SimplexMesh& mesh)
{
  // Morton keys above 32 bits of element id: one 64-bit sort.
  const auto& d = mesh.Geometry().Dims;
  const std::int64_t m = mesh.NumberOfElements();
  int shift = 2;
  while ((std::max({ d[0], d[1], d[2] }) >> shift) >= 1024)
  {
    ++shift;
  }
  auto spread = [](std::uint64_t x) {
    x &= 0x3ff;
    x = (x | (x << 16)) & 0x30000ff;
    x = (x | (x << 8)) & 0x300f00f;
    x = (x | (x << 4)) & 0x30c30c3;
    return (x | (x << 2)) & 0x9249249;
  };
  const auto& P = mesh.Points();
  const int vpc = mesh.VerticesPerCell();
  std::vector<std::uint64_t> key(static_cast<std::size_t>(m));
  for (std::int64_t e = 0; e < m; ++e)
  {
    const std::int64_t* cell = mesh.Cell(e);
    double lo[3] = { P[cell[0]][0], P[cell[0]][1], P[cell[0]][2] };
    for (int v = 1; v < vpc; ++v)
    {
      for (int a = 0; a < 3; ++a)
      {
        lo[a] = std::min(lo[a], P[cell[v]][a]);
      }
    }
    std::uint64_t code = 0;
    for (int a = 0; a < 3; ++a)
    {
      const auto block = static_cast<std::uint64_t>(std::max(0.0, std::ceil(lo[a]))) >> shift;
      code |= spread(block) << a;
    }
    key[e] = (code << 32) | static_cast<std::uint64_t>(e);
  }
  std::sort(key.begin(), key.end());
  std::vector<std::int64_t> order(static_cast<std::size_t>(m));
  for (std::int64_t i = 0; i < m; ++i)
  {
    order[i] = static_cast<std::int64_t>(key[i] & 0xffffffffu);
  }
  return order;
}

const FaceAdjacency& SimplexMesh::Faces() const
{
  std::lock_guard<std::mutex> lock(this->Cached->Lock);
  if (!this->Cached->Faces)
  {
    this->Cached->Faces = std::make_shared<const FaceAdjacency>(BuildFaces(this->FramePoints(), this->CellIds, this->Vpc));
  }
  return *this->Cached->Faces;
}

std::shared_ptr<const FaceAdjacency> SimplexMesh::SharedFaces() const
{
  this->Faces();
  std::lock_guard<std::mutex> lock(this->Cached->Lock);
  return this->Cached->Faces;
}

const std::vector<std::int32_t>& SimplexMesh::ElementFaces() const
{
  const FaceAdjacency& faces = this->Faces();
  std::lock_guard<std::mutex> lock(this->Cached->Lock);
  if (!this->Cached->ElementFaces)
  {
    if (faces.A.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    {
      throw std::length_error("the mesh has more faces than 32-bit face ids hold.");
    }
    auto table = std::make_shared<std::vector<std::int32_t>>(static_cast<std::size_t>(this->NumberOfElements() * this->Vpc), -1);
    for (std::size_t f = 0; f < faces.A.size(); ++f)
    {
      (*table)[faces.A[f] * this->Vpc + faces.LocalA[f]] = static_cast<std::int32_t>(f);
      (*table)[faces.B[f] * this->Vpc + faces.LocalB[f]] = static_cast<std::int32_t>(f);
    }
    this->Cached->ElementFaces = table;
  }
  return *this->Cached->ElementFaces;
}

const CompressedRows& SimplexMesh::Stars() const
{
  std::lock_guard<std::mutex> lock(this->Cached->Lock);
  if (!this->Cached->Stars)
  {
    // Two passes, count then insert; elements go in ascending order.
    auto rows = std::make_shared<CompressedRows>();
    rows->Offsets.assign(this->IndexPoints.size() + 1, 0);
    for (std::int64_t id : this->CellIds)
    {
      rows->Offsets[id + 1]++;
    }
    std::partial_sum(rows->Offsets.begin(), rows->Offsets.end(), rows->Offsets.begin());
    rows->Ids.resize(this->CellIds.size());
    std::vector<std::int64_t> fill(rows->Offsets.begin(), rows->Offsets.end() - 1);
    for (std::size_t k = 0; k < this->CellIds.size(); ++k)
    {
      rows->Ids[fill[this->CellIds[k]]++] = static_cast<std::int64_t>(k) / this->Vpc;
    }
    this->Cached->Stars = rows;
  }
  return *this->Cached->Stars;
}

const CompressedRows& SimplexMesh::VertexNeighbours() const
{
  const CompressedRows& stars = this->Stars();
  std::lock_guard<std::mutex> lock(this->Cached->Lock);
  if (!this->Cached->Neighbours)
  {
    auto rows = std::make_shared<CompressedRows>();
    const std::int64_t n = this->NumberOfPoints();
    rows->Offsets.assign(n + 1, 0);
    std::vector<std::int64_t> around;
    for (std::int64_t v = 0; v < n; ++v)
    {
      around.clear();
      for (const std::int64_t* e = stars.Begin(v); e != stars.End(v); ++e)
      {
        for (int k = 0; k < this->Vpc; ++k)
        {
          const std::int64_t w = this->CellIds[*e * this->Vpc + k];
          if (w != v)
          {
            around.push_back(w);
          }
        }
      }
      std::sort(around.begin(), around.end());
      around.erase(std::unique(around.begin(), around.end()), around.end());
      rows->Ids.insert(rows->Ids.end(), around.begin(), around.end());
      rows->Offsets[v + 1] = static_cast<std::int64_t>(rows->Ids.size());
    }
    this->Cached->Neighbours = rows;
  }
  return *this->Cached->Neighbours;
}

namespace
{
// A face whose vertices all lie in one plane of the image box.
bool OnBox(const SimplexMesh& mesh, const std::int64_t* ids, int count)
{
  const ImageGeometry& g = mesh.Geometry();
  const auto& P = mesh.Points();
  for (int a = 0; a < g.Dimension(); ++a)
  {
    for (const double side : { 0.0, g.Dims[a] - 1.0 })
    {
      bool all = true;
      for (int k = 0; all && k < count; ++k)
      {
        all = P[ids[k]][a] == side;
      }
      if (all)
      {
        return true;
      }
    }
  }
  return false;
}

// The ids of local face f (opposite local vertex f) of element e, ascending.
std::array<std::int64_t, 3> FaceKey(const SimplexMesh& mesh, std::int64_t e, int f)
{
  const int vpc = mesh.VerticesPerCell();
  const std::int64_t* cell = mesh.Cell(e);
  std::array<std::int64_t, 3> key = { { -1, -1, -1 } };
  for (int k = 1, n = 0; k < vpc; ++k)
  {
    key[n++] = cell[(f + k) % vpc];
  }
  std::sort(key.begin(), key.begin() + vpc - 1);
  return key;
}

// The boundary's (element, local face) pairs, interface and hull, as oriented faces in their order.
std::vector<std::int64_t> OrientedBoundary(const SimplexMesh& mesh, std::vector<std::pair<std::int64_t, int>>& inner,
  std::vector<std::pair<std::int64_t, int>>& hull, std::int64_t* interfaceFaces)
{
  const int vpc = mesh.VerticesPerCell();
  std::sort(inner.begin(), inner.end());
  std::sort(hull.begin(), hull.end());
  if (interfaceFaces)
  {
    *interfaceFaces = static_cast<std::int64_t>(inner.size());
  }
  const std::vector<std::array<double, 3>> frame = mesh.FramePoints();
  const bool flip = mesh.Geometry().IsMirrored();
  std::vector<std::int64_t> out;
  out.reserve((inner.size() + hull.size()) * (vpc - 1));
  for (const auto* list : { &inner, &hull })
  {
    for (const auto& face : *list)
    {
      std::int64_t f[3];
      OutwardFace(frame, mesh.Cell(face.first), vpc, face.second, f);
      if (flip)
      {
        std::swap(f[0], f[1]);
      }
      out.insert(out.end(), f, f + vpc - 1);
    }
  }
  return out;
}
} // namespace

std::vector<std::int64_t> LabelBoundaryFaces(
  const SimplexMesh& mesh, const std::vector<std::uint8_t>& label, std::int64_t* interfaceFaces)
{
  // The faces of the object elements that no other object element shares: hashing the object's
  // faces needs no adjacency of the whole mesh.
  const int vpc = mesh.VerticesPerCell();
  struct Face
  {
    std::array<std::int64_t, 3> Key;
    std::int64_t Element;
    int Local;
  };
  std::vector<Face> faces;
  for (std::int64_t e = 0; e < mesh.NumberOfElements(); ++e)
  {
    if (!label[e])
    {
      continue;
    }
    for (int f = 0; f < vpc; ++f)
    {
      faces.push_back(Face{ FaceKey(mesh, e, f), e, f });
    }
  }
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) { return a.Key < b.Key; });
  std::vector<std::pair<std::int64_t, int>> inner, hull;
  for (std::size_t i = 0; i < faces.size();)
  {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].Key == faces[i].Key)
    {
      ++j;
    }
    if (j == i + 1)
    {
      (OnBox(mesh, faces[i].Key.data(), vpc - 1) ? hull : inner).emplace_back(faces[i].Element, faces[i].Local);
    }
    i = j;
  }
  return OrientedBoundary(mesh, inner, hull, interfaceFaces);
}

std::vector<std::int64_t> LabelBoundaryFaces(const SimplexMesh& mesh, const FaceAdjacency& adjacency,
  const std::vector<std::uint8_t>& label, std::int64_t* interfaceFaces)
{
  std::vector<std::pair<std::int64_t, int>> inner, hull;
  const int vpc = mesh.VerticesPerCell();
  // Every face between two labels has an end of a label other than 0: the faces of those elements
  // (most of a mesh is background), each face from the end it is listed by. Another adjacency than
  // the mesh's own is walked whole.
  if (&adjacency == &mesh.Faces())
  {
    const std::vector<std::int32_t>& faceOf = mesh.ElementFaces();
    for (std::size_t e = 0; e < label.size(); ++e)
    {
      if (!label[e])
      {
        continue;
      }
      for (int k = 0; k < vpc; ++k)
      {
        const std::int32_t i = faceOf[e * vpc + k];
        if (i < 0)
        {
          continue;
        }
        const std::int64_t a = adjacency.A[i], b = adjacency.B[i];
        if (label[a] != label[b] && static_cast<std::int64_t>(e) == (label[a] ? a : b))
        {
          inner.emplace_back(e, k);
        }
      }
    }
  }
  else
  {
    for (std::size_t i = 0; i < adjacency.A.size(); ++i)
    {
      const std::int64_t a = adjacency.A[i], b = adjacency.B[i];
      if (label[a] != label[b])
      {
        inner.emplace_back(label[a] ? a : b, label[a] ? adjacency.LocalA[i] : adjacency.LocalB[i]);
      }
    }
  }
  for (std::size_t h = 0; h < adjacency.HullElement.size(); ++h)
  {
    const std::int64_t e = adjacency.HullElement[h];
    if (label[e])
    {
      // Unshared faces off the box (a mesh that does not tile it) count as interface, as above.
      const std::array<std::int64_t, 3> key = FaceKey(mesh, e, adjacency.HullFace[h]);
      (OnBox(mesh, key.data(), vpc - 1) ? hull : inner).emplace_back(e, adjacency.HullFace[h]);
    }
  }
  return OrientedBoundary(mesh, inner, hull, interfaceFaces);
}

std::vector<std::uint8_t> FreeAxes(const SimplexMesh& mesh, const std::vector<std::uint8_t>& fixed, bool fixedMayMove)
{
  const ImageGeometry& g = mesh.Geometry();
  const int dimension = g.Dimension();
  const auto& P = mesh.Points();
  std::vector<std::uint8_t> free(P.size(), 0);
  for (size_t i = 0; i < P.size(); ++i)
  {
    if (i < fixed.size() && fixed[i] && !fixedMayMove)
    {
      continue;
    }
    for (int a = 0; a < dimension; ++a)
    {
      if (P[i][a] != 0.0 && P[i][a] != g.Dims[a] - 1.0)
      {
        free[i] |= static_cast<std::uint8_t>(1 << a);
      }
    }
  }
  return free;
}
} // namespace featuremesh
