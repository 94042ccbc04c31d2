// PCA edge sampling (thesis 2.1): a sampling radius per edge point from the shape of its
// neighbouring edge points, and greedy thinning to those radii.
#pragma once

#include "FeatureNodes.h"
#include "ImageGeometry.h"
#include "Parallel.h"

#include <cstdint>
#include <vector>

namespace featuremesh
{
// Sampling radius from the edge points around one edge point: their count and integer moments
// relative to it, {sum x, sum y, sum z, sum xx, sum yy, sum zz, sum xy, sum xz, sum yz}. The
// eigenvalue ratio of their covariance (smallest / largest) classes the point as straight or flat,
// moderate, or curved (a corner, a speck, or too few points); each class has its radius.
std::uint8_t SamplingRadius(std::int64_t count, const std::int64_t moments[9], int dimension, const FeatureNodeParameters& p);

// PCA sampling radius of each edge point (listed by voxel index).
std::vector<std::uint8_t> EdgeSampleRadii(const std::vector<std::int64_t>& edgePoints,
  const std::vector<std::uint8_t>& edgeMap, const ImageGeometry& grid, const FeatureNodeParameters& p,
  const ParallelFor& parallel);

// Greedy thinning: visit points by (radius, voxel index); keep a point when no kept point lies
// within its (2R+1)-box. Returns the indices (into edgePoints) of the kept points.
std::vector<std::int64_t> ThinEdgePoints(
  const std::vector<std::int64_t>& edgePoints, const std::vector<std::uint8_t>& radii, const ImageGeometry& grid);
} // namespace featuremesh
