// Feature-sensitive node generation (thesis 2.1 and 4.1): Canny edge points thinned by PCA,
// halftoning points from a Hessian feature map, uniform fill points and boundary nodes.
// Works on a float image in index space.
#pragma once

#include "Contract.h"
#include "ImageGeometry.h"
#include "Parallel.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace featuremesh
{
struct FeatureNodeParameters
{
  // Gaussian standard deviations (voxels): before Canny, and before the Hessian of the feature map.
  double GaussianSigma = 0.7;
  double HessianSigma = 2.0;
  // Canny hysteresis thresholds, as fractions of a robust maximum of the gradient magnitude.
  double LowThreshold = 0.1;
  double HighThreshold = 0.6;
  // Percentile of the gradient magnitude (over all voxels) taken as its maximum; 100 = plain max.
  double MaximumPercentile = 99.0;
  // Noise floor. The thresholds above are fractions of maxima, which noise lifts less than it
  // lifts the flat regions: on a noisy image every voxel became an edge. With NoiseFloor, Canny's
  // low and high thresholds are at least NoiseLowFactor and NoiseHighFactor standard deviations
  // of the noise's gradient component, and the feature map below is 0 where its Hessian norm stays
  // under NoiseFeatureFactor deviations of the noise's Hessian diagonal; the noise's deviation is
  // estimated from the image (EstimateNoiseSigma, 0 on a noise-free image: nothing changes). In
  // white noise 3 % of voxels exceed the low floor, 1e-5 the high one, 1 % the feature floor.
  bool NoiseFloor = true;
  double NoiseLowFactor = 3.0;
  double NoiseHighFactor = 5.0;
  double NoiseFeatureFactor = 3.5;
  // Edge of the (cubic) neighbourhood whose edge points give the PCA covariance; 0 = 11 (2D), 5 (3D).
  int CovarianceNeighbourhood = 0;
  // Eigenvalue-ratio classes: ratio < StraightRatio -> straight/flat, < CurvedRatio -> moderate.
  double StraightRatio = 0.3;
  double CurvedRatio = 0.5;
  // Sampling radii (voxels) for straight / moderate / curved edge points.
  std::array<int, 3> Radii2D{ { 5, 3, 1 } };
  std::array<int, 3> Radii3D{ { 4, 3, 2 } };
  // Halftoning: threshold q and exponent gamma of rho = (max|mu| / A)^gamma.
  bool Halftoning = true;
  double HalftoneThreshold = 0.3;
  double HalftoneGamma = 1.0;
  // Percentile of the Hessian norm taken as A; 100 (the thesis's plain maximum) keeps the map
  // sparse on noisy images, where a robust maximum would let noise set the node density.
  double FeaturePercentile = 100.0;
  // Edge of the window (voxels) that must be free of Canny points for a halftone point, and of
  // any node for a uniform point.
  int ExclusionWindow = 7;
  // The uniform and boundary lattices' spacing, in voxels of the finest axis (the uniform points'
  // window too): even in world units on thick slices.
  int UniformSpacing = 7;
  int BoundarySpacing = 7;
  // With an edge map supplied (a sparse, seed-driven one such as RSP Edge Enhancement's), SeedAware
  // makes the mesh fine at those edges and coarse away from them: the edges are the map plus the
  // Canny edges within EdgeGateRadius voxels of it; the halftone map is kept within s of the edges and damped by
  // exp(-((d - s) / s)^2) beyond, and
  // the uniform and boundary spacings double at distances 2s, 6s, 14s ... from the edges (s =
  // UniformSpacing, at most CoarseningLevels doublings). Off: the map replaces Canny, nothing else
  // changes (the thesis's use). Without an edge map these have no effect.
  bool SeedAware = true;
  int EdgeGateRadius = 20;
  int CoarseningLevels = 3;
};

struct FeatureNodeResult
{
  // Node positions in index space, one node per voxel at most.
  std::vector<std::array<int, 3>> Positions;
  std::vector<NodeType> Type;
  std::vector<std::uint8_t> Fixed;
  std::vector<float> SampleRadius;
  // Edge map used (1 = edge voxel), on the input grid.
  std::vector<std::uint8_t> EdgeMap;
  double GradientMaximum = 0.0;
  double FeatureMaximum = 0.0;
  // The noise's standard deviation in the image's units (0 without NoiseFloor).
  double NoiseSigma = 0.0;
  std::int64_t EdgeVoxels = 0;
  std::int64_t Counts[4] = { 0, 0, 0, 0 };
  // Seconds spent per step, for the benchmark.
  std::vector<std::pair<std::string, double>> StepSeconds;
  bool Aborted = false;
};

// The whole recipe on `image` (smoothing included). `edgeMap`, when not null, replaces Canny
// (non-zero = edge).
FeatureNodeResult ComputeFeatureNodes(const float* image, const std::uint8_t* edgeMap, const ImageGeometry& grid,
  const FeatureNodeParameters& p, const ParallelFor& parallel, const ProgressFunction& progress);

// Returns an empty string when the parameters are usable, else a sentence saying what is wrong.
std::string ValidateParameters(const FeatureNodeParameters& p);
} // namespace featuremesh
