// A Gaussian mixture fitted by expectation-maximisation to weighted points (binned samples: each
// bin's centre weighted by its count), for a label's density over several channels. Deterministic:
// the components start from weighted quantiles along the samples' principal axis; the number of
// components is chosen by the Bayesian information criterion.
#pragma once

#include <vector>

namespace featuremesh
{
struct GaussianMixture
{
  int Dimensions = 0;
  std::vector<double> Weight;     // per component
  std::vector<double> Mean;       // component x dimension
  std::vector<double> Covariance; // component x dimension x dimension

  int Components() const { return static_cast<int>(this->Weight.size()); }
  // The density at each point of `points` (count x Dimensions).
  std::vector<double> Densities(const std::vector<double>& points) const;
};

// The mixture of 1..maxComponents components with the lowest BIC for `points` (count x dimensions)
// with weights `weight` (the number of samples each stands for). `regularisation` (per dimension)
// is added to every component's covariance diagonal: the variance of the kernel a binned density
// would be smoothed with, so that no component collapses onto one bin. Empty without weight.
GaussianMixture FitGaussianMixture(const std::vector<double>& points, const std::vector<double>& weight, int dimensions,
  int maxComponents, const std::vector<double>& regularisation);
} // namespace featuremesh
