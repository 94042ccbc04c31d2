// Element adjacency of a triangle / tetrahedral mesh: pairs of elements sharing an edge (2D) or a
// face (3D), and the faces on the mesh's hull.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace featuremesh
{
struct MeshAdjacency
{
  // Interior faces: elements A[i] and B[i] share face i, of measure Measure[i] (edge length in 2D,
  // face area in 3D, world units).
  std::vector<std::int64_t> A, B;
  std::vector<double> Measure;
  // Local face index of the shared face in A[i] and in B[i].
  std::vector<std::uint8_t> LocalA, LocalB;
  // Hull faces: element and local face index (the face opposite that local vertex).
  std::vector<std::int64_t> HullElement;
  std::vector<std::uint8_t> HullFace;
};

// Faces are grouped by their smallest vertex id (a counting sort), then matched within each group,
// so the cost is linear in the number of elements.
MeshAdjacency BuildAdjacency(const std::vector<std::array<double, 3>>& points, const std::vector<std::int64_t>& cells,
  int verticesPerCell);

// Vertex ids of local face f of an element (the face opposite local vertex f), ordered so that the
// face's normal points out of the element (2D: the edge runs with the element on its left).
void OutwardFace(const std::vector<std::array<double, 3>>& points, const std::int64_t* cell, int verticesPerCell,
  int f, std::int64_t* face);
} // namespace featuremesh
