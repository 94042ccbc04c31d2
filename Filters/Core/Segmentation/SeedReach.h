// The seeds' reach (Task Object): the object a user seeds lies within reach of its seeds. R is the
// largest distance from an object seed to the nearest background seed: the background seeds placed
// around the object bound it. A node farther than Reach x R from every seed of the object
// pays Weight x (distance / R - Reach) per voxel as that object. The geodesic term's ratio prior
// fades to 1/2 far from every seed, where tissue of the object's own intensities then joins it (the
// far leaks of docs/benchmark.md); this term does not fade. Distances are in frame coordinates
// (ImageGeometry: index x |spacing|).
#pragma once

#include "ImageGeometry.h"
#include "Parallel.h"
#include "SharedArray.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace featuremesh
{
class SimplexMesh;

struct SeedReachParameters
{
  // Cost per voxel (nats, as the region term's) one R beyond Reach; it grows linearly. 0 = off.
  double Weight = 4.0;
  // Where the cost starts, in units of R.
  double Reach = 1.0;
};

std::string ValidateParameters(const SeedReachParameters& p);

// Frame coordinates of a cut graph's nodes: explicit centres (elements' centroids, shared), else
// the voxels of the geometry's grid.
struct NodeCentres
{
  ImageGeometry Geometry;
  SharedArray<std::array<double, 3>> Centre;
  std::int64_t Size() const { return this->Centre.empty() ? this->Geometry.Size() : static_cast<std::int64_t>(this->Centre.size()); }
  std::array<double, 3> operator()(std::int64_t p) const;
};
NodeCentres ElementCentres(const SimplexMesh& mesh);
NodeCentres VoxelCentres(const ImageGeometry& g);

// Per node (rows) and object label (columns 1..labels-1; the background, label 0, pays nothing):
// the reach term per voxel of labelling the node so, from seed voxels and their labels, into
// `cost` (resized; its storage is reused). False, `cost` empty, when Weight is 0 or no object label
// has seeds while the background has some. `reach`, when given, receives R per label (0: none).
bool SeedReachCosts(const NodeCentres& nodes, const std::vector<std::int64_t>& seedVoxels,
  const std::vector<std::uint8_t>& seedLabels, int labels, const SeedReachParameters& p, const ParallelFor& parallel,
  std::vector<double>& cost, std::vector<double>* reach = nullptr);
} // namespace featuremesh
