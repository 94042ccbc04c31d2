// Voxel refinement of a super-voxel cut along its boundary: the boundary step of Lazy Snapping (Li,
// Sun, Tang & Shum, SIGGRAPH 2004), on a band as in banded graph cuts (Lombaert, Sun, Grady & Xu,
// ICCV 2005). An element that straddles the objects' boundary can only take one label; its voxels
// are labelled again by the voxel cut's energy (the same region and spatial terms per voxel, Potts
// weights exp(-|x_v - x_u|^2 / 2 sigma^2) per voxel face), with every voxel outside the band held
// at its element's label. Binary: one exact max-flow; k labels: one cycle of alpha-expansion from
// the elements' labels, each voxel choosing among the labels near its element.
#pragma once

#include "AlphaExpansion.h"
#include "ElementRasterizer.h"
#include "Parallel.h"
#include "SeedConnectivity.h"
#include "SimplexMesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

namespace featuremesh
{
struct VoxelRefinementProblem
{
  const SimplexMesh* Mesh = nullptr;
  const VoxelOwnerMap* Owner = nullptr;
  const std::vector<std::uint8_t>* Label = nullptr; // each element's label, 0..Labels-1
  // Per element, 1 when its voxels keep its label (the seeds' elements); empty = none.
  std::vector<std::uint8_t> Fixed;
  int Labels = 2;
  // Face steps from an element of another label within which an element's voxels are refined
  // (1: the elements along the boundary only).
  int Rings = 1;
  // Voxel v's cost of each label into costs[0..Labels) (v's element is e): lambda times its region
  // and spatial terms, as the cut gives them per voxel.
  std::function<void(std::int64_t v, std::int64_t e, double* costs)> Cost;
  // |x_a - x_b|^2 of two voxels' channel vectors.
  std::function<double(std::int64_t a, std::int64_t b)> Distance2;
  // The Potts weights' sigma on the voxel grid (VoxelGridSigma).
  double Sigma = 1.0;
  // The cut's connectivity rule (resolved: Off, Fill Holes or Seeded Object), applied to the band's
  // voxels (RefineOnVoxels).
  featuremesh::Connectivity Connectivity = featuremesh::Connectivity::Off;
  // Optional, two labels: each element's index among the object components (-1 background); the
  // result then gives each component's change in voxels.
  const std::vector<std::int64_t>* Component = nullptr;
  ParallelFor Parallel = SerialFor();
};

struct VoxelRefinementResult
{
  // The voxels whose label differs from their element's (in a fixed order) and their labels.
  std::vector<std::int64_t> Voxel;
  std::vector<std::uint8_t> Label;
  std::int64_t BandVoxels = 0;
  // Per object component (Problem.Component): voxels gained less voxels lost. A voxel that leaves
  // the background counts with the component of the object element nearest its element.
  std::vector<double> ComponentChange;
  double Energy = 0.0, Seconds = 0.0;
  std::string Error;
  bool Aborted = false;
};

// What a refinement keeps for the next (a seed edit's re-cut) of one mesh and image: a map of the
// image's voxels to the domain (4 bytes per voxel of the slices it spans), the domain (the band's
// voxels, and those of elements in an earlier band, held at their elements' labels) with its voxel
// faces and weights, and the solver's state. The next refinement adds the new band's voxels outside
// the domain to it while the domain holds at most 1.5 times the band's elements, else builds it
// again. Two labels: the max-flow graphs with their flow, whose terminal capacities move and whose
// flow runs on (Kohli & Torr; one graph only); its labels are a fresh refinement's, as a node's
// label depends only on the maximum flow's residual graph. More labels: the expansion's memory and,
// while the faces stay, its rows of edges; each move's optimum is a fresh band's (held voxels are
// hard nodes).
class VoxelRefinementCache
{
public:
  VoxelRefinementCache();
  ~VoxelRefinementCache();
  VoxelRefinementCache(VoxelRefinementCache&&) noexcept;
  VoxelRefinementCache& operator=(VoxelRefinementCache&&) noexcept;
  void Clear();
  struct State;
  std::unique_ptr<State> Kept;
};

VoxelRefinementResult RefineOnVoxels(const VoxelRefinementProblem& problem, const ProgressFunction& progress = NoProgress(),
  VoxelRefinementCache* cache = nullptr);

// The voxel cuts' automatic sigma: the root mean square of |x_v - x_u| over the grid's face
// neighbours (`values` voxels x channels, interleaved), summed over fixed slabs of slices so that
// any thread count gives the same value; 1 when it is 0.
template <typename T>
double VoxelGridSigma(const T* values, int channels, const ImageGeometry& geometry, const ParallelFor& parallel)
{
  constexpr std::int64_t slab = std::int64_t(1) << 16;
  const std::int64_t size = geometry.Size(), slabs = (size + slab - 1) / slab;
  const std::int64_t stride[3] = { 1, geometry.Dims[0], geometry.SliceStride() };
  std::vector<double> ss(slabs, 0.0), count(slabs, 0.0);
  parallel(slabs, 1, [&](std::int64_t s0, std::int64_t s1) {
    for (std::int64_t s = s0; s < s1; ++s)
    {
      const std::int64_t last = std::min(size, (s + 1) * slab);
      // The voxel's coordinates stepped along, not divided out of its index per voxel.
      std::array<int, 3> ijk = geometry.Coordinates(s * slab);
      double sum = 0.0, edges = 0.0;
      for (std::int64_t v = s * slab; v < last; ++v)
      {
        for (int d = 0; d < 3; ++d)
        {
          if (ijk[d] + 1 < geometry.Dims[d])
          {
            double d2 = 0.0;
            for (int c = 0; c < channels; ++c)
            {
              const double x = static_cast<double>(values[v * channels + c]) -
                static_cast<double>(values[(v + stride[d]) * channels + c]);
              d2 += x * x;
            }
            sum += d2;
            edges += 1.0;
          }
        }
        if (++ijk[0] == geometry.Dims[0])
        {
          ijk[0] = 0;
          if (++ijk[1] == geometry.Dims[1])
          {
            ijk[1] = 0;
            ++ijk[2];
          }
        }
      }
      ss[s] = sum;
      count[s] = edges;
    }
  });
  const double total = std::accumulate(ss.begin(), ss.end(), 0.0), edges = std::accumulate(count.begin(), count.end(), 0.0);
  const double sigma = edges > 0.0 ? std::sqrt(total / edges) : 1.0;
  return sigma > 0.0 ? sigma : 1.0;
}

// The exact minimum of a two-label Potts problem (label 1 pays Cost[2i + 1]) by Boykov-Kolmogorov
// max-flow; returns the energy, throws std::runtime_error when memory runs out. A graph that falls
// apart into components (a band around separate objects) runs them on two graphs side by side,
// dealt in order of their first node to the graph with fewer nodes so far; one component of more
// than three quarters of the nodes (an object's shell) runs alone. The labels are one graph's: a node
// takes label 1 unless it reaches the sink in the final residual graph, which every maximum flow
// leaves the same.
double BinaryPottsCut(const PottsProblem& problem, std::vector<std::uint8_t>& label, const ParallelFor& parallel);

// Writes the refinement into a label image whose voxels hold their elements' labels.
void ApplyRefinement(const VoxelRefinementResult& refinement, std::uint8_t* labels);
} // namespace featuremesh
