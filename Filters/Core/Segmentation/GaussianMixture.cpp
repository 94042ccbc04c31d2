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
constexpr double Tolerance = 1e-8; // relative change of the log-likelihood that ends EM
const double Log2Pi = std::log(2.0 * 3.14159265358979323846);

struct Component
{
  double Weight = 0.0;
  Vector Mean;
  Matrix Covariance;
};

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

// Per component: log of its weight times its normalising constant, and the Cholesky factor.
struct Prepared
{
  double LogScale = 0.0;
  Eigen::LLT<Matrix> Factor;
};

Prepared Prepare(const Component& c, double total)
{
  Prepared p;
  p.Factor.compute(c.Covariance);
  const Matrix& l = p.Factor.matrixLLT();
  double logDet = 0.0;
  for (int i = 0; i < l.rows(); ++i)
  {
    logDet += 2.0 * std::log(l(i, i));
  }
  p.LogScale = std::log(c.Weight / total) - 0.5 * (static_cast<double>(l.rows()) * Log2Pi + logDet);
  return p;
}

double LogComponent(const Prepared& p, const Component& c, const Vector& x)
{
  const Vector z = p.Factor.matrixL().solve(x - c.Mean);
  return p.LogScale - 0.5 * z.squaredNorm();
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
    const double total = std::accumulate(components.begin(), components.end(), 0.0,
      [](double s, const Component& c) { return s + c.Weight; });
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
        resp[i * k + j] = LogComponent(prepared[j], components[j], x[i]);
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

double GaussianMixture::Density(const double* x) const
{
  const int d = this->Dimensions;
  double sum = 0.0;
  for (int j = 0; j < this->Components(); ++j)
  {
    const Eigen::Map<const Matrix> cov(this->Covariance.data() + j * d * d, d, d);
    const Eigen::Map<const Vector> mean(this->Mean.data() + j * d, d);
    const Eigen::Map<const Vector> at(x, d);
    Component c;
    c.Weight = this->Weight[j];
    c.Mean = mean;
    c.Covariance = cov;
    const Prepared p = Prepare(c, 1.0);
    sum += std::exp(LogComponent(p, c, at));
  }
  return sum;
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
      const double sum = std::accumulate(components.begin(), components.end(), 0.0,
        [](double s, const Component& c) { return s + c.Weight; });
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
