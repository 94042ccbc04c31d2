// Randomized shortest paths edge enhancement (thesis chapter 5): marching distance maps from the
// object and background seeds, random sources and sinks drawn from them, all source-sink shortest
// paths on the image grid, and the edge confidence (EC) they leave; in 2D the closed contour the EC
// ridge draws around the object. Works on a float image in index space.
#pragma once

#include "ImageGeometry.h"
#include "Parallel.h"

#include <cstdint>
#include <string>
#include <vector>

namespace featuremesh
{
struct RSPParameters
{
  // beta of the pixel cost G = exp(-beta |grad I|) (thesis eq. 25, 0.1). |grad I| is in 8-bit grey
  // levels per voxel: the image's robust range (1st to 99th percentile) is mapped to 0..255, so beta
  // means on any intensity range what the thesis's 0.1 means on an 8-bit image.
  double GradientScale = 0.1;
  // Gaussian standard deviation (voxels) before the gradient; 0 = the raw image, as the thesis.
  double GradientSigma = 1.0;
  // Random sources (object side) and sinks (background side), the thesis's 50 and 100.
  int Sources = 50;
  int Sinks = 100;
  // T of the rejection sampler (a voxel P is taken when M(P) <= V, V uniform in [0, T]), in units
  // of the marching map; 0 = the median of the map over the other class's seeds.
  double SamplingThreshold = 0.0;
  unsigned RandomSeed = 0;
  // Images with more voxels run on a grid coarsened by the smallest integer factor that brings them
  // within this many (block means; maps and EC come back by nearest neighbour); 0 = never. 2^21:
  // 2D images up to 1024^2 and the liver CT run at full resolution, BraTS (8.9 M) at factor 3.
  std::int64_t MaximumPathVoxels = 1048576;
  // Voxels the paths may use beyond the box the two marching maps reach (below their T).
  int PathMargin = 8;
  // The binary edge map: EC >= this fraction of the paths.
  double EdgeThreshold = 0.01;
  // 2D final contour: the cost of a voxel with EC = 0, in units of the cost of a voxel that every
  // path crossed. The thesis makes it infinite; a large finite cost bridges a one-voxel gap in the
  // ridge instead of leaving no contour.
  double GapCost = 1.0e4;
};

struct RSPResult
{
  // Per voxel of the input grid.
  std::vector<float> EdgeConfidence;      // paths through the voxel
  std::vector<std::uint8_t> EdgeMap;      // 1 = EC >= EdgeThreshold x paths
  std::vector<float> ObjectDistance;      // marching map from the object seeds (+inf beyond T)
  std::vector<float> BackgroundDistance;  // from the background seeds
  std::vector<std::int64_t> SourceVoxels, SinkVoxels;
  double ObjectThreshold = 0.0, BackgroundThreshold = 0.0; // T used for sources / sinks
  double GradientRange = 0.0;             // intensity range mapped to 255 grey levels
  std::int64_t Paths = 0;
  std::int64_t PathVoxels = 0;            // voxels of the box the paths ran in (on the path grid)
  int PathGridFactor = 1;                 // the path grid's coarsening of the input grid
  // 2D: the closed contour (voxel indices in order; the last is a 4-neighbour of the first) and the
  // region it encloses, contour included (1 inside).
  std::vector<std::int64_t> Contour;
  std::vector<std::uint8_t> Region;
  std::vector<std::pair<std::string, double>> StepSeconds;
  bool Aborted = false;
  std::string Error;
};

// Empty when usable, else a sentence.
std::string ValidateParameters(const RSPParameters& p);

// First-order fast marching of |grad M| = slowness from the `seeds` (M = 0 there), on the grid's
// index space with the spacing's aspect (unit = the smallest spacing). Marching stops once the front
// passes `stopAt` (or, when `stopAt` <= 0, when every voxel is reached); voxels not reached are
// +inf. With `median` not null and `stopAt` <= 0, marching stops once it passes the median of M over
// `medianOf` (written to *median) instead. Empty when `progress` (asked every 65536 voxels, with
// the fraction of the image reached) asks to abort.
std::vector<float> FastMarching(const float* slowness, const ImageGeometry& grid, const std::vector<std::int64_t>& seeds,
  double stopAt, const std::vector<std::int64_t>* medianOf = nullptr, double* median = nullptr,
  const ProgressFunction& progress = NoProgress());

// Rejection sampling (thesis 5.1.3): draws voxels uniformly among those with map <= T and keeps P
// when map(P) <= V, V uniform in [0, T], until `count` distinct voxels are kept (fewer when the
// draws run out). Deterministic for a given `seed`.
std::vector<std::int64_t> RejectionSample(const std::vector<float>& map, double T, int count, std::uint64_t seed);

// The whole stage. Seeds are voxel indices; errors (constant image, seeds of both kinds on one
// voxel, bad parameters) come back in Error.
RSPResult RSPEdgeEnhancement(const float* image, const ImageGeometry& grid, const std::vector<std::int64_t>& objectSeeds,
  const std::vector<std::int64_t>& backgroundSeeds, const RSPParameters& p, const ParallelFor& parallel,
  const ProgressFunction& progress);

// The 2D final contour (thesis 5.3) on an EC image: the cheapest closed path (cost 1/EC per voxel,
// GapCost where EC = 0) through the brightest voxel A that winds around the nearest of `inside`
// (the object seeds), without the tail out to A when A lies off the loop. Voxel indices in order;
// each is a 4-neighbour of the next and the last of the first; no voxel twice. Empty when the image is not 2D or EC is all zero.
std::vector<std::int64_t> FinalContour(const std::vector<float>& ec, const ImageGeometry& grid,
  const std::vector<std::int64_t>& inside, double gapCost);

// The voxels enclosed by a closed 4-connected contour, contour included (2D).
std::vector<std::uint8_t> FillContour(const std::vector<std::int64_t>& contour, const ImageGeometry& grid);
} // namespace featuremesh
