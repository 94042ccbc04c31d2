#include "MultiLabelCut.h"
#include "GaussianMixture.h"
#include "Percentile.h"
#include "SeedGeodesics.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>

namespace featuremesh
{
namespace
{
using Clock = std::chrono::steady_clock;
double Since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// At most this many Gaussians per label (ChannelModel GaussianMixture); BIC picked 2 on the
// abdomen's organs and 4 allowed no better fit than 2 (docs/multilabel.md).
constexpr int MixtureComponents = 4;

// A Gaussian blur of `grid` (PerChannel^channels bins) along `axis`, sigma `h` bins, truncated at 3h.
void BlurAxis(std::vector<double>& grid, int perChannel, int channels, int axis, double h)
{
  const int radius = static_cast<int>(std::ceil(3.0 * h));
  std::vector<double> kernel(2 * radius + 1);
  for (int i = -radius; i <= radius; ++i)
  {
    kernel[i + radius] = std::exp(-0.5 * i * i / (h * h));
  }
  std::int64_t stride = 1;
  for (int a = 0; a < axis; ++a)
  {
    stride *= perChannel;
  }
  const std::int64_t total = static_cast<std::int64_t>(grid.size());
  std::vector<double> out(grid.size(), 0.0), line(perChannel);
  (void)channels;
  for (std::int64_t start = 0; start < total; ++start)
  {
    if ((start / stride) % perChannel != 0)
    {
      continue; // not the first bin of a line along `axis`
    }
    for (int i = 0; i < perChannel; ++i)
    {
      line[i] = grid[start + i * stride];
    }
    for (int i = 0; i < perChannel; ++i)
    {
      if (line[i] == 0.0)
      {
        continue;
      }
      for (int d = -radius; d <= radius; ++d)
      {
        const int j = i + d;
        if (j >= 0 && j < perChannel)
        {
          out[start + j * stride] += line[i] * kernel[d + radius];
        }
      }
    }
  }
  grid.swap(out);
}

// Silverman's bandwidth in bins of the samples `counts` along `axis` (d dimensions).
double Bandwidth(const std::vector<double>& counts, int perChannel, int axis, int d, double factor)
{
  std::int64_t stride = 1;
  for (int a = 0; a < axis; ++a)
  {
    stride *= perChannel;
  }
  double n = 0.0, sum = 0.0, sum2 = 0.0;
  for (std::size_t b = 0; b < counts.size(); ++b)
  {
    const double x = static_cast<double>((static_cast<std::int64_t>(b) / stride) % perChannel);
    n += counts[b];
    sum += counts[b] * x;
    sum2 += counts[b] * x * x;
  }
  if (n <= 0.0)
  {
    return 1.0;
  }
  const double mean = sum / n, sd = std::sqrt(std::max(0.0, sum2 / n - mean * mean));
  return std::max(1.0, factor * 1.06 * sd * std::pow(n, -1.0 / (d + 4)));
}

// -ln of a normalised density mixed with 1 % uniform.
std::vector<double> NegativeLog(std::vector<double> density)
{
  const double total = std::accumulate(density.begin(), density.end(), 0.0);
  const double uniform = 1.0 / static_cast<double>(density.size());
  for (double& p : density)
  {
    p = -std::log(0.99 * (total > 0.0 ? p / total : uniform) + 0.01 * uniform);
  }
  return density;
}

// The seeds' nodes: hard[p] = label or -1; false with a sentence when two labels share a node.
bool LabelConstraints(const LabelledSeeds& seeds, const std::function<std::int64_t(std::int64_t)>& node,
  std::int64_t nodes, const char* what, std::vector<std::int16_t>& hard, std::string& error)
{
  hard.assign(nodes, -1);
  for (std::size_t s = 0; s < seeds.Voxel.size(); ++s)
  {
    const std::int64_t p = node(seeds.Voxel[s]);
    if (p < 0)
    {
      error = "a seed lies outside the mesh.";
      return false;
    }
    if (hard[p] >= 0 && hard[p] != seeds.Label[s])
    {
      error = std::string(what) + " " + std::to_string(p) + " holds seeds of labels " + std::to_string(hard[p]) + " and " +
        std::to_string(seeds.Label[s]) + "; move one of them.";
      return false;
    }
    hard[p] = seeds.Label[s];
  }
  return true;
}

// Boundary weights contact * exp(-|dm|^2 / 2 sigma^2) over the edges, sigma automatic (RMS) when <= 0.
std::vector<double> PottsWeights(const GraphEdges& edges, const std::vector<double>& mean, int channels,
  const std::vector<double>& contact, double& sigma)
{
  auto d2 = [&](std::int64_t a, std::int64_t b) {
    double s = 0.0;
    for (int c = 0; c < channels; ++c)
    {
      const double d = mean[a * channels + c] - mean[b * channels + c];
      s += d * d;
    }
    return s;
  };
  if (sigma <= 0.0)
  {
    double ss = 0.0;
    edges.ForEach([&](std::int64_t, std::int64_t a, std::int64_t b) { ss += d2(a, b); });
    sigma = edges.Size() ? std::sqrt(ss / static_cast<double>(edges.Size())) : 1.0;
    sigma = sigma > 0.0 ? sigma : 1.0;
  }
  const double inv2s2 = 1.0 / (2.0 * sigma * sigma);
  std::vector<double> w(edges.Size());
  edges.ForEach([&](std::int64_t e, std::int64_t a, std::int64_t b) {
    const double s = d2(a, b);
    w[e] = (contact.empty() ? 1.0 : contact[e]) * (s == 0.0 ? 1.0 : std::exp(-s * inv2s2));
  });
  return w;
}

// Adds the seeds' geodesic spatial term for L labels to `cost` (nodes x L), each node's share
// weighted by lambda * size; `cache` keeps each label's distances and updates them for its seed edits.
bool AddGeodesicCosts(const GraphEdges& edges, const std::vector<double>& mean, const ChannelBins& bins,
  const SharedArray<double>& step, const std::vector<std::int16_t>& hard, int L, const SeedGeodesicParameters& geo,
  double lambda, const std::vector<double>& size, std::vector<double>& cost, const ParallelFor& parallel,
  const ProgressFunction& progress, MultiLabelCache* cache, SharedArray<double>& added)
{
  const std::int64_t n = static_cast<std::int64_t>(hard.size());
  const int channels = bins.Channels;
  // One value per node: the channels in units of their ranges, summed.
  std::vector<double> value(n, 0.0);
  for (std::int64_t p = 0; p < n; ++p)
  {
    for (int c = 0; c < channels; ++c)
    {
      value[p] += mean[p * channels + c] / (bins.Width[c] * bins.PerChannel);
    }
  }
  GeodesicGraph graph;
  graph.Edges = &edges;
  graph.Value = std::move(value);
  graph.Step = step;
  std::vector<std::uint8_t> kind(n);
  for (std::int64_t p = 0; p < n; ++p)
  {
    kind[p] = static_cast<std::uint8_t>(hard[p] + 1);
  }
  SeedDistanceChanges changes;
  const std::vector<SharedArray<double>> distance = SeedKindDistances(
    graph, kind, L, 1.0, geo.LengthWeight, progress, cache ? &cache->Geodesic : nullptr, parallel, &changes);
  if (distance.empty())
  {
    return false;
  }
  // A node's term is redone only when one of its distances changed since the kept cut's.
  GeodesicTerm* kept = cache ? &cache->Term : nullptr;
  const bool reuse = kept && !changes.All && kept->Labels == L && kept->Weight == geo.Weight &&
    kept->Lambda == lambda && kept->Size == size && static_cast<std::int64_t>(kept->Term.size()) == n * L;
  if (kept && !reuse)
  {
    kept->Labels = L;
    kept->Weight = geo.Weight;
    kept->Lambda = lambda;
    kept->Size = size;
    kept->Term = SharedArray<double>(std::vector<double>(n * L, 0.0));
  }
  std::vector<double> own(kept ? 0 : n * L);
  std::vector<double>& term = kept ? kept->Term.Mutable() : own;
  const double mix = 0.01;
  const auto redo = [&](std::int64_t p) {
    double total = 0.0;
    int zeros = 0;
    for (int l = 0; l < L; ++l)
    {
      const double d = distance[l][p];
      zeros += d == 0.0;
      total += d > 0.0 && std::isfinite(d) ? 1.0 / d : 0.0;
    }
    const double s = lambda * (size.empty() ? 1.0 : size[p]);
    for (int l = 0; l < L; ++l)
    {
      const double d = distance[l][p];
      const double share = zeros ? (d == 0.0 ? 1.0 / zeros : 0.0)
                                 : (total > 0.0 ? (std::isfinite(d) ? 1.0 / d / total : 0.0) : 1.0 / L);
      term[p * L + l] = s * -geo.Weight * std::log(mix + (1.0 - L * mix) * share);
    }
  };
  if (!reuse)
  {
    parallel(n, 16384, [&](std::int64_t p0, std::int64_t p1) {
      for (std::int64_t p = p0; p < p1; ++p)
      {
        redo(p);
      }
    });
  }
  else
  {
    ForEachChangedNode(changes, parallel, redo);
  }
  parallel(n * L, 65536, [&](std::int64_t i0, std::int64_t i1) {
    for (std::int64_t i = i0; i < i1; ++i)
    {
      cost[i] += term[i];
    }
  });
  added = kept ? kept->Term : SharedArray<double>(std::move(own));
  return true;
}

// Adds to samples[label] the bins of the voxels within `radius` of each seed voxel.
void SeedBallSamples(const LabelledSeeds& seeds, const ChannelBins& bins, const ImageGeometry& g, double radius,
  std::vector<std::vector<double>>& samples)
{
  for (std::size_t s = 0; s < seeds.Voxel.size(); ++s)
  {
    ForEachVoxelWithin(g, seeds.Voxel[s], radius, [&](std::int64_t v) { samples[seeds.Label[s]][bins.Bin[v]] += 1.0; });
  }
}

int LabelCount(const LabelledSeeds& seeds)
{
  int top = 0;
  for (std::uint8_t l : seeds.Label)
  {
    top = std::max<int>(top, l);
  }
  return top + 1;
}

std::string CheckSeeds(const LabelledSeeds& seeds)
{
  std::vector<double> labels(seeds.Label.begin(), seeds.Label.end());
  return ValidateSeedLabels(labels);
}

// Each node's region cost of every label (nodes x labels): lambda times the sum over its voxels'
// runs of their bins' costs. A label whose bin costs are those of the kept cut's keeps its column
// (a seed edit changes the densities of the edited labels only).
std::vector<double> RegionCosts(const NodeBinRuns& runs, const std::vector<std::vector<double>>& costs, double lambda,
  std::int64_t n, const ParallelFor& parallel, MultiLabelCache* cache)
{
  const int L = static_cast<int>(costs.size());
  std::vector<double> own;
  const bool keep = cache && cache->RegionLambda == lambda && cache->BinCosts.size() == costs.size() &&
    static_cast<std::int64_t>(cache->Region.size()) == n * L;
  std::vector<int> redo;
  for (int l = 0; l < L; ++l)
  {
    if (!keep || cache->BinCosts[l] != costs[l])
    {
      redo.push_back(l);
    }
  }
  std::vector<double>& region = cache ? cache->Region : own;
  if (!keep)
  {
    region.assign(n * L, 0.0);
  }
  if (!redo.empty())
  {
    parallel(n, 16384, [&](std::int64_t b, std::int64_t e) {
      for (std::int64_t p = b; p < e; ++p)
      {
        for (int l : redo)
        {
          region[p * L + l] = 0.0;
        }
        for (std::int64_t k = runs.Offset[p]; k < runs.Offset[p + 1]; ++k)
        {
          for (int l : redo)
          {
            region[p * L + l] += lambda * runs.Count[k] * costs[l][runs.Bin[k]];
          }
        }
      }
    });
  }
  if (!cache)
  {
    return own;
  }
  cache->BinCosts = costs;
  cache->RegionLambda = lambda;
  return region;
}

// The checks both cuts make first: the seeds' labels, the inputs' sizes, the parameters.
std::string CheckInputs(const LabelledSeeds& seeds, bool sizesMatch, const char* mismatch, const SeededCutParameters& par)
{
  std::string error = CheckSeeds(seeds);
  if (error.empty() && !sizesMatch)
  {
    error = mismatch;
  }
  return error.empty() ? ValidateParameters(par) : error;
}

// What both cuts do once their graph, region costs and hard labels are made: the seeds' geodesic
// term (Task Object), the Potts weights, alpha-expansion from `start` and the connectivity rule.
// `mean` holds the nodes' channel vectors, `size` their voxel counts (empty: 1 each), `step` the
// explicit edges' lengths (empty: the grid), `contact` their contacts (empty: 1 each).
void SolveLabels(PottsProblem& pr, std::vector<std::int16_t> hard, const std::vector<double>& mean, const ChannelBins& bins,
  const SharedArray<double>& step, const std::vector<double>& contact, const std::vector<double>& size,
  const std::vector<std::uint8_t>& border, const SeededCutParameters& par, const MultiLabelParameters& multi,
  std::vector<double> reach, std::vector<std::uint8_t> start, const ParallelFor& parallel,
  const ProgressFunction& progress, MultiLabelCache* cache, Clock::time_point t0, MultiLabelResult& r,
  const ContactsFunction& contactsOf)
{
  const GraphEdges& edges = *pr.Edges;
  r.Error = GraphSizeProblem(pr.Nodes, edges.Size()); // before the geodesic term's 32-bit ids
  if (!r.Error.empty())
  {
    return;
  }
  if (par.Task == Task::Object && par.Geodesic.Weight > 0.0)
  {
    const auto g0 = Clock::now();
    if (!AddGeodesicCosts(edges, mean, bins, step, hard, pr.Labels, par.Geodesic, par.Lambda, size, pr.Cost, parallel,
          SubProgress(progress, 0.0, 0.2), cache, r.Spatial))
    {
      r.Aborted = true;
      return;
    }
    r.GeodesicSeconds = Since(g0);
  }
  if (!reach.empty())
  {
    const int L = pr.Labels;
    parallel(pr.Nodes, 16384, [&](std::int64_t p0, std::int64_t p1) {
      for (std::int64_t p = p0; p < p1; ++p)
      {
        const double s = par.Lambda * (size.empty() ? 1.0 : size[p]);
        for (int l = 1; l < L; ++l)
        {
          pr.Cost[p * L + l] += s * reach[p * (L - 1) + l - 1];
        }
      }
    });
    r.Reach = SharedArray<double>(std::move(reach));
  }
  r.Sigma = par.Sigma;
  if (cache && static_cast<std::int64_t>(cache->Weight.size()) == edges.Size())
  {
    pr.Weight = cache->Weight;
    r.Sigma = cache->Sigma;
  }
  else
  {
    pr.Weight = PottsWeights(edges, mean, bins.Channels, contact, r.Sigma);
    if (cache)
    {
      cache->Weight = pr.Weight;
      cache->Sigma = r.Sigma;
    }
  }
  pr.Hard = hard;
  r.SetupSeconds = Since(t0);
  const auto t1 = Clock::now();
  ExpansionResult x = AlphaExpansion(pr, std::move(start), SubProgress(progress, 0.2, 0.95), multi.MaxCycles,
    cache ? &cache->Moves : nullptr, parallel);
  r.ExpansionSeconds = Since(t1);
  if (!x.Error.empty() || x.Aborted)
  {
    r.Error = x.Error;
    r.Aborted = x.Aborted;
    return;
  }
  if (cache)
  {
    cache->Label = x.Label;
  }
  r.Energy = x.Energy;
  r.Moves = x.Moves;
  r.Cycles = x.Cycles;
  r.Label = std::move(x.Label);
  r.ConnectivityChanged =
    ApplyWithContacts(r.Label, contactsOf, [&](std::vector<std::uint8_t>& label, const GraphEdges& contacts, LabelComponentsOf& components) {
      return ApplyLabelConnectivity(
        ConnectivityFor(par.Connectivity, par.Task), label, edges, pr.Weight, hard, border, contacts, &components);
    });
}
} // namespace

int ChannelBins::Count() const
{
  int c = 1;
  for (int i = 0; i < this->Channels; ++i)
  {
    c *= this->PerChannel;
  }
  return c;
}

int BinsPerChannel(int channels, int bins)
{
  int b = bins > 0 ? bins : 64;
  while (b > 2 && std::pow(static_cast<double>(b), channels) > 4096.0)
  {
    --b;
  }
  return b;
}

template <typename T>
bool BinChannels(const T* values, int channels, std::int64_t voxels, int bins, ChannelBins& out, std::string& error,
  const ParallelFor& parallel)
{
  out = ChannelBins();
  if (channels < 1 || channels > 12 || voxels <= 0)
  {
    error = "the image needs 1 to 12 components and at least one voxel.";
    return false;
  }
  std::int64_t bad = 0;
  for (std::int64_t i = 0; i < voxels * channels; ++i)
  {
    const double v = static_cast<double>(values[i]);
    bad += !(std::isfinite(v) && std::fabs(v) <= 1e150);
  }
  if (bad)
  {
    error = std::to_string(bad) + " image values are NaN, infinite or beyond +-1e150; replace them (e.g. with a Calculator) first.";
    return false;
  }
  out.Channels = channels;
  out.PerChannel = BinsPerChannel(channels, bins);
  for (int c = 0; c < channels; ++c)
  {
    const std::array<double, 2> range = HistogramRange(values, voxels, channels, c);
    out.Low.push_back(range[0]);
    out.High.push_back(range[1]);
    out.Width.push_back((range[1] - range[0]) / out.PerChannel);
  }
  out.Bin.resize(voxels);
  const int per = out.PerChannel;
  parallel(voxels, 65536, [&](std::int64_t b, std::int64_t e) {
    for (std::int64_t v = b; v < e; ++v)
    {
      int index = 0, stride = 1;
      for (int c = 0; c < channels; ++c)
      {
        const double q = (static_cast<double>(values[v * channels + c]) - out.Low[c]) / out.Width[c];
        const int k = q < 1.0 ? 0 : (q >= per - 1 ? per - 1 : static_cast<int>(q));
        index += k * stride;
        stride *= per;
      }
      out.Bin[v] = static_cast<std::uint16_t>(index);
    }
  });
  return true;
}

template <typename T>
void NodeChannelMeans(const std::int32_t* owner, const T* values, int channels, std::int64_t voxels, std::int64_t nodes,
  std::vector<double>& mean, std::vector<double>& count)
{
  mean.assign(nodes * channels, 0.0);
  count.assign(nodes, 0.0);
  for (std::int64_t v = 0; v < voxels; ++v)
  {
    const std::int32_t p = owner[v];
    if (p >= 0)
    {
      count[p] += 1.0;
      for (int c = 0; c < channels; ++c)
      {
        mean[p * channels + c] += static_cast<double>(values[v * channels + c]);
      }
    }
  }
  for (std::int64_t p = 0; p < nodes; ++p)
  {
    for (int c = 0; c < channels && count[p] > 0.0; ++c)
    {
      mean[p * channels + c] /= count[p];
    }
  }
}

template <typename T>
int SeedBinsPerChannel(const T* values, int channels, const ImageGeometry& g, const LabelledSeeds& seeds, double radius,
  int bins, double bandwidth, const ChannelBins* binned)
{
  if (bins > 0 || channels != 1 || seeds.Voxel.empty())
  {
    return BinsPerChannel(channels, bins);
  }
  std::vector<std::vector<double>> samples(LabelCount(seeds));
  for (std::size_t s = 0; s < seeds.Voxel.size(); ++s)
  {
    ForEachVoxelWithin(g, seeds.Voxel[s], radius, [&](std::int64_t v) { samples[seeds.Label[s]].push_back(static_cast<double>(values[v])); });
  }
  // The range the image was binned with, else the same percentiles afresh.
  const std::array<double, 2> range = binned && binned->Channels == 1 && binned->High.size() == 1
    ? std::array<double, 2>{ { binned->Low[0], binned->High[0] } }
    : HistogramRange(values, g.Size());
  std::vector<WeightedSamples> sets;
  for (const std::vector<double>& s : samples)
  {
    sets.push_back({ &s, nullptr });
  }
  return AutomaticBins(sets, range[0], range[1], bandwidth);
}

#define FEATUREMESH_CHANNELS(T)                                                                                          \
  template int SeedBinsPerChannel<T>(                                                                                    \
    const T*, int, const ImageGeometry&, const LabelledSeeds&, double, int, double, const ChannelBins*);                 \
  template bool BinChannels<T>(const T*, int, std::int64_t, int, ChannelBins&, std::string&, const ParallelFor&);       \
  template void NodeChannelMeans<T>(const std::int32_t*, const T*, int, std::int64_t, std::int64_t, std::vector<double>&, \
    std::vector<double>&);
FEATUREMESH_CHANNELS(float)
FEATUREMESH_CHANNELS(double)
FEATUREMESH_CHANNELS(char)
FEATUREMESH_CHANNELS(signed char)
FEATUREMESH_CHANNELS(unsigned char)
FEATUREMESH_CHANNELS(short)
FEATUREMESH_CHANNELS(unsigned short)
FEATUREMESH_CHANNELS(int)
FEATUREMESH_CHANNELS(unsigned int)
FEATUREMESH_CHANNELS(long)
FEATUREMESH_CHANNELS(unsigned long)
FEATUREMESH_CHANNELS(long long)
FEATUREMESH_CHANNELS(unsigned long long)

NodeBinRuns GroupNodeBins(const std::int32_t* owner, const ChannelBins& bins, std::int64_t nodes)
{
  const std::int64_t voxels = static_cast<std::int64_t>(bins.Bin.size());
  std::vector<std::int64_t> start(nodes + 1, 0);
  for (std::int64_t v = 0; v < voxels; ++v)
  {
    if (owner[v] >= 0)
    {
      ++start[owner[v] + 1];
    }
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::uint16_t> sorted(start[nodes]);
  std::vector<std::int64_t> cursor(start.begin(), start.end() - 1);
  for (std::int64_t v = 0; v < voxels; ++v)
  {
    if (owner[v] >= 0)
    {
      sorted[cursor[owner[v]]++] = bins.Bin[v];
    }
  }
  NodeBinRuns runs;
  runs.Offset.assign(nodes + 1, 0);
  for (std::int64_t p = 0; p < nodes; ++p)
  {
    std::sort(sorted.begin() + start[p], sorted.begin() + start[p + 1]);
    for (std::int64_t i = start[p]; i < start[p + 1]; ++i)
    {
      if (i == start[p] || sorted[i] != sorted[i - 1])
      {
        runs.Bin.push_back(sorted[i]);
        runs.Count.push_back(0);
      }
      ++runs.Count.back();
    }
    runs.Offset[p + 1] = static_cast<std::int64_t>(runs.Bin.size());
  }
  return runs;
}

std::vector<std::vector<double>> LabelCosts(const std::vector<std::vector<double>>& counts, const ChannelBins& bins,
  ChannelModel model, double bandwidth)
{
  const int n = bins.Channels, per = bins.PerChannel;
  std::vector<std::vector<double>> cost;
  for (const std::vector<double>& count : counts)
  {
    if (model == ChannelModel::GaussianMixture)
    {
      std::vector<double> points(count.size() * n), reg(n);
      for (std::size_t b = 0; b < count.size(); ++b)
      {
        std::int64_t rest = static_cast<std::int64_t>(b);
        for (int c = 0; c < n; ++c, rest /= per)
        {
          points[b * n + c] = static_cast<double>(rest % per);
        }
      }
      for (int c = 0; c < n; ++c)
      {
        const double h = Bandwidth(count, per, c, n, bandwidth);
        reg[c] = h * h;
      }
      const GaussianMixture mixture = FitGaussianMixture(points, count, n, MixtureComponents, reg);
      cost.push_back(NegativeLog(mixture.Densities(points)));
      continue;
    }
    if (model == ChannelModel::Joint || n == 1)
    {
      std::vector<double> density = count;
      for (int c = 0; c < n; ++c)
      {
        BlurAxis(density, per, n, c, Bandwidth(count, per, c, n, bandwidth));
      }
      cost.push_back(NegativeLog(std::move(density)));
      continue;
    }
    // Independent: one blurred marginal per channel; a bin's cost is the sum of its channels'.
    std::vector<std::vector<double>> marginal(n, std::vector<double>(per, 0.0));
    for (std::size_t b = 0; b < count.size(); ++b)
    {
      std::int64_t rest = static_cast<std::int64_t>(b);
      for (int c = 0; c < n; ++c, rest /= per)
      {
        marginal[c][rest % per] += count[b];
      }
    }
    for (int c = 0; c < n; ++c)
    {
      BlurAxis(marginal[c], per, 1, 0, Bandwidth(marginal[c], per, 0, 1, bandwidth));
      marginal[c] = NegativeLog(std::move(marginal[c]));
    }
    std::vector<double> sum(count.size(), 0.0);
    for (std::size_t b = 0; b < count.size(); ++b)
    {
      std::int64_t rest = static_cast<std::int64_t>(b);
      for (int c = 0; c < n; ++c, rest /= per)
      {
        sum[b] += marginal[c][rest % per];
      }
    }
    cost.push_back(std::move(sum));
  }
  return cost;
}

std::string ValidateSeedLabels(const std::vector<double>& labels)
{
  std::vector<char> seen(256, 0);
  for (double l : labels)
  {
    if (!(l >= 0.0 && l <= 255.0) || l != std::floor(l))
    {
      return "a seed label is " + std::to_string(l) + "; labels are whole numbers from 0 (background) to 255.";
    }
    seen[static_cast<int>(l)] = 1;
  }
  int top = 255;
  while (top > 0 && !seen[top])
  {
    --top;
  }
  if (std::count(seen.begin(), seen.end(), 1) < 2)
  {
    return "the seeds hold one label only; give seeds of the background (0) and of at least one object (1..k).";
  }
  for (int l = 0; l <= top; ++l)
  {
    if (!seen[l])
    {
      return "label " + std::to_string(l) + " has no seed; number the labels 0 (background) to " + std::to_string(top) +
        " without gaps.";
    }
  }
  return std::string();
}

std::int64_t ApplyLabelConnectivity(Connectivity mode, std::vector<std::uint8_t>& label, const GraphEdges& edges,
  const std::vector<double>& weight, const std::vector<std::int16_t>& hard, const std::vector<std::uint8_t>& border,
  const GraphEdges& contacts, LabelComponentsOf* components)
{
  if (mode == Connectivity::Off)
  {
    return 0;
  }
  // The components of equal label once; then whole components are relabelled and joined, over the
  // edges between them.
  const std::int64_t n = static_cast<std::int64_t>(label.size());
  LabelComponentsOf own;
  LabelComponentsOf& given = components ? *components : own;
  KeepLabelComponents(label, edges, given);
  const std::vector<std::int64_t>& edge = given.Between; // (p, q, e) of the edges between labels
  std::int64_t count = 0;
  std::vector<std::int64_t> joinedId;
  const std::vector<std::int64_t>& comp = ComponentIds(label, contacts, given, joinedId, count);
  std::vector<std::int64_t> root(count), size(count, 0);
  std::iota(root.begin(), root.end(), std::int64_t(0));
  std::vector<std::uint8_t> group(count, 0), seeded(count, 0), touches(count, 0);
  for (std::int64_t p = 0; p < n; ++p)
  {
    group[comp[p]] = label[p];
    seeded[comp[p]] |= hard[p] == label[p];
    touches[comp[p]] |= border[p];
    ++size[comp[p]];
  }
  struct Between
  {
    std::int64_t A, B;
    double W;
  };
  // Nodes of different labels lie in different components, and an edge between equal labels joins.
  std::vector<Between> between(edge.size() / 3);
  for (std::size_t i = 0; i < between.size(); ++i)
  {
    const std::int64_t e = edge[3 * i + 2];
    between[i] = { comp[edge[3 * i]], comp[edge[3 * i + 1]], weight.empty() ? 1.0 : weight[e] + 1e-300 };
  }
  const auto find = [&](std::int64_t c) {
    while (root[c] != c)
    {
      c = root[c] = root[root[c]];
    }
    return c;
  };
  std::int64_t changed = 0;
  // A dropped component may border only dropped ones: a second pass takes what the first settled.
  for (int pass = 0; pass < 3; ++pass)
  {
    std::vector<std::uint8_t> drop(count, 0);
    bool any = false;
    for (std::int64_t c = 0; c < count; ++c)
    {
      drop[c] = root[c] == c && !seeded[c] &&
        ((group[c] == 0 && !touches[c]) || (group[c] != 0 && mode == Connectivity::SeededObject));
      any = any || drop[c];
    }
    if (!any)
    {
      break;
    }
    // Per dropped component, the shared weight with each kept neighbouring label.
    std::map<std::pair<std::int64_t, int>, double> shared;
    for (const Between& e : between)
    {
      const std::int64_t ca = find(e.A), cb = find(e.B);
      if (ca == cb)
      {
        continue;
      }
      if (drop[ca] && !drop[cb])
      {
        shared[{ ca, group[cb] }] += e.W;
      }
      if (drop[cb] && !drop[ca])
      {
        shared[{ cb, group[ca] }] += e.W;
      }
    }
    std::vector<int> to(count, -1);
    std::vector<double> best(count, -1.0);
    for (const auto& s : shared)
    {
      if (s.second > best[s.first.first])
      {
        best[s.first.first] = s.second;
        to[s.first.first] = s.first.second;
      }
    }
    std::int64_t moved = 0;
    for (std::int64_t c = 0; c < count; ++c)
    {
      if (drop[c] && to[c] >= 0 && to[c] != group[c])
      {
        group[c] = static_cast<std::uint8_t>(to[c]);
        moved += size[c];
      }
    }
    changed += moved;
    if (!moved)
    {
      break;
    }
    // Components of one label that now touch are one.
    for (const Between& e : between)
    {
      std::int64_t ca = find(e.A), cb = find(e.B);
      if (ca != cb && group[ca] == group[cb])
      {
        if (cb < ca)
        {
          std::swap(ca, cb);
        }
        root[cb] = ca;
        size[ca] += size[cb];
        seeded[ca] |= seeded[cb];
        touches[ca] |= touches[cb];
      }
    }
  }
  for (std::int64_t p = 0; p < n; ++p)
  {
    label[p] = group[find(comp[p])];
  }
  return changed;
}

MultiLabelResult MultiLabelSuperVoxelCut(const SimplexMesh& mesh, const SuperVoxelCutData& data, const ChannelBins& bins,
  const NodeBinRuns& runs, const std::vector<double>& mean, const std::vector<double>& count, const LabelledSeeds& seeds,
  const SuperVoxelCutParameters& par, const MultiLabelParameters& multi, const ParallelFor& parallel,
  const ProgressFunction& progress, MultiLabelCache* cache)
{
  const auto t0 = Clock::now();
  MultiLabelResult r;
  const std::int64_t n = mesh.NumberOfElements();
  r.Error = CheckInputs(seeds,
    static_cast<std::int64_t>(runs.Offset.size()) == n + 1 && static_cast<std::int64_t>(mean.size()) == n * bins.Channels &&
      static_cast<std::int64_t>(count.size()) == n && static_cast<std::int64_t>(data.Owner.size()) == mesh.Geometry().Size(),
    "the voxel owners or channel statistics do not match the mesh.", par);
  if (!r.Error.empty())
  {
    return r;
  }
  const int L = r.Labels = LabelCount(seeds);
  std::vector<std::int16_t> hard;
  if (!LabelConstraints(
        seeds, [&](std::int64_t v) { return static_cast<std::int64_t>(data.Owner[v]); }, n, "element", hard, r.Error))
  {
    return r;
  }
  // Samples: the voxels within SeedRadius of each seed, for the elements and the voxel refinement
  // alike. The seed elements' voxels (the binary cut's SampleSeedElements) gave several labels a
  // worse model (docs/multilabel.md).
  std::vector<std::vector<double>> samples(L, std::vector<double>(bins.Count(), 0.0));
  SeedBallSamples(seeds, bins, mesh.Geometry(), par.SeedRadius, samples);
  std::vector<std::vector<double>> costs = LabelCosts(samples, bins, multi.Channels, par.Bandwidth);
  PottsProblem pr;
  pr.Nodes = n;
  pr.Labels = L;
  const std::shared_ptr<const FaceAdjacency> faces = mesh.SharedFaces();
  const GraphEdges edges(faces->A, faces->B, faces);
  pr.Edges = &edges;
  pr.Cost = RegionCosts(runs, costs, par.Lambda, n, parallel, cache);
  const SharedArray<double> step = MeshCentreSteps(mesh, data);
  std::vector<std::uint8_t> border(n, 0);
  for (std::int64_t e : faces->HullElement)
  {
    border[e] = 1;
  }
  std::vector<std::uint8_t> start;
  if (cache && static_cast<std::int64_t>(cache->Label.size()) == n)
  {
    start = cache->Label;
    for (std::uint8_t& l : start)
    {
      l = l < L ? l : 0;
    }
  }
  // The weights depend on the mesh, the image and these two parameters only: a re-cut keeps them.
  if (cache && (cache->WeightSigma != par.Sigma || cache->WeightContact != par.ScaleByContact))
  {
    cache->Weight.clear();
    cache->WeightSigma = par.Sigma;
    cache->WeightContact = par.ScaleByContact;
  }
  const bool weighted = cache && static_cast<std::int64_t>(cache->Weight.size()) == edges.Size();
  const SharedArray<double> contact = weighted ? SharedArray<double>() : MeshContact(mesh, data, par.ScaleByContact);
  std::vector<double> reach;
  if (par.Task == Task::Object)
  {
    SeedReachCosts(MeshCentres(mesh, data), seeds.Voxel, seeds.Label, L, par.Reach, parallel, reach, &r.ReachDistance);
  }
  SolveLabels(pr, hard, mean, bins, step, contact.Vector(),
    count, border, par, multi, std::move(reach), std::move(start), parallel, progress, cache, t0, r,
    [&](const std::vector<std::int64_t>& elements) { return VoxelContactsOf(mesh, data.Owner, elements); });
  if (!r.Error.empty() || r.Aborted)
  {
    return r;
  }
  r.BinCosts = std::move(costs);
  r.BoundaryFaces = LabelBoundaryFaces(mesh, *faces, r.Label);
  return r;
}

MultiLabelResult MultiLabelVoxelCut(const std::vector<double>& values, const ChannelBins& bins, const ImageGeometry& g,
  const LabelledSeeds& seeds, const VoxelCutParameters& par, const MultiLabelParameters& multi,
  const ProgressFunction& progress, const ParallelFor& parallel)
{
  const auto t0 = Clock::now();
  MultiLabelResult r;
  const std::int64_t n = g.Size();
  r.Error = CheckInputs(seeds,
    static_cast<std::int64_t>(bins.Bin.size()) == n && static_cast<std::int64_t>(values.size()) == n * bins.Channels,
    "the channel values do not match the image.", par);
  if (!r.Error.empty())
  {
    return r;
  }
  const int L = r.Labels = LabelCount(seeds);
  std::vector<std::int16_t> hard;
  if (!LabelConstraints(seeds, [](std::int64_t v) { return v; }, n, "voxel", hard, r.Error))
  {
    return r;
  }
  std::vector<std::vector<double>> samples(L, std::vector<double>(bins.Count(), 0.0));
  SeedBallSamples(seeds, bins, g, par.SeedRadius, samples);
  const std::vector<std::vector<double>> costs = LabelCosts(samples, bins, multi.Channels, par.Bandwidth);
  PottsProblem pr;
  pr.Nodes = n;
  pr.Labels = L;
  const GraphEdges edges = GraphEdges::Grid(g.Dims[0], g.Dims[1], g.Dims[2]);
  pr.Edges = &edges;
  pr.Cost.resize(n * L);
  for (std::int64_t v = 0; v < n; ++v)
  {
    for (int l = 0; l < L; ++l)
    {
      pr.Cost[v * L + l] = par.Lambda * costs[l][bins.Bin[v]];
    }
  }
  std::vector<double> reach;
  if (par.Task == Task::Object)
  {
    SeedReachCosts(VoxelCentres(g), seeds.Voxel, seeds.Label, L, par.Reach, parallel, reach, &r.ReachDistance);
  }
  SolveLabels(pr, hard, values, bins, {}, {}, {}, BorderVoxels(g), par, multi, std::move(reach), {}, parallel, progress,
    nullptr, t0, r, nullptr);
  return r;
}
} // namespace featuremesh
