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
  int UniformSpacing = 7;
  int BoundarySpacing = 7;
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
  std::int64_t EdgeVoxels = 0;
  std::int64_t Counts[4] = { 0, 0, 0, 0 };
  // Seconds spent per step, for the benchmark.
  std::vector<std::pair<std::string, double>> StepSeconds;
  bool Aborted = false;
};

// Separable Gaussian smoothing, sigma in voxels, kernel radius ceil(3 sigma), borders replicated.
// Own implementation because vtkImageGaussianSmooth measured 0.54 s (SMP) to 1.16 s (threads) for
// sigma 0.7 on a 240x240x155 float volume, against a 0.6 s budget for the whole stage.
void GaussianSmooth(const float* in, float* out, const ImageGeometry& grid, double sigma, const ParallelFor& parallel);

// Gradient magnitude by central differences (one-sided on the border), in voxel units.
void GradientMagnitude(const float* image, const ImageGeometry& grid, float* magnitude, const ParallelFor& parallel);

// Value below which `percentile` % of the values lie (a 4096-bin histogram over [0, max]).
double RobustMaximum(const float* values, std::int64_t n, double percentile, const ParallelFor& parallel);

// Canny edges on an already smoothed image: non-maximum suppression along the quantised gradient
// direction, hysteresis by 8-/26-connectivity. Returns 1 on edge voxels.
// `magnitudeBuffer`, when given, is n floats of scratch for the gradient magnitude.
std::vector<std::uint8_t> CannyEdges(const float* smoothed, const ImageGeometry& grid, double low, double high,
  double percentile, const ParallelFor& parallel, double* gradientMaximum = nullptr,
  float* magnitudeBuffer = nullptr);

// PCA sampling radius of each edge point (listed by voxel index).
std::vector<std::uint8_t> EdgeSampleRadii(const std::vector<std::int64_t>& edgePoints,
  const std::vector<std::uint8_t>& edgeMap, const ImageGeometry& grid, const FeatureNodeParameters& p,
  const ParallelFor& parallel);

// Greedy thinning: visit points by (radius, voxel index); keep a point when no kept point lies
// within its (2R+1)-box. Returns the indices (into edgePoints) of the kept points.
std::vector<std::int64_t> ThinEdgePoints(
  const std::vector<std::int64_t>& edgePoints, const std::vector<std::uint8_t>& radii, const ImageGeometry& grid);

// max |eigenvalue| of the symmetric 3x3 matrix [a11 a12 a13; a12 a22 a23; a13 a23 a33], to about
// 1e-6 of the matrix norm.
float LargestAbsEigenvalue(float a11, float a22, float a33, float a12, float a13, float a23);

// rho = (max_i |mu_i| / A)^gamma from the Hessian's eigenvalues, A a robust maximum; clipped to 1.
// Written into a caller's buffer of n floats.
void HessianFeatureMap(const float* smoothed, const ImageGeometry& grid, double gamma, double percentile,
  const ParallelFor& parallel, float* rho, double* featureMaximum = nullptr);

// Floyd-Steinberg error diffusion of rho with threshold q: a dot is worth 2q of feature (a midpoint
// quantiser, q = 0.5 is the classic algorithm), so raising q lowers the dot count. 3D uses half the
// classic in-slice stencil plus half to the next slice (centre 6/16, its 4-neighbours 2.5/16 each).
// Returns the voxel indices of the dots.
std::vector<std::int64_t> Halftone(const float* rho, const ImageGeometry& grid, double q);

// The whole recipe on `image` (smoothing included). `edgeMap`, when not null, replaces Canny
// (non-zero = edge).
FeatureNodeResult ComputeFeatureNodes(const float* image, const std::uint8_t* edgeMap, const ImageGeometry& grid,
  const FeatureNodeParameters& p, const ParallelFor& parallel, const ProgressFunction& progress);

// Returns an empty string when the parameters are usable, else a sentence saying what is wrong.
std::string ValidateParameters(const FeatureNodeParameters& p);
} // namespace featuremesh
