#include "GaussianMixture.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace featuremesh
{
namespace
{
using Matrix = Eigen::MatrixXd;
using Vector = Eigen::VectorXd;

constexpr int MaxIterations = 200;
constexpr double Tolerance = 1e-7; // relative change of the log-likelihood that ends EM
const double Log2Pi = std::log(2.0 * 3.14159265358979323846);

struct Component
{
  double Weight = 0.0;
  Vector Mean;
  Matrix Covariance;
};

double TotalWeight(const std::vector<Component>& components)
{
  return std::accumulate(components.begin(), components.end(), 0.0, [](double s, const Component& c) { return s + c.Weight; });
}

// The weighted mean and covariance (+ regularisation) of the points i with `use(i)`.
template <typename Use>
Component Moments(const std::vector<Vector>& x, const std::vector<double>& w, const Vector& reg, Use use)
{
  const int d = static_cast<int>(reg.size());
  Component c;
  c.Mean = Vector::Zero(d);
  c.Covariance = Matrix::Zero(d, d);
  for (std::size_t i = 0; i < x.size(); ++i)
  {
    const double u = use(i) * w[i];
    c.Weight += u;
    c.Mean += u * x[i];
  }
  if (c.Weight > 0.0)
  {
    c.Mean /= c.Weight;
    for (std::size_t i = 0; i < x.size(); ++i)
    {
      const double u = use(i) * w[i];
      const Vector r = x[i] - c.Mean;
      c.Covariance += u * r * r.transpose();
    }
    c.Covariance /= c.Weight;
  }
  c.Covariance += reg.asDiagonal();
  return c;
}

// Per component: log of its weight times its normalising constant, and the inverse of its
// covariance's Cholesky factor (row-major, d x d): the log-density is LogScale - |Inverse (x - mean)|^2 / 2.
struct Prepared
{
  double LogScale = 0.0;
  std::vector<double> Inverse, Mean;
};

Prepared Prepare(const Component& c, double total)
{
  const int d = static_cast<int>(c.Mean.size());
  Prepared p;
  const Eigen::LLT<Matrix> factor(c.Covariance);
  const Matrix l = factor.matrixL();
  double logDet = 0.0;
  for (int i = 0; i < d; ++i)
  {
    logDet += 2.0 * std::log(l(i, i));
  }
  const Matrix inverse = l.triangularView<Eigen::Lower>().solve(Matrix::Identity(d, d));
  p.Inverse.resize(d * d);
  for (int i = 0; i < d; ++i)
  {
    for (int j = 0; j < d; ++j)
    {
      p.Inverse[i * d + j] = inverse(i, j);
    }
  }
  p.Mean.assign(c.Mean.data(), c.Mean.data() + d);
  p.LogScale = std::log(c.Weight / total) - 0.5 * (static_cast<double>(d) * Log2Pi + logDet);
  return p;
}

double LogComponent(const Prepared& p, const double* x)
{
  const int d = static_cast<int>(p.Mean.size());
  double q = 0.0;
  for (int i = 0; i < d; ++i)
  {
    double z = 0.0;
    for (int j = 0; j <= i; ++j)
    {
      z += p.Inverse[i * d + j] * (x[j] - p.Mean[j]);
    }
    q += z * z;
  }
  return p.LogScale - 0.5 * q;
}

// EM from `components`; returns the weighted log-likelihood.
double Expectation(const std::vector<Vector>& x, const std::vector<double>& w, const Vector& reg,
  std::vector<Component>& components)
{
  const std::size_t n = x.size();
  double last = -std::numeric_limits<double>::infinity(), ll = last;
  std::vector<double> resp;
  for (int it = 0; it < MaxIterations; ++it)
  {
    const double total = TotalWeight(components);
    std::vector<Prepared> prepared;
    for (const Component& c : components)
    {
      prepared.push_back(Prepare(c, total));
    }
    const std::size_t k = components.size();
    resp.assign(n * k, 0.0);
    ll = 0.0;
    for (std::size_t i = 0; i < n; ++i)
    {
      double top = -std::numeric_limits<double>::infinity();
      for (std::size_t j = 0; j < k; ++j)
      {
        resp[i * k + j] = LogComponent(prepared[j], x[i].data());
        top = std::max(top, resp[i * k + j]);
      }
      double sum = 0.0;
      for (std::size_t j = 0; j < k; ++j)
      {
        resp[i * k + j] = std::exp(resp[i * k + j] - top);
        sum += resp[i * k + j];
      }
      for (std::size_t j = 0; j < k; ++j)
      {
        resp[i * k + j] /= sum;
      }
      ll += w[i] * (top + std::log(sum));
    }
    if (std::fabs(ll - last) <= Tolerance * std::fabs(ll))
    {
      break;
    }
    last = ll;
    std::vector<Component> next;
    for (std::size_t j = 0; j < k; ++j)
    {
      Component c = Moments(x, w, reg, [&](std::size_t i) { return resp[i * k + j]; });
      if (c.Weight > 1e-9 * total)
      {
        next.push_back(std::move(c));
      }
    }
    components.swap(next);
  }
  return ll;
}

// k components from weighted quantiles along the principal axis.
std::vector<Component> Start(const std::vector<Vector>& x, const std::vector<double>& w, const Vector& reg, int k)
{
  const Component all = Moments(x, w, reg, [](std::size_t) { return 1.0; });
  Eigen::SelfAdjointEigenSolver<Matrix> eigen(all.Covariance);
  const Vector axis = eigen.eigenvectors().col(eigen.eigenvalues().size() - 1);
  std::vector<std::size_t> order(x.size());
  std::iota(order.begin(), order.end(), 0);
  std::vector<double> along(x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
  {
    along[i] = axis.dot(x[i] - all.Mean);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return along[a] < along[b]; });
  std::vector<int> group(x.size(), 0);
  double seen = 0.0;
  for (std::size_t i : order)
  {
    group[i] = std::min(k - 1, static_cast<int>(k * (seen + 0.5 * w[i]) / all.Weight));
    seen += w[i];
  }
  std::vector<Component> components;
  for (int j = 0; j < k; ++j)
  {
    Component c = Moments(x, w, reg, [&](std::size_t i) { return group[i] == j ? 1.0 : 0.0; });
    if (c.Weight > 0.0)
    {
      components.push_back(std::move(c));
    }
  }
  return components;
}
} // namespace

std::vector<double> GaussianMixture::Densities(const std::vector<double>& points) const
{
  const int d = this->Dimensions;
  std::vector<Prepared> prepared;
  for (int j = 0; j < this->Components(); ++j)
  {
    Component c;
    c.Weight = this->Weight[j];
    c.Mean = Eigen::Map<const Vector>(this->Mean.data() + j * d, d);
    c.Covariance = Eigen::Map<const Matrix>(this->Covariance.data() + j * d * d, d, d);
    prepared.push_back(Prepare(c, 1.0));
  }
  std::vector<double> density(d > 0 ? points.size() / d : 0, 0.0);
  for (std::size_t i = 0; i < density.size(); ++i)
  {
    for (const Prepared& p : prepared)
    {
      density[i] += std::exp(LogComponent(p, points.data() + i * d));
    }
  }
  return density;
}

GaussianMixture FitGaussianMixture(const std::vector<double>& points, const std::vector<double>& weight, int dimensions,
  int maxComponents, const std::vector<double>& regularisation)
{
  GaussianMixture best;
  best.Dimensions = dimensions;
  std::vector<Vector> x;
  std::vector<double> w;
  for (std::size_t i = 0; i < weight.size(); ++i)
  {
    if (weight[i] > 0.0)
    {
      x.push_back(Eigen::Map<const Vector>(points.data() + i * dimensions, dimensions));
      w.push_back(weight[i]);
    }
  }
  const double total = std::accumulate(w.begin(), w.end(), 0.0);
  if (x.empty() || !(total > 0.0))
  {
    return best;
  }
  const Vector reg = Eigen::Map<const Vector>(regularisation.data(), dimensions);
  double bestScore = std::numeric_limits<double>::infinity();
  const double d = dimensions;
  for (int k = 1; k <= maxComponents; ++k)
  {
    std::vector<Component> components = Start(x, w, reg, k);
    const double ll = Expectation(x, w, reg, components);
    const double kk = static_cast<double>(components.size());
    const double parameters = kk - 1.0 + kk * d + kk * d * (d + 1.0) / 2.0;
    const double score = -2.0 * ll + parameters * std::log(total);
    if (score < bestScore)
    {
      bestScore = score;
      best.Weight.clear();
      best.Mean.clear();
      best.Covariance.clear();
      const double sum = TotalWeight(components);
      for (const Component& c : components)
      {
        best.Weight.push_back(c.Weight / sum);
        best.Mean.insert(best.Mean.end(), c.Mean.data(), c.Mean.data() + dimensions);
        best.Covariance.insert(best.Covariance.end(), c.Covariance.data(), c.Covariance.data() + dimensions * dimensions);
      }
    }
  }
  return best;
}
} // namespace featuremesh
