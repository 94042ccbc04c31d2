#include "BoykovJolly.h"

#include <maxflow.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numeric>

namespace featuremesh
{
namespace
{
// Percentile of at most ~1 M evenly strided values: exact enough for a histogram range, and a
// 9 M-voxel volume is not copied and partially sorted twice.
double Percentile(const double* data, std::int64_t n, double q)
{
  if (n <= 0)
  {
    return 0.0;
  }
  const std::int64_t stride = std::max<std::int64_t>(1, n / 1000000);
  std::vector<double> v;
  v.reserve(static_cast<size_t>(n / stride + 1));
  for (std::int64_t i = 0; i < n; i += stride)
  {
    v.push_back(data[i]);
  }
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(q / 100.0 * static_cast<double>(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}
using Clock = std::chrono::steady_clock;
} // namespace

std::string ValidateParameters(const BoykovJollyParameters& p)
{
  if (p.Bins != 0 && (p.Bins < 2 || p.Bins > 4096))
  {
    return "the histogram bin count must be 0 (automatic) or between 2 and 4096.";
  }
  if (!(p.Sigma >= 0.0) || !std::isfinite(p.Sigma))
  {
    return "sigma must be 0 (automatic) or positive.";
  }
  if (!(p.Lambda >= 0.0) || !std::isfinite(p.Lambda))
  {
    return "lambda must be a finite, non-negative number.";
  }
  return std::string();
}

std::vector<double> SmoothedHistogram(
  const std::vector<double>& s, const std::vector<double>& w, double low, double high, int bins)
{
  std::vector<double> hist(bins, 0.0);
  const double width = (high - low) / bins;
  double total = 0.0, mean = 0.0;
  for (size_t i = 0; i < s.size(); ++i)
  {
    const double wi = w.empty() ? 1.0 : w[i];
    const int b = std::min(bins - 1, std::max(0, static_cast<int>((s[i] - low) / width)));
    hist[b] += wi;
    total += wi;
    mean += wi * s[i];
  }
  std::vector<double> density(bins, 1.0 / bins);
  if (total <= 0.0)
  {
    return density;
  }
  mean /= total;
  double var = 0.0;
  for (size_t i = 0; i < s.size(); ++i)
  {
    var += (w.empty() ? 1.0 : w[i]) * (s[i] - mean) * (s[i] - mean);
  }
  const double sd = std::sqrt(var / total);
  // Silverman's rule with the unweighted sample count: weights say how much a sample counts, not
  // how many independent draws it is.
  const double h = std::max(1.0, 1.06 * sd * std::pow(static_cast<double>(s.size()), -0.2) / width);
  const int radius = static_cast<int>(std::ceil(3.0 * h));
  double sum = 0.0;
  for (int b = 0; b < bins; ++b)
  {
    double acc = 0.0;
    for (int t = std::max(0, b - radius); t <= std::min(bins - 1, b + radius); ++t)
    {
      acc += hist[t] * std::exp(-0.5 * (b - t) * (b - t) / (h * h));
    }
    density[b] = acc;
    sum += acc;
  }
  for (double& d : density)
  {
    d = 0.99 * d / sum + 0.01 / bins;
  }
  return density;
}

CutResult BoykovJollyCut(const CutProblem& pr, const BoykovJollyParameters& par)
{
  CutResult r;
  const auto t0 = Clock::now();
  const std::int64_t n = static_cast<std::int64_t>(pr.Value.size());
  const std::int64_t m = static_cast<std::int64_t>(pr.A.size());
  if (n == 0)
  {
    r.Error = "the graph is empty.";
    return r;
  }
  if (n > static_cast<std::int64_t>(2000000000) || 2 * m > static_cast<std::int64_t>(2000000000))
  {
    r.Error = "the graph is too large for the max-flow library (node ids are 32-bit).";
    return r;
  }
  r.Bins = par.Bins > 0 ? par.Bins : 64;
  const bool exact = pr.VoxelValue && pr.VoxelOwner;
  const double* rangeData = exact ? pr.VoxelValue : pr.Value.data();
  const std::int64_t rangeCount = exact ? pr.VoxelTotal : n;
  double low = Percentile(rangeData, rangeCount, 0.5), high = Percentile(rangeData, rangeCount, 99.5);
  for (double v : pr.ObjectSamples)
  {
    low = std::min(low, v);
    high = std::max(high, v);
  }
  for (double v : pr.BackgroundSamples)
  {
    low = std::min(low, v);
    high = std::max(high, v);
  }
  if (!(high > low))
  {
    high = low + 1.0;
  }
  const std::vector<double> pObject = SmoothedHistogram(pr.ObjectSamples, pr.ObjectWeights, low, high, r.Bins);
  const std::vector<double> pBackground =
    SmoothedHistogram(pr.BackgroundSamples, pr.BackgroundWeights, low, high, r.Bins);
  std::vector<double> costObject(r.Bins), costBackground(r.Bins);
  for (int b = 0; b < r.Bins; ++b)
  {
    costObject[b] = -std::log(pObject[b]);
    costBackground[b] = -std::log(pBackground[b]);
  }
  const double width = (high - low) / r.Bins;
  auto bin = [&](double v) { return std::min(r.Bins - 1, std::max(0, static_cast<int>((v - low) / width))); };

  r.Sigma = par.Sigma;
  if (r.Sigma <= 0.0)
  {
    double ss = 0.0;
    for (std::int64_t e = 0; e < m; ++e)
    {
      const double d = pr.Value[pr.A[e]] - pr.Value[pr.B[e]];
      ss += d * d;
    }
    r.Sigma = m ? std::sqrt(ss / static_cast<double>(m)) : 1.0;
    if (!(r.Sigma > 0.0))
    {
      r.Sigma = 1.0;
    }
  }
  const double inv2s2 = 1.0 / (2.0 * r.Sigma * r.Sigma);

  using G = maxflow::Graph_DDD;
  auto g = std::make_unique<G>(static_cast<int>(n), static_cast<int>(m));
  g->add_node(static_cast<int>(n));
  std::vector<double> weight(m);
  double total = 1.0;
  for (std::int64_t e = 0; e < m; ++e)
  {
    const double d = pr.Value[pr.A[e]] - pr.Value[pr.B[e]];
    weight[e] = pr.Contact[e] * std::exp(-d * d * inv2s2);
    total += weight[e];
  }
  // Region costs of each node: labelled object it pays regionObject, labelled background regionBackground.
  std::vector<double> regionObject(n), regionBackground(n);
  if (exact)
  {
    for (std::int64_t v = 0; v < pr.VoxelTotal; ++v)
    {
      const std::int64_t p = pr.VoxelOwner[v];
      if (p >= 0 && p < n)
      {
        const int b = bin(pr.VoxelValue[v]);
        regionObject[p] += costObject[b];
        regionBackground[p] += costBackground[b];
      }
    }
  }
  else
  {
    for (std::int64_t p = 0; p < n; ++p)
    {
      const int b = bin(pr.Value[p]);
      regionObject[p] = pr.Size[p] * costObject[b];
      regionBackground[p] = pr.Size[p] * costBackground[b];
    }
  }
  for (std::int64_t p = 0; p < n; ++p)
  {
    regionObject[p] *= par.Lambda;
    regionBackground[p] *= par.Lambda;
    total += std::max(regionObject[p], regionBackground[p]);
  }
  // K exceeds the energy of any labelling, so hard constraints are never cut.
  const double K = total;
  for (std::int64_t p = 0; p < n; ++p)
  {
    if (pr.Hard[p] == 1)
    {
      g->add_tweights(static_cast<int>(p), K, 0.0);
    }
    else if (pr.Hard[p] == 2)
    {
      g->add_tweights(static_cast<int>(p), 0.0, K);
    }
    else
    {
      // Source = object: a node left on the source side pays its sink capacity.
      g->add_tweights(static_cast<int>(p), regionBackground[p], regionObject[p]);
    }
  }
  for (std::int64_t e = 0; e < m; ++e)
  {
    g->add_edge(static_cast<int>(pr.A[e]), static_cast<int>(pr.B[e]), weight[e], weight[e]);
  }
  const auto t1 = Clock::now();
  r.GraphSeconds = std::chrono::duration<double>(t1 - t0).count();
  r.Flow = g->maxflow();
  r.Label.resize(n);
  for (std::int64_t p = 0; p < n; ++p)
  {
    r.Label[p] = g->what_segment(static_cast<int>(p)) == G::SOURCE ? 1 : 0;
  }
  r.FlowSeconds = std::chrono::duration<double>(Clock::now() - t1).count();
  return r;
}
} // namespace featuremesh
