// A triangle (2D) or tetrahedral (3D) mesh over an image: points in the image's index space,
// 3 or 4 point ids per element, positively oriented in index space. Adjacency is built on request
// and cached: element face pairs and hull faces, vertex stars (vertex -> elements) and vertex
// neighbours (vertex -> vertices). Moving the points drops what depends on positions.
#pragma once

#include "ImageGeometry.h"

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace featuremesh
{
// Compressed rows: the ids of row r are Ids[Offsets[r] .. Offsets[r + 1]), ascending.
struct CompressedRows
{
  std::vector<std::int64_t> Offsets{ 0 };
  std::vector<std::int64_t> Ids;
  std::int64_t Size(std::int64_t r) const { return this->Offsets[r + 1] - this->Offsets[r]; }
  const std::int64_t* Begin(std::int64_t r) const { return this->Ids.data() + this->Offsets[r]; }
  const std::int64_t* End(std::int64_t r) const { return this->Ids.data() + this->Offsets[r + 1]; }
};

struct FaceAdjacency
{
  // Interior faces: elements A[i] < B[i] share face i, of measure Measure[i] (edge length in 2D,
  // face area in 3D, frame = world units), which is local face LocalA[i] of A and LocalB[i] of B.
  std::vector<std::int64_t> A, B;
  std::vector<double> Measure;
  std::vector<std::uint8_t> LocalA, LocalB;
  // Hull faces: element and local face index (the face opposite that local vertex).
  std::vector<std::int64_t> HullElement;
  std::vector<std::uint8_t> HullFace;
};

class SimplexMesh
{
public:
  SimplexMesh() = default;
  SimplexMesh(const ImageGeometry& geometry, std::vector<std::array<double, 3>> indexPoints,
    std::vector<std::int64_t> cells, int verticesPerCell);

  const ImageGeometry& Geometry() const { return this->Frame; }
  const std::vector<std::array<double, 3>>& Points() const { return this->IndexPoints; }
  const std::vector<std::int64_t>& Cells() const { return this->CellIds; }
  int VerticesPerCell() const { return this->Vpc; }
  std::int64_t NumberOfPoints() const { return static_cast<std::int64_t>(this->IndexPoints.size()); }
  std::int64_t NumberOfElements() const { return this->Vpc ? static_cast<std::int64_t>(this->CellIds.size()) / this->Vpc : 0; }
  const std::int64_t* Cell(std::int64_t e) const { return this->CellIds.data() + e * this->Vpc; }
  std::array<double, 3> FramePoint(std::int64_t i) const { return this->Frame.IndexToFrame(this->IndexPoints[i]); }
  std::vector<std::array<double, 3>> FramePoints() const;
  std::vector<std::array<double, 3>> WorldPoints() const;

  // Empty when every cell id names a point and the element type matches the image's dimension.
  std::string Validate() const;

  // Orients every element positively in index space (swaps two ids of the others); drops the
  // cached adjacency when it changes anything.
  void OrientPositively();

  // Replaces the points (same count; stage 3 moves them), dropping the face measures.
  void SetPoints(std::vector<std::array<double, 3>> indexPoints);

  // Renumbers the elements in SpatialElementOrder, dropping the cached adjacency. Stages 2 and 3
  // write their meshes so: a pass over the elements' neighbours (the cut's Dijkstra and max-flow)
  // then finds them near in memory, where the meshers' order scatters them.
  void SortElementsSpatially();
  // Whether the elements are in SpatialElementOrder as sorted (moving the points forgets it): the
  // rasteriser then walks them as they are instead of sorting them again.
  bool InSpatialOrder() const { return this->SpatiallySorted; }

  // Built on first use, then cached; safe to call from several threads.
  const FaceAdjacency& Faces() const;
  // The same adjacency, shared: it stays alive (unchanged) as long as a holder keeps it.
  std::shared_ptr<const FaceAdjacency> SharedFaces() const;
  const CompressedRows& Stars() const;
  const CompressedRows& VertexNeighbours() const;
  // Per element and local face (elements x VerticesPerCell()): the index of the interior face in
  // Faces(), -1 on the hull. Built on first use from Faces(): the faces of a few elements without a
  // pass over every face. Throws std::length_error beyond 2^31 - 1 faces (the cuts' max-flow ids
  // stop at 10^9 faces, GraphSizeProblem).
  const std::vector<std::int32_t>& ElementFaces() const;

private:
  ImageGeometry Frame;
  std::vector<std::array<double, 3>> IndexPoints;
  std::vector<std::int64_t> CellIds;
  int Vpc = 0;
  bool SpatiallySorted = false;
  struct Cache
  {
    std::mutex Lock;
    std::shared_ptr<const FaceAdjacency> Faces;
    std::shared_ptr<const CompressedRows> Stars, Neighbours;
    std::shared_ptr<const std::vector<std::int32_t>> ElementFaces;
  };
  std::shared_ptr<Cache> Cached = std::make_shared<Cache>();
};

// The elements in Morton order of their lowest voxel corner (blocks of 4 voxels or more, 10 bits
// per axis), ties in id order. Elements near in the image are then near in the order.
std::vector<std::int64_t> SpatialElementOrder(const SimplexMesh& mesh);

// Signed area (triangles, xy) or volume (tetrahedra) of the simplex with vertices v[0..vpc): the
// one formula of the project (orientation, ODT weights, a label's measure).
double SimplexMeasure(const std::array<double, 3>* const* v, int verticesPerCell);
// The same of an element of `points`.
double ElementMeasure(const std::vector<std::array<double, 3>>& points, const std::int64_t* cell, int verticesPerCell);

// Vertex ids of local face f of an element (the face opposite local vertex f), ordered so that the
// face's normal points out of the element in `points`' coordinates (2D: the edge runs with the
// element on its left).
void OutwardFace(const std::vector<std::array<double, 3>>& points, const std::int64_t* cell, int verticesPerCell,
  int f, std::int64_t* face);

// The faces between elements labelled 1 and 0, and the hull faces of elements labelled 1, each
// oriented out of the labelled region in world coordinates (mirrored frames flip it): vpc - 1 ids
// per face, interface faces first, then hull faces, each in order of (element, local face).
// `interfaceFaces` receives the number of interface faces. Needs no face adjacency.
std::vector<std::int64_t> LabelBoundaryFaces(
  const SimplexMesh& mesh, const std::vector<std::uint8_t>& label, std::int64_t* interfaceFaces = nullptr);
// The same from the mesh's face adjacency (Faces()), for callers that hold it: no hashing.
std::vector<std::int64_t> LabelBoundaryFaces(const SimplexMesh& mesh, const FaceAdjacency& adjacency,
  const std::vector<std::uint8_t>& label, std::int64_t* interfaceFaces = nullptr);

// Per-node freedom in the image box (stages 3 and 6): which index axes a node may move along (bit a = axis a): none for fixed nodes
// (unless fixedMayMove) and box corners, the axes of its face or edge for a node on the box.
std::vector<std::uint8_t> FreeAxes(const SimplexMesh& mesh, const std::vector<std::uint8_t>& fixed, bool fixedMayMove = false);
} // namespace featuremesh
