// Stage 4 with k objects: labelled seeds (0 background, 1..k objects) on an image of one or more
// channels, segmented by alpha-expansion (AlphaExpansion.h) of the binary cut's energy with a Potts
// boundary term, on the mesh's elements (super-voxel) or on the voxel grid (voxel cut):
//
//   E(L) = lambda * sum_p sum_{v in p} -ln Pr(x_v | L_p) + sum_pq contact_pq exp(-|m_p - m_q|^2 / 2 sigma^2) [L_p != L_q]
//
// x_v is a voxel's vector of channels and m_p a node's mean vector; sigma is the root mean square
// of |m_p - m_q| over the graph's edges (automatic) as in the binary cut. Pr(x | l) is a density of
// label l's seed samples on a grid of bins over the channels' 0.5-99.5 percentile ranges: joint
// (a kernel density on the n-dimensional grid) or independent (the product of one per channel),
// or a Gaussian mixture (ChannelModel), mixed with 1 % uniform. For Task Object each label also pays the seeds' geodesic spatial term
// (SeedGeodesics.h) generalised to k + 1 labels: Pr(l) = (1 / D_l) / sum_j (1 / D_j).
#pragma once

#include "AlphaExpansion.h"
#include "ElementRasterizer.h"
#include "SeedGeodesics.h"
#include "SuperVoxelCut.h"

#include <cstdint>
#include <string>
#include <vector>

namespace featuremesh
{
enum class ChannelModel : int
{
  // One density over all channels together: labels told apart by how the channels co-vary.
  Joint = 0,
  // The product of one density per channel (naive Bayes).
  Independent = 1,
  // A Gaussian mixture over all channels, fitted to the seed samples by EM (GaussianMixture.h): a
  // smooth, parametric density where a label's samples are multimodal (a stomach's wall and content).
  GaussianMixture = 2,
};

// Seeds with labels: the voxel each lies in and its label (0 background, 1..255 objects).
struct LabelledSeeds
{
  std::vector<std::int64_t> Voxel;
  std::vector<std::uint8_t> Label;
};

struct MultiLabelParameters
{
  // Independent: with a few seeds per label it beat the joint density on the two-channel brain
  // tumour cases (docs/multilabel.md).
  ChannelModel Channels = ChannelModel::Independent;
  // Most cycles over the labels.
  int MaxCycles = 8;
};

// Every voxel's bin on a grid of PerChannel bins per channel (the joint index, channel 0 fastest)
// over each channel's 0.5-99.5 percentile range, clamped at the ends.
struct ChannelBins
{
  int Channels = 0, PerChannel = 0;
  std::vector<double> Low, High, Width;
  std::vector<std::uint16_t> Bin;
  int Count() const;
};

// Bins per channel for `channels` channels: `bins` (> 0) or 64, capped so the grid holds at most
// 4096 bins (2 channels: 64 each; 3: 16).
int BinsPerChannel(int channels, int bins);

// Bins per channel for labelled seeds: BinsPerChannel(channels, bins), except with automatic bins
// (0) on one channel: AutomaticBins (BoykovJolly.h) of each label's samples on the channel's
// 0.5-99.5 percentile range (`binned`'s, when it binned this image). The samples are the voxels
// within `radius` of each seed, as both cuts sample them.
template <typename T>
int SeedBinsPerChannel(const T* values, int channels, const ImageGeometry& geometry, const LabelledSeeds& seeds,
  double radius, int bins, double bandwidth, const ChannelBins* binned = nullptr);

// `values` (voxels x channels, interleaved, any arithmetic type) binned into `out`; false with a
// sentence for a value that is not finite or beyond +-1e150.
template <typename T>
bool BinChannels(const T* values, int channels, std::int64_t voxels, int bins, ChannelBins& out, std::string& error,
  const ParallelFor& parallel);

// Each node's mean of every channel (nodes x channels; 0 for a node without voxels) and its voxel count.
template <typename T>
void NodeChannelMeans(const std::int32_t* owner, const T* values, int channels, std::int64_t voxels, std::int64_t nodes,
  std::vector<double>& mean, std::vector<double>& count);

// Each node's voxels as runs of one joint bin: node p's at [Offset[p], Offset[p + 1]).
struct NodeBinRuns
{
  std::vector<std::int64_t> Offset;
  std::vector<std::uint16_t> Bin;
  std::vector<std::uint32_t> Count;
};
NodeBinRuns GroupNodeBins(const std::int32_t* owner, const ChannelBins& bins, std::int64_t nodes);

// -ln Pr(bin | l) of each label from its samples' bin counts (Labels x Count()).
std::vector<std::vector<double>> LabelCosts(const std::vector<std::vector<double>>& counts, const ChannelBins& bins,
  ChannelModel model, double bandwidth);

struct MultiLabelResult
{
  std::vector<std::uint8_t> Label;
  int Labels = 0; // k + 1
  double Energy = 0.0, Sigma = 0.0;
  int Moves = 0, Cycles = 0;
  double SetupSeconds = 0.0, ExpansionSeconds = 0.0, GeodesicSeconds = 0.0;
  std::int64_t ConnectivityChanged = 0;
  std::vector<std::int64_t> BoundaryFaces; // super-voxel cut: faces between labels and labels' hull faces
  // The voxel refinement's terms (super-voxel cut): each label's -ln Pr per joint bin (the cut's
  // own, from the voxels within SeedRadius of its seeds), and each node's spatial term per label
  // as the expansion paid it (nodes x labels, lambda x size x the term per voxel; empty without one).
  std::vector<std::vector<double>> BinCosts;
  SharedArray<double> Spatial;
  // The seeds' reach per voxel of each node (nodes x (labels - 1): the object labels; before
  // lambda; empty without one).
  SharedArray<double> Reach;
  // R of each label's reach, world units (label 0 and labels without the term: 0).
  std::vector<double> ReachDistance;
  std::string Error;
  bool Aborted = false;
};

// The seeds' spatial term of the last cut per node and label (nodes x labels), with the label
// count, weight, lambda and node sizes it was made from; the geodesic cache beside it names the
// nodes whose distances changed since.
struct GeodesicTerm
{
  SharedArray<double> Term;
  std::vector<double> Size;
  double Weight = 0.0, Lambda = 0.0;
  int Labels = 0;
};

// What a multi-label cut of one graph keeps for the next: the last labelling (the next cut starts
// from it), its seeds' geodesic distances per label (updated, not redone, after a seed edit) and
// each label's move graph with its flow.
struct MultiLabelCache
{
  std::vector<std::uint8_t> Label;
  SeedGeodesicCache Geodesic;
  GeodesicTerm Term;
  RecycledMoves Moves;
  // The Potts weights, for the Sigma and ScaleByContact they were made with, and the sigma used.
  std::vector<double> Weight;
  double WeightSigma = -1.0, Sigma = 0.0;
  bool WeightContact = false;
  // Each label's bin costs and the nodes' region costs made from them, at RegionLambda.
  std::vector<std::vector<double>> BinCosts;
  std::vector<double> Region;
  double RegionLambda = 0.0;
  void Clear()
  {
    this->Label.clear();
    this->BinCosts.clear();
    this->Region.clear();
    this->Geodesic.Clear();
    this->Term = GeodesicTerm();
    this->Moves.Clear();
    this->Weight.clear();
  }
};

// The super-voxel cut with labelled seeds: `runs` and `mean` (elements x channels) from the image's
// channels, `count` the elements' voxel counts. A seed's element takes its label (two labels in one
// element are an error); the histograms sample the voxels within SeedRadius of each seed.
MultiLabelResult MultiLabelSuperVoxelCut(const SimplexMesh& mesh, const SuperVoxelCutData& data, const ChannelBins& bins,
  const NodeBinRuns& runs, const std::vector<double>& mean, const std::vector<double>& count, const LabelledSeeds& seeds,
  const SuperVoxelCutParameters& parameters, const MultiLabelParameters& multi, const ParallelFor& parallel,
  const ProgressFunction& progress = NoProgress(), MultiLabelCache* cache = nullptr);

// The voxel cut with labelled seeds; `values` (voxels x channels) as doubles; the histograms sample
// the voxels within SeedRadius of each seed.
MultiLabelResult MultiLabelVoxelCut(const std::vector<double>& values, const ChannelBins& bins,
  const ImageGeometry& geometry, const LabelledSeeds& seeds, const VoxelCutParameters& parameters,
  const MultiLabelParameters& multi, const ProgressFunction& progress = NoProgress(),
  const ParallelFor& parallel = SerialFor());

// The connectivity rule per label, in place: with Seeded Object a component of an object label that
// holds none of that label's seeds, and with either rule a background component that holds no
// background seed and touches no border, takes the label it shares most edge weight with. Returns
// the nodes relabelled. `contacts` (optional) join components of equal label besides the edges, and
// `components` (optional) keeps `label`'s as given (ApplyConnectivity).
std::int64_t ApplyLabelConnectivity(Connectivity mode, std::vector<std::uint8_t>& label, const GraphEdges& edges,
  const std::vector<double>& weight, const std::vector<std::int16_t>& hard, const std::vector<std::uint8_t>& border,
  const GraphEdges& contacts = GraphEdges(), LabelComponentsOf* components = nullptr);

// Empty when usable, else a sentence: labels beyond 255 or negative, fewer than two labels, a label
// with no seed among 0..max.
std::string ValidateSeedLabels(const std::vector<double>& labels);
} // namespace featuremesh
