// Multi-label cuts: alpha-expansion, labelled seeds, several channels (MultiLabelCut.h).
#include "AlphaExpansion.h"
#include "DelaunayImageMesh.h"
#include "ElementRasterizer.h"
#include "GaussianMixture.h"
#include "MultiLabelCut.h"
#include "SimplexMesh.h"
#include "SeedGeodesics.h"
#include "SegmentationSurfaceSmoothing.h"
#include "TestHelpers.h"

#include <gtest/gtest.h>

#include <chrono>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <thread>

using namespace featuremesh;

namespace
{
ImageGeometry Grid(int nx, int ny)
{
  ImageGeometry g;
  g.Dims = { { nx, ny, 1 } };
  return g;
}

// Reverse-ordered small chunks on two threads: any split of the loops.
const ParallelFor TwoThreads = [](std::int64_t n, std::int64_t, const RangeFunction& body) {
  std::thread t([&] {
    for (std::int64_t b = 0; b < n / 2; b += 5)
      body(b, std::min(n / 2, b + 5));
  });
  for (std::int64_t b = n / 2; b < n; b += 7)
    body(b, std::min(n, b + 7));
  t.join();
};

// An image of `channels` interleaved channels on a 2D grid; value(i, j, c).
template <typename F>
std::vector<float> Image(const ImageGeometry& g, int channels, F value)
{
  std::vector<float> v(g.Size() * channels);
  for (int j = 0; j < g.Dims[1]; ++j)
    for (int i = 0; i < g.Dims[0]; ++i)
      for (int c = 0; c < channels; ++c)
        v[g.Index(i, j, 0) * channels + c] = value(i, j, c);
  return v;
}

// The mesh of a 2-pixel lattice (and the last row and column), with everything a cut needs.
struct Lattice
{
  SimplexMesh Mesh;
  SuperVoxelCutData Data;
  ChannelBins Bins;
  NodeBinRuns Runs;
  std::vector<double> Mean, Count;
  bool Make(const ImageGeometry& g, const std::vector<float>& image, int channels)
  {
    std::vector<std::array<double, 3>> pts = featuremesh_test::LatticeNodes(g);
    std::sort(pts.begin(), pts.end());
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    const DelaunayResult d = Triangulate2D(pts);
    if (!d.Error.empty())
      return false;
    this->Mesh = SimplexMesh(g, d.Points, d.Cells, d.VerticesPerCell);
    this->Mesh.OrientPositively();
    std::string error;
    if (!PrepareVoxelOwners(this->Mesh, this->Data, SerialFor()) ||
      !BinChannels(image.data(), channels, g.Size(), 0, this->Bins, error, SerialFor()))
      return false;
    NodeChannelMeans(this->Data.Owner.data(), image.data(), channels, g.Size(), this->Mesh.NumberOfElements(), this->Mean, this->Count);
    this->Runs = GroupNodeBins(this->Data.Owner.data(), this->Bins, this->Mesh.NumberOfElements());
    return true;
  }
  // The labels on the pixel grid.
  std::vector<std::uint8_t> Cut(const LabelledSeeds& seeds, const SuperVoxelCutParameters& par,
    const MultiLabelParameters& multi = MultiLabelParameters(), const ParallelFor& parallel = SerialFor(),
    MultiLabelResult* out = nullptr)
  {
    const MultiLabelResult r = MultiLabelSuperVoxelCut(this->Mesh, this->Data, this->Bins, this->Runs, this->Mean, this->Count,
      seeds, par, multi, parallel);
    EXPECT_TRUE(r.Error.empty()) << r.Error;
    std::vector<std::uint8_t> pixels(this->Mesh.Geometry().Size(), 0);
    if (r.Error.empty())
      VoxelLabels(this->Data.Owner, r.Label, pixels.data(), SerialFor());
    if (out)
      *out = r;
    return pixels;
  }
};

std::vector<std::uint8_t> VoxelCutLabels(const ImageGeometry& g, const std::vector<float>& image, int channels,
  const LabelledSeeds& seeds, const VoxelCutParameters& par, const MultiLabelParameters& multi = MultiLabelParameters())
{
  ChannelBins bins;
  std::string error;
  EXPECT_TRUE(BinChannels(image.data(), channels, g.Size(), 0, bins, error, SerialFor())) << error;
  const MultiLabelResult r = MultiLabelVoxelCut(std::vector<double>(image.begin(), image.end()), bins, g, seeds, par, multi);
  EXPECT_TRUE(r.Error.empty()) << r.Error;
  return r.Label;
}

// Three vertical plateaus 10 / 50 / 90 with noise, labels 0 / 1 / 2, seeds in each.
struct Plateaus
{
  ImageGeometry G = Grid(60, 40);
  std::vector<float> Image;
  LabelledSeeds Seeds;
  static int Truth(int i) { return i < 20 ? 0 : (i < 40 ? 1 : 2); }
  Plateaus()
  {
    std::mt19937 rng(3);
    std::normal_distribution<float> noise(0.f, 6.f);
    this->Image = ::Image(this->G, 1, [&](int i, int, int) { return 10.f + 40.f * Truth(i) + noise(rng); });
    for (int l = 0; l < 3; ++l)
      for (int j : { 8, 20, 32 })
      {
        this->Seeds.Voxel.push_back(this->G.Index(10 + 20 * l, j, 0));
        this->Seeds.Label.push_back(static_cast<std::uint8_t>(l));
      }
  }
  double Correct(const std::vector<std::uint8_t>& label) const
  {
    std::int64_t right = 0;
    for (int j = 0; j < this->G.Dims[1]; ++j)
      for (int i = 0; i < this->G.Dims[0]; ++i)
        right += label[this->G.Index(i, j, 0)] == Truth(i);
    return static_cast<double>(right) / this->G.Size();
  }
};
// `tries` random node pairs among `nodes`, self-loops left out: an irregular graph's edges.
struct RandomPairs
{
  std::vector<std::int64_t> A, B;
  RandomPairs(std::mt19937& rng, std::int64_t nodes, int tries)
  {
    for (int e = 0; e < tries; ++e)
    {
      const std::int64_t p = rng() % nodes, q = rng() % nodes;
      if (p != q)
      {
        this->A.push_back(p);
        this->B.push_back(q);
      }
    }
  }
};
} // namespace

TEST(AlphaExpansion, TwoLabelsReachTheGlobalMinimumAndThreeStayWithinTwice)
{
  // Brute force over every labelling of a 3 x 3 grid: two labels, one expansion move is the exact
  // binary cut; three labels, the expansion's bound (factor 2 for Potts).
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const GraphEdges edges = GraphEdges::Grid(3, 3, 1);
  for (int labels : { 2, 3 })
    for (int trial = 0; trial < 20; ++trial)
    {
      PottsProblem pr;
      pr.Nodes = 9;
      pr.Labels = labels;
      pr.Edges = &edges;
      for (std::int64_t e = 0; e < edges.Size(); ++e)
        pr.Weight.push_back(u(rng));
      for (int i = 0; i < 9 * labels; ++i)
        pr.Cost.push_back(2.0 * u(rng));
      double best = 1e300;
      std::vector<std::uint8_t> l(9, 0);
      int total = 1;
      for (int i = 0; i < 9; ++i)
        total *= labels;
      for (int code = 0; code < total; ++code)
      {
        for (int i = 0, c = code; i < 9; ++i, c /= labels)
          l[i] = static_cast<std::uint8_t>(c % labels);
        best = std::min(best, PottsEnergy(pr, l));
      }
      const ExpansionResult r = AlphaExpansion(pr, {});
      ASSERT_TRUE(r.Error.empty()) << r.Error;
      EXPECT_NEAR(r.Energy, PottsEnergy(pr, r.Label), 1e-9);
      if (labels == 2)
        EXPECT_NEAR(r.Energy, best, 1e-9) << "trial " << trial;
      else
        EXPECT_LE(r.Energy, 2.0 * best + 1e-9) << "trial " << trial;
      // Each move is an exact optimum: no expansion of the result lowers its energy.
      for (int alpha = 0; alpha < labels; ++alpha)
        for (int subset = 0; subset < 512; ++subset)
        {
          std::vector<std::uint8_t> moved = r.Label;
          for (int i = 0; i < 9; ++i)
            if (subset >> i & 1)
              moved[i] = static_cast<std::uint8_t>(alpha);
          EXPECT_GE(PottsEnergy(pr, moved), r.Energy - 1e-9) << "trial " << trial << " alpha " << alpha;
        }
    }
}

TEST(AlphaExpansion, HardLabelsHold)
{
  // Costs pull every node to label 0; the hard nodes keep 1 and 2.
  const GraphEdges edges = GraphEdges::Grid(5, 5, 1);
  PottsProblem pr;
  pr.Nodes = 25;
  pr.Labels = 3;
  pr.Edges = &edges;
  pr.Weight.assign(edges.Size(), 1.0);
  for (int p = 0; p < 25; ++p)
    pr.Cost.insert(pr.Cost.end(), { 0.0, 5.0, 5.0 });
  pr.Hard.assign(25, -1);
  pr.Hard[6] = 1;
  pr.Hard[18] = 2;
  const ExpansionResult r = AlphaExpansion(pr, {});
  ASSERT_TRUE(r.Error.empty());
  EXPECT_EQ(r.Label[6], 1);
  EXPECT_EQ(r.Label[18], 2);
  EXPECT_EQ(std::count(r.Label.begin(), r.Label.end(), 0), 23);
}

TEST(AlphaExpansion, RecycledMovesEqualFreshMoves)
{
  // A re-cut's edits on a grid and on a random graph: costs of one label everywhere, of every label
  // on a few nodes, hard labels set and cleared, then the weights changed (the kept graphs start
  // afresh), and an expansion aborted half way. Each time the recycled expansion, from the kept
  // graphs, gives the fresh one's labels (random real costs: no move has tied cuts).
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const RandomPairs pairs(rng, 400, 1500);
  const GraphEdges grid = GraphEdges::Grid(20, 20, 1), random(pairs.A, pairs.B);
  for (const GraphEdges* edges : { &grid, &random })
    for (int labels : { 3, 5 })
    {
      PottsProblem pr;
      pr.Nodes = 400;
      pr.Labels = labels;
      pr.Edges = edges;
      for (std::int64_t e = 0; e < edges->Size(); ++e)
        pr.Weight.push_back(0.5 + u(rng));
      for (int i = 0; i < 400 * labels; ++i)
        pr.Cost.push_back(3.0 * u(rng));
      pr.Hard.assign(400, -1);
      RecycledMoves recycled;
      std::vector<std::uint8_t> start;
      for (int edit = 0; edit < 8; ++edit)
      {
        if (edit == 6)
        {
          // Aborted after two moves: the kept graphs stay usable.
          int calls = 0;
          const ExpansionResult stopped =
            AlphaExpansion(pr, start, [&](double) { return ++calls <= 2; }, 8, &recycled);
          EXPECT_TRUE(stopped.Aborted);
        }
        const ExpansionResult kept = AlphaExpansion(pr, start, NoProgress(), 8, &recycled);
        const ExpansionResult fresh = AlphaExpansion(pr, start, NoProgress(), 8);
        ASSERT_TRUE(kept.Error.empty() && fresh.Error.empty()) << kept.Error << fresh.Error;
        EXPECT_EQ(kept.Label, fresh.Label) << "edit " << edit << ", " << labels << " labels";
        EXPECT_NEAR(kept.Energy, fresh.Energy, 1e-9 * std::fabs(fresh.Energy));
        EXPECT_EQ(kept.Moves, fresh.Moves);
        start = kept.Label;
        const int l = static_cast<int>(rng() % labels);
        for (int p = 0; p < 400; ++p)
          pr.Cost[p * labels + l] *= 0.8 + 0.4 * u(rng);
        for (int i = 0; i < 20; ++i)
          pr.Cost[(rng() % 400) * labels + rng() % labels] = 3.0 * u(rng);
        pr.Hard[rng() % 400] = static_cast<std::int16_t>(rng() % labels);
        pr.Hard[rng() % 400] = -1;
        if (edit == 4)
          for (double& w : pr.Weight)
            w *= 0.5 + u(rng);
      }
    }
}

TEST(AlphaExpansion, AWorkspaceLentAcrossProblemsChangesNothing)
{
  // One workspace lent to expansions of different graphs, sizes and label counts (larger, then
  // smaller, then larger again, as the voxel refinement's bands come): each gives a fresh
  // expansion's labels and energy.
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const RandomPairs pairs(rng, 400, 1500);
  const GraphEdges small = GraphEdges::Grid(20, 20, 1), random(pairs.A, pairs.B), large = GraphEdges::Grid(40, 30, 1);
  ExpansionWorkspace workspace;
  int runs = 0;
  for (const GraphEdges* edges : { &large, &small, &random, &large })
    for (int labels : { 4, 3 })
    {
      PottsProblem pr;
      pr.Nodes = edges == &large ? 1200 : 400;
      pr.Labels = labels;
      pr.Edges = edges;
      for (std::int64_t e = 0; e < edges->Size(); ++e)
        pr.Weight.push_back(0.5 + u(rng));
      for (std::int64_t i = 0; i < pr.Nodes * labels; ++i)
        pr.Cost.push_back(3.0 * u(rng));
      // Every problem under a key of its own, each run twice: the second keeps the first's rows.
      workspace.GraphKey = static_cast<std::uint64_t>(runs + 1);
      const ExpansionResult lent = AlphaExpansion(pr, {}, NoProgress(), 8, nullptr, SerialFor(), &workspace);
      const ExpansionResult again = AlphaExpansion(pr, {}, NoProgress(), 8, nullptr, SerialFor(), &workspace);
      const ExpansionResult fresh = AlphaExpansion(pr, {});
      ASSERT_TRUE(lent.Error.empty() && fresh.Error.empty()) << lent.Error << fresh.Error;
      EXPECT_EQ(lent.Label, fresh.Label) << "run " << runs;
      EXPECT_EQ(lent.Energy, fresh.Energy) << "run " << runs;
      EXPECT_EQ(again.Label, fresh.Label) << "run " << runs;
      EXPECT_EQ(again.Energy, fresh.Energy) << "run " << runs;
      EXPECT_GT(fresh.Moves, 0);
      ++runs;
    }
  EXPECT_TRUE(workspace.Kept != nullptr);
}

TEST(AlphaExpansion, EdgesInAnyOrderGiveTheSameMoves)
{
  // Edges in ascending order of their first ends (a voxel band's faces) build each move from the
  // free nodes' rows; the same edges reversed, from the whole list. The labels and energies agree.
  std::mt19937 rng(37);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const GraphEdges grid = GraphEdges::Grid(30, 20, 1);
  std::vector<std::int64_t> a, b;
  grid.ForEach([&](std::int64_t, std::int64_t p, std::int64_t q) {
    a.push_back(p);
    b.push_back(q);
  });
  const GraphEdges ascending(a, b);
  std::vector<std::int64_t> ra(a.rbegin(), a.rend()), rb(b.rbegin(), b.rend());
  const GraphEdges reversed(ra, rb);
  for (int labels : { 3, 4 })
  {
    PottsProblem pr;
    pr.Nodes = 600;
    pr.Labels = labels;
    for (std::int64_t e = 0; e < grid.Size(); ++e)
      pr.Weight.push_back(e % 7 == 0 ? 0.0 : 0.5 + u(rng)); // some zero weights, skipped either way
    for (std::int64_t i = 0; i < pr.Nodes * labels; ++i)
      pr.Cost.push_back(3.0 * u(rng));
    pr.Hard.assign(pr.Nodes, -1);
    for (int k = 0; k < 30; ++k)
      pr.Hard[rng() % pr.Nodes] = static_cast<std::int16_t>(rng() % labels);
    pr.Edges = &ascending;
    const ExpansionResult rows = AlphaExpansion(pr, {});
    PottsProblem back = pr;
    back.Edges = &reversed;
    back.Weight.assign(pr.Weight.rbegin(), pr.Weight.rend());
    const ExpansionResult list = AlphaExpansion(back, {});
    ASSERT_TRUE(rows.Error.empty() && list.Error.empty()) << rows.Error << list.Error;
    EXPECT_GT(rows.Moves, 1);
    EXPECT_EQ(rows.Label, list.Label) << labels << " labels";
    EXPECT_NEAR(rows.Energy, list.Energy, 1e-9 * std::fabs(list.Energy));
    EXPECT_EQ(rows.Moves, list.Moves);
  }
}

TEST(AlphaExpansion, BadProblemsAreErrors)
{
  const GraphEdges edges = GraphEdges::Grid(2, 2, 1);
  PottsProblem pr;
  pr.Nodes = 4;
  pr.Labels = 2;
  pr.Edges = &edges;
  pr.Weight.assign(edges.Size(), 1.0);
  pr.Cost.assign(8, 0.0);
  pr.Cost[3] = std::nan("");
  EXPECT_FALSE(AlphaExpansion(pr, {}).Error.empty());
  pr.Cost[3] = 0.0;
  pr.Weight[0] = -1.0;
  EXPECT_FALSE(AlphaExpansion(pr, {}).Error.empty());
  pr.Weight[0] = 1.0;
  pr.Hard = { -1, 2, -1, -1 };
  EXPECT_FALSE(AlphaExpansion(pr, {}).Error.empty());
  pr.Labels = 1;
  EXPECT_FALSE(AlphaExpansion(pr, {}).Error.empty());
  // The checks share their passes with the start's energy: an edge to a node beyond the graph and a
  // cost beyond the bound are errors, not reads out of range or an overflow.
  const GraphEdges beyond = GraphEdges::Owned({ 0, 1, 2 }, { 1, 7, 3 });
  PottsProblem far;
  far.Nodes = 4;
  far.Labels = 2;
  far.Edges = &beyond;
  far.Weight.assign(3, 1.0);
  far.Cost.assign(8, 0.0);
  EXPECT_NE(AlphaExpansion(far, { 0, 1, 0, 1 }).Error.find("outside the graph"), std::string::npos);
  far.Edges = &edges;
  far.Weight.assign(edges.Size(), 1.0);
  far.Cost[5] = 1e200;
  EXPECT_NE(AlphaExpansion(far, {}).Error.find("not finite"), std::string::npos);
}

TEST(MultiLabel, ThreePlateausAreTheLabelsOnVoxelsAndElements)
{
  const Plateaus p;
  Lattice m;
  ASSERT_TRUE(m.Make(p.G, p.Image, 1));
  VoxelCutParameters vp;
  SuperVoxelCutParameters sp;
  for (Task task : { Task::Object, Task::Class })
  {
    vp.Task = sp.Task = task;
    const std::vector<std::uint8_t> voxel = VoxelCutLabels(p.G, p.Image, 1, p.Seeds, vp);
    const std::vector<std::uint8_t> super = m.Cut(p.Seeds, sp);
    EXPECT_GT(p.Correct(voxel), 0.99);
    // Elements of the 2-pixel lattice straddle each plateau edge by a pixel.
    EXPECT_GT(p.Correct(super), 0.97);
    for (std::size_t s = 0; s < p.Seeds.Voxel.size(); ++s)
    {
      EXPECT_EQ(voxel[p.Seeds.Voxel[s]], p.Seeds.Label[s]);
      EXPECT_EQ(super[p.Seeds.Voxel[s]], p.Seeds.Label[s]);
    }
  }
}

TEST(MultiLabel, TheSeedReachStopsALeakAlongABridge)
{
  // Label 1's disk is joined by a bright bridge to a look-alike disk far away; label 2 is a dimmer
  // disk, and background seeds ring label 1's. Without the reach term both cuts give the far disk
  // to label 1 (its appearance, no edge along the bridge, one piece with the seeded disk); with it
  // (default) the far disk is background, and the seeded disks keep their labels.
  const ImageGeometry g = Grid(96, 32);
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.f, 3.f);
  const std::vector<float> image = Image(g, 1, [&](int i, int j, int) {
    if (std::hypot(i - 14, j - 16) <= 7 || std::hypot(i - 80, j - 16) <= 7 || (std::abs(j - 16) <= 2 && i > 14 && i < 80))
      return 100.f + noise(rng);
    return (std::hypot(i - 46, j - 6) <= 5 ? 60.f : 20.f) + noise(rng);
  });
  LabelledSeeds seeds;
  for (auto [i, j] : { std::pair<int, int>{ 14, 16 }, { 11, 14 }, { 16, 19 } })
  {
    seeds.Voxel.push_back(g.Index(i, j, 0));
    seeds.Label.push_back(1);
  }
  seeds.Voxel.push_back(g.Index(46, 6, 0));
  seeds.Label.push_back(2);
  for (double a : { 0.8, 1.57, 2.36, 3.14, 3.93, 4.71, 5.5 })
  {
    seeds.Voxel.push_back(g.Index(int(14 + 11 * std::cos(a)), int(16 + 11 * std::sin(a)), 0));
    seeds.Label.push_back(0);
  }
  Lattice m;
  ASSERT_TRUE(m.Make(g, image, 1));
  for (double weight : { 0.0, SeedReachParameters().Weight })
  {
    VoxelCutParameters vp;
    vp.Reach.Weight = weight;
    SuperVoxelCutParameters sp;
    sp.Reach.Weight = weight;
    const std::vector<std::uint8_t> voxel = VoxelCutLabels(g, image, 1, seeds, vp);
    const std::vector<std::uint8_t> super = m.Cut(seeds, sp);
    for (const auto* label : { &voxel, &super })
    {
      const char* what = label == &super ? "elements" : "voxels";
      EXPECT_EQ((*label)[g.Index(14, 16, 0)], 1) << what << ", reach weight " << weight;
      EXPECT_EQ((*label)[g.Index(46, 6, 0)], 2) << what << ", reach weight " << weight;
      EXPECT_EQ((*label)[g.Index(80, 16, 0)], weight > 0 ? 0 : 1) << what << ", reach weight " << weight;
    }
  }
}

TEST(MultiLabel, TheSameLabelsOnAnyThreads)
{
  const Plateaus p;
  Lattice m;
  ASSERT_TRUE(m.Make(p.G, p.Image, 1));
  const SuperVoxelCutParameters sp;
  MultiLabelResult serial, threaded;
  m.Cut(p.Seeds, sp, MultiLabelParameters(), SerialFor(), &serial);
  m.Cut(p.Seeds, sp, MultiLabelParameters(), TwoThreads, &threaded);
  EXPECT_EQ(serial.Label, threaded.Label);
  EXPECT_EQ(serial.Energy, threaded.Energy);
}

TEST(MultiLabel, TheSecondChannelTellsTheLabelsApart)
{
  // Channel 0 is the same noise everywhere; channel 1 tells three bands apart. With both channels
  // (either model) the labels are the bands; with channel 0 alone they cannot be.
  const ImageGeometry g = Grid(60, 40);
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.f, 5.f);
  const std::vector<float> two = Image(g, 2, [&](int i, int, int c) {
    return c == 0 ? 50.f + noise(rng) : 10.f + 40.f * Plateaus::Truth(i) + noise(rng);
  });
  std::vector<float> first(g.Size());
  for (std::int64_t v = 0; v < g.Size(); ++v)
    first[v] = two[2 * v];
  const Plateaus p;
  VoxelCutParameters vp;
  vp.Task = Task::Class; // appearance and boundary alone
  SuperVoxelCutParameters sp;
  sp.Task = Task::Class;
  for (ChannelModel model : { ChannelModel::Joint, ChannelModel::Independent, ChannelModel::GaussianMixture })
  {
    MultiLabelParameters multi;
    multi.Channels = model;
    EXPECT_GT(p.Correct(VoxelCutLabels(g, two, 2, p.Seeds, vp, multi)), 0.98);
    Lattice m;
    ASSERT_TRUE(m.Make(g, two, 2));
    EXPECT_GT(p.Correct(m.Cut(p.Seeds, sp, multi)), 0.95);
  }
  EXPECT_LT(p.Correct(VoxelCutLabels(g, first, 1, p.Seeds, vp)), 0.8);
  Lattice m;
  ASSERT_TRUE(m.Make(g, first, 1));
  EXPECT_LT(p.Correct(m.Cut(p.Seeds, sp)), 0.8);
}

TEST(MultiLabel, LargeGraphsRunTheirKindsFromAHelperThread)
{
  // A grid of 1.08 M nodes (a voxel cut's graph): three kinds run from a helper thread on two
  // threads give each kind's own distances; progress comes on this thread and rises; an abort
  // comes back at once as empty distances.
  const int nx = 128, ny = 128, nz = 66;
  const GraphEdges grid = GraphEdges::Grid(nx, ny, nz);
  std::vector<double> value(static_cast<std::size_t>(nx) * ny * nz);
  for (std::size_t v = 0; v < value.size(); ++v)
    value[v] = static_cast<double>((v * 2654435761u) % 97);
  GeodesicGraph graph;
  graph.Edges = &grid;
  graph.Value = value;
  std::vector<std::uint8_t> hard(value.size(), 0);
  hard[5] = 1;
  hard[value.size() / 2] = 2;
  hard[value.size() - 7] = 3;
  const std::thread::id here = std::this_thread::get_id();
  std::vector<double> reported;
  bool elsewhere = false;
  const auto d = SeedKindDistances(graph, hard, 3, 97.0, 0.01, [&](double t) {
    elsewhere = elsewhere || std::this_thread::get_id() != here;
    reported.push_back(t);
    return true;
  }, nullptr, TwoThreads);
  ASSERT_EQ(d.size(), 3u);
  EXPECT_FALSE(elsewhere);
  EXPECT_TRUE(std::is_sorted(reported.begin(), reported.end()));
  for (int kind = 1; kind <= 3; ++kind)
    EXPECT_EQ(d[kind - 1].Vector(), GeodesicDistances(graph, hard, static_cast<std::uint8_t>(kind), 97.0, 0.01)) << "kind " << kind;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(SeedKindDistances(graph, hard, 3, 97.0, 0.01, [](double) { return false; }, nullptr, TwoThreads).empty());
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
}

TEST(MultiLabel, AGaussianMixtureFindsItsComponents)
{
  // Binned samples of two correlated Gaussians (weights 0.7 / 0.3): BIC picks two of at most four,
  // and EM finds their weights and means.
  std::mt19937 rng(3);
  std::normal_distribution<double> z(0.0, 1.0);
  const int per = 64;
  std::vector<double> count(per * per, 0.0), points(2 * per * per);
  for (int b = 0; b < per * per; ++b)
  {
    points[2 * b] = b % per;
    points[2 * b + 1] = b / per;
  }
  for (int i = 0; i < 20000; ++i)
  {
    const bool first = i % 10 < 7;
    const double u = z(rng), v = z(rng);
    const double x = first ? 16.0 + 3.0 * u : 44.0 + 2.0 * u;
    const double y = first ? 20.0 + 2.0 * u + 1.5 * v : 40.0 - 1.5 * u + 2.0 * v;
    const int bx = std::clamp(static_cast<int>(std::floor(x + 0.5)), 0, per - 1);
    const int by = std::clamp(static_cast<int>(std::floor(y + 0.5)), 0, per - 1);
    count[by * per + bx] += 1.0;
  }
  const GaussianMixture g = FitGaussianMixture(points, count, 2, 4, { 1.0 / 12.0, 1.0 / 12.0 });
  ASSERT_EQ(g.Components(), 2);
  const int a = g.Mean[0] < g.Mean[2] ? 0 : 1, b = 1 - a;
  EXPECT_NEAR(g.Weight[a], 0.7, 0.01);
  EXPECT_NEAR(g.Mean[2 * a], 16.0, 0.1);
  EXPECT_NEAR(g.Mean[2 * a + 1], 20.0, 0.1);
  EXPECT_NEAR(g.Mean[2 * b], 44.0, 0.1);
  EXPECT_NEAR(g.Mean[2 * b + 1], 40.0, 0.1);
  EXPECT_GT(g.Covariance[4 * a + 1], 4.0); // cov(x, y) = 6 in the first, -3 in the second
  EXPECT_LT(g.Covariance[4 * b + 1], -2.0);
  const std::vector<double> density = g.Densities({ 16.0, 20.0, 30.0, 30.0 }); // a mean, and between the two
  EXPECT_GT(density[0], 100.0 * density[1]);
  EXPECT_EQ(FitGaussianMixture(points, std::vector<double>(per * per, 0.0), 2, 4, { 1.0, 1.0 }).Components(), 0);
}

TEST(MultiLabel, AutomaticBinsTellTissuesOfACTApart)
{
  // Bands of air (-1000), tissue at 44 and tissue at 52, a little noise: 64 bins over the range put
  // both tissues in one bin; the seeds' automatic bins (one channel) resolve them, on voxels and on
  // elements. Two channels keep the 64 x 64 grid.
  const ImageGeometry g = Grid(60, 40);
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.f, 1.5f);
  const float level[3] = { -1000.f, 44.f, 52.f };
  const std::vector<float> ct = Image(g, 1, [&](int i, int, int) { return level[Plateaus::Truth(i)] + noise(rng); });
  const Plateaus p;
  VoxelCutParameters vp;
  vp.Task = Task::Class;
  const int automatic = SeedBinsPerChannel(ct.data(), 1, g, p.Seeds, vp.SeedRadius, 0, vp.Bandwidth);
  EXPECT_GT(automatic, 64);
  EXPECT_EQ(SeedBinsPerChannel(ct.data(), 1, g, p.Seeds, vp.SeedRadius, 32, vp.Bandwidth), 32);
  const std::vector<float> two = Image(g, 2, [&](int i, int, int) { return level[Plateaus::Truth(i)] + noise(rng); });
  EXPECT_EQ(SeedBinsPerChannel(two.data(), 2, g, p.Seeds, vp.SeedRadius, 0, vp.Bandwidth), 64);
  auto voxelCut = [&](int bins) {
    ChannelBins b;
    std::string error;
    EXPECT_TRUE(BinChannels(ct.data(), 1, g.Size(), bins, b, error, SerialFor())) << error;
    const MultiLabelResult r = MultiLabelVoxelCut(std::vector<double>(ct.begin(), ct.end()), b, g, p.Seeds, vp, MultiLabelParameters());
    EXPECT_TRUE(r.Error.empty()) << r.Error;
    return r.Label;
  };
  EXPECT_LT(p.Correct(voxelCut(64)), 0.8);
  EXPECT_GT(p.Correct(voxelCut(automatic)), 0.98);
  Lattice m;
  ASSERT_TRUE(m.Make(g, ct, 1));
  std::string error;
  ASSERT_TRUE(BinChannels(ct.data(), 1, g.Size(), automatic, m.Bins, error, SerialFor()));
  m.Runs = GroupNodeBins(m.Data.Owner.data(), m.Bins, m.Mesh.NumberOfElements());
  SuperVoxelCutParameters sp;
  sp.Task = Task::Class;
  EXPECT_GT(p.Correct(m.Cut(p.Seeds, sp)), 0.95);
}

TEST(MultiLabel, TwoObjectsThatLookAlikeTakeTheirSeedsLabels)
{
  // Two disks of one intensity with labels 1 and 2 (left and right kidney, say): by appearance
  // either label fits either disk; each takes its seeds' label.
  const ImageGeometry g = Grid(70, 40);
  std::mt19937 rng(9);
  std::normal_distribution<float> noise(0.f, 4.f);
  auto disk = [](int i, int j) { return std::hypot(i - 18, j - 20) < 10 ? 1 : (std::hypot(i - 52, j - 20) < 10 ? 2 : 0); };
  const std::vector<float> image = Image(g, 1, [&](int i, int j, int) { return (disk(i, j) ? 80.f : 20.f) + noise(rng); });
  LabelledSeeds seeds;
  for (auto s : { std::array<int, 3>{ 18, 20, 1 }, { 52, 20, 2 }, { 2, 2, 0 }, { 67, 37, 0 }, { 35, 20, 0 } })
  {
    seeds.Voxel.push_back(g.Index(s[0], s[1], 0));
    seeds.Label.push_back(static_cast<std::uint8_t>(s[2]));
  }
  VoxelCutParameters vp;
  const std::vector<std::uint8_t> label = VoxelCutLabels(g, image, 1, seeds, vp);
  std::int64_t right = 0;
  for (int j = 0; j < 40; ++j)
    for (int i = 0; i < 70; ++i)
      right += label[g.Index(i, j, 0)] == disk(i, j);
  EXPECT_GT(static_cast<double>(right) / g.Size(), 0.99);
}

TEST(MultiLabel, TheGeodesicTermFindsWhatTheHistogramsCannot)
{
  // A faint ring whose inside looks like its outside, label 1 seeded on a small brighter blob at its
  // centre (2 noise deviations above), and a bright square (label 2) outside it. By appearance the inside is background and
  // label 1 shrinks to its blob; with the spatial term label 1 is the ring's inside, on the voxel
  // grid and on the elements. Connectivity off.
  const int n = 64;
  const ImageGeometry g = Grid(n, n);
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.f, 1.f);
  auto radius = [&](int i, int j) { return std::hypot(i - n / 2, j - n / 2); };
  auto square = [](int i, int j) { return i >= 1 && i <= 8 && j >= 28 && j <= 36; };
  const std::vector<float> image = Image(g, 1, [&](int i, int j, int) {
    return (square(i, j) ? 100.f : (radius(i, j) >= 20 && radius(i, j) <= 22 ? 40.f : (radius(i, j) < 3 ? 62.f : 60.f))) +
      noise(rng);
  });
  LabelledSeeds seeds;
  for (auto s : { std::array<int, 3>{ n / 2, n / 2, 1 }, { 4, 32, 2 }, { 2, 2, 0 }, { n - 3, n - 3, 0 }, { 2, n - 3, 0 },
         { n - 3, 2, 0 } })
  {
    seeds.Voxel.push_back(g.Index(s[0], s[1], 0));
    seeds.Label.push_back(static_cast<std::uint8_t>(s[2]));
  }
  auto filled = [&](const std::vector<std::uint8_t>& label) {
    std::int64_t inside = 0, one = 0;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        if (radius(i, j) < 19.5)
        {
          ++inside;
          one += label[g.Index(i, j, 0)] == 1;
        }
    return static_cast<double>(one) / inside;
  };
  Lattice m;
  ASSERT_TRUE(m.Make(g, image, 1));
  for (double weight : { 0.0, SeedGeodesicParameters().Weight })
  {
    VoxelCutParameters vp;
    vp.Connectivity = Connectivity::Off;
    vp.Geodesic.Weight = weight;
    SuperVoxelCutParameters sp;
    sp.Connectivity = Connectivity::Off;
    sp.Geodesic.Weight = weight;
    const std::vector<std::uint8_t> voxel = VoxelCutLabels(g, image, 1, seeds, vp);
    const std::vector<std::uint8_t> super = m.Cut(seeds, sp);
    for (const auto* label : { &voxel, &super })
    {
      if (weight > 0)
        EXPECT_GT(filled(*label), 0.97) << (label == &super ? "elements" : "voxels");
      else
        EXPECT_LT(filled(*label), 0.1) << (label == &super ? "elements" : "voxels");
    }
  }
}

TEST(MultiLabel, AKeptReCutEqualsAFreshOne)
{
  // Three noisy plateaus on the elements, Task Object; seeds added one at a time, each cut keeping
  // what the last one kept (distances, spatial term, weights, move graphs). From the same start
  // labels, a cut with nothing kept gives the same labels and energy.
  Plateaus p;
  Lattice m;
  ASSERT_TRUE(m.Make(p.G, p.Image, 1));
  SuperVoxelCutParameters par;
  MultiLabelCache kept;
  LabelledSeeds seeds;
  for (int s : { 0, 3, 6, 1, 4, 7, 2 })
  {
    seeds.Voxel.push_back(p.Seeds.Voxel[s]);
    seeds.Label.push_back(p.Seeds.Label[s]);
    if (seeds.Voxel.size() < 3)
      continue;
    MultiLabelCache fresh;
    fresh.Label = kept.Label;
    const MultiLabelResult a = MultiLabelSuperVoxelCut(m.Mesh, m.Data, m.Bins, m.Runs, m.Mean, m.Count, seeds, par,
      MultiLabelParameters(), SerialFor(), NoProgress(), &kept);
    const MultiLabelResult b = MultiLabelSuperVoxelCut(m.Mesh, m.Data, m.Bins, m.Runs, m.Mean, m.Count, seeds, par,
      MultiLabelParameters(), SerialFor(), NoProgress(), &fresh);
    ASSERT_TRUE(a.Error.empty() && b.Error.empty()) << a.Error << b.Error;
    EXPECT_EQ(a.Label, b.Label) << seeds.Voxel.size() << " seeds";
    EXPECT_NEAR(a.Energy, b.Energy, 1e-9 * std::fabs(b.Energy));
    EXPECT_EQ(a.Moves, b.Moves);
  }
  std::vector<std::uint8_t> pixels(p.G.Size(), 0);
  VoxelLabels(m.Data.Owner, kept.Label, pixels.data(), SerialFor());
  EXPECT_GT(p.Correct(pixels), 0.95);
}

TEST(MultiLabel, ConnectivityGivesAnUnseededPieceToItsNeighbour)
{
  // A row 0 0 2 2 1 1 1 0 0 with seeds of 1 (node 5) and 0 (nodes 0, 8): the piece of 2 holds no
  // seed of 2, and shares more weight with label 1 than with 0, so Seeded Object makes it 1.
  const GraphEdges edges = GraphEdges::Grid(9, 1, 1);
  std::vector<std::uint8_t> label{ 0, 0, 2, 2, 1, 1, 1, 0, 0 };
  std::vector<double> weight{ 1.0, 0.2, 1.0, 0.9, 1.0, 1.0, 1.0, 1.0 };
  std::vector<std::int16_t> hard{ 0, -1, -1, -1, -1, 1, -1, -1, 0 };
  const std::vector<std::uint8_t> border{ 1, 0, 0, 0, 0, 0, 0, 0, 1 };
  EXPECT_EQ(ApplyLabelConnectivity(Connectivity::FillHoles, label, edges, weight, hard, border), 0);
  EXPECT_EQ(ApplyLabelConnectivity(Connectivity::SeededObject, label, edges, weight, hard, border), 2);
  EXPECT_EQ(label, (std::vector<std::uint8_t>{ 0, 0, 1, 1, 1, 1, 1, 0, 0 }));
}

TEST(MultiLabel, SeedLabelsAreChecked)
{
  EXPECT_TRUE(ValidateSeedLabels({ 0, 1, 2, 2, 0 }).empty());
  EXPECT_FALSE(ValidateSeedLabels({ 0, -1, 1 }).empty());
  EXPECT_FALSE(ValidateSeedLabels({ 0, 256, 1 }).empty());
  EXPECT_FALSE(ValidateSeedLabels({ 0, 1.5 }).empty());
  EXPECT_FALSE(ValidateSeedLabels({ 0, 1, 3 }).empty()); // label 2 has no seed
  EXPECT_FALSE(ValidateSeedLabels({ 1, 1 }).empty());    // no background
  EXPECT_FALSE(ValidateSeedLabels({ 0, 0 }).empty());    // no object
  EXPECT_FALSE(ValidateSeedLabels({ 0, std::nan("") }).empty());
}

namespace
{
// Node ids of a mesh with the number of distinct labels in their star.
std::vector<int> StarLabelCount(const SimplexMesh& mesh, const std::vector<std::uint8_t>& label)
{
  std::vector<std::set<int>> seen(mesh.NumberOfPoints());
  for (std::int64_t e = 0; e < mesh.NumberOfElements(); ++e)
    for (int k = 0; k < mesh.VerticesPerCell(); ++k)
      seen[mesh.Cell(e)[k]].insert(label[e]);
  std::vector<int> count(seen.size());
  for (std::size_t i = 0; i < seen.size(); ++i)
    count[i] = static_cast<int>(seen[i].size());
  return count;
}

double SignedMeasure(const std::vector<std::array<double, 3>>& p, const std::int64_t* c, int vpc)
{
  const std::array<double, 3> a{ { p[c[1]][0] - p[c[0]][0], p[c[1]][1] - p[c[0]][1], p[c[1]][2] - p[c[0]][2] } };
  const std::array<double, 3> b{ { p[c[2]][0] - p[c[0]][0], p[c[2]][1] - p[c[0]][1], p[c[2]][2] - p[c[0]][2] } };
  if (vpc == 3)
    return a[0] * b[1] - a[1] * b[0];
  const std::array<double, 3> d{ { p[c[3]][0] - p[c[0]][0], p[c[3]][1] - p[c[0]][1], p[c[3]][2] - p[c[0]][2] } };
  return a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) + a[2] * (b[0] * d[1] - b[1] * d[0]);
}
} // namespace

TEST(MultiLabelSurface, ATJunctionKeepsItsPointAndEveryInterfaceStaysClosed)
{
  // Jagged labels on a jittered 2D mesh: 1 on the left, 2 top right, 0 bottom right; the three
  // interfaces meet at one junction point. After smoothing: no element inverts, nodes where three
  // labels meet stay, and each pair's interface is still a set of curves that end only at a
  // junction point or on the image box.
  const ImageGeometry g = Grid(41, 41);
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  std::vector<std::array<double, 3>> pts;
  for (int j = 0; j <= 40; j += 2)
    for (int i = 0; i <= 40; i += 2)
    {
      const bool box = i == 0 || j == 0 || i == 40 || j == 40;
      pts.push_back({ { i + (box ? 0.0 : jitter(rng)), j + (box ? 0.0 : jitter(rng)), 0.0 } });
    }
  const DelaunayResult d = Triangulate2D(pts);
  ASSERT_TRUE(d.Error.empty());
  SimplexMesh mesh(g, d.Points, d.Cells, d.VerticesPerCell);
  mesh.OrientPositively();
  std::vector<std::uint8_t> label(mesh.NumberOfElements());
  for (std::int64_t e = 0; e < mesh.NumberOfElements(); ++e)
  {
    double cx = 0, cy = 0;
    for (int k = 0; k < 3; ++k)
    {
      cx += mesh.Points()[mesh.Cell(e)[k]][0] / 3;
      cy += mesh.Points()[mesh.Cell(e)[k]][1] / 3;
    }
    const double wobble = 1.5 * std::sin(cx * 1.3) + 1.5 * std::cos(cy * 1.7);
    label[e] = cx + wobble < 20 ? 1 : (cy + wobble > 20 ? 2 : 0);
  }
  const std::vector<int> before = StarLabelCount(mesh, label);
  const SegmentationSurfaceSmoothingResult r = SmoothSegmentationSurface(mesh, label, SegmentationSurfaceSmoothingParameters(), SerialFor());
  ASSERT_TRUE(r.Error.empty()) << r.Error;
  std::int64_t points = 0, moved = 0;
  for (std::int64_t v = 0; v < mesh.NumberOfPoints(); ++v)
  {
    if (before[v] >= 3)
    {
      ++points;
      EXPECT_EQ(r.Points[v], mesh.Points()[v]) << "junction point " << v << " moved";
    }
    moved += r.Points[v] != mesh.Points()[v];
  }
  EXPECT_GE(points, 1);
  EXPECT_GT(moved, 20);
  for (std::int64_t e = 0; e < mesh.NumberOfElements(); ++e)
    EXPECT_GT(SignedMeasure(r.Points, mesh.Cell(e), 3), 0.0) << "element " << e << " inverted";
  // Each pair's interface edges: a node of odd degree is a junction point or on the box.
  const FaceAdjacency& adj = mesh.Faces();
  std::map<std::pair<int, int>, std::map<std::int64_t, int>> degree;
  for (std::size_t f = 0; f < adj.A.size(); ++f)
  {
    const int a = label[adj.A[f]], b = label[adj.B[f]];
    if (a == b)
      continue;
    for (int k = 1; k < 3; ++k)
      ++degree[std::minmax(a, b)][mesh.Cell(adj.A[f])[(adj.LocalA[f] + k) % 3]];
  }
  EXPECT_EQ(degree.size(), 3u);
  for (const auto& pair : degree)
    for (const auto& node : pair.second)
      if (node.second % 2)
      {
        const auto& q = mesh.Points()[node.first];
        EXPECT_TRUE(before[node.first] >= 3 || q[0] == 0 || q[1] == 0 || q[0] == 40 || q[1] == 40)
          << "pair " << pair.first.first << "|" << pair.first.second << " ends at node " << node.first;
      }
}

TEST(MultiLabelSurface, AJunctionCurveMovesAlongItselfIn3D)
{
  // A ball cut in two halves (labels 1 and 2) in label 0: a junction circle where the three meet.
  // Its nodes are smoothed along the circle (they move, and stay junction nodes); no tetrahedron
  // inverts; the labelled volume changes by little.
  ImageGeometry g;
  g.Dims = { { 25, 25, 25 } };
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  std::vector<std::array<double, 3>> pts;
  for (int k = 0; k <= 24; k += 2)
    for (int j = 0; j <= 24; j += 2)
      for (int i = 0; i <= 24; i += 2)
      {
        const bool box = i == 0 || j == 0 || k == 0 || i == 24 || j == 24 || k == 24;
        pts.push_back({ { i + (box ? 0.0 : jitter(rng)), j + (box ? 0.0 : jitter(rng)), k + (box ? 0.0 : jitter(rng)) } });
      }
  DelaunayImageMeshParameters o;
  o.Backend = DelaunayBackend::CGAL;
  const DelaunayResult d = Tetrahedralize(pts, o);
  ASSERT_TRUE(d.Error.empty()) << d.Error;
  SimplexMesh mesh(g, d.Points, d.Cells, d.VerticesPerCell);
  mesh.OrientPositively();
  std::vector<std::uint8_t> label(mesh.NumberOfElements());
  for (std::int64_t e = 0; e < mesh.NumberOfElements(); ++e)
  {
    std::array<double, 3> c{ { 0, 0, 0 } };
    for (int v = 0; v < 4; ++v)
      for (int a = 0; a < 3; ++a)
        c[a] += mesh.Points()[mesh.Cell(e)[v]][a] / 4;
    label[e] = std::hypot(c[0] - 12, c[1] - 12, c[2] - 12) > 8 ? 0 : (c[2] < 12 ? 1 : 2);
  }
  const std::vector<int> before = StarLabelCount(mesh, label);
  const SegmentationSurfaceSmoothingResult r = SmoothSegmentationSurface(mesh, label, SegmentationSurfaceSmoothingParameters(), SerialFor());
  ASSERT_TRUE(r.Error.empty()) << r.Error;
  std::int64_t curve = 0, curveMoved = 0;
  for (std::int64_t v = 0; v < mesh.NumberOfPoints(); ++v)
    if (before[v] == 3)
    {
      ++curve;
      curveMoved += r.Points[v] != mesh.Points()[v];
    }
  EXPECT_GT(curve, 20);
  EXPECT_GT(curveMoved, curve / 2);
  // Pinches of the staircase surfaces as in the binary case, and the curve's ends: a few.
  EXPECT_LT(r.PinchedNodes, r.BoundaryNodes / 10);
  for (std::int64_t e = 0; e < mesh.NumberOfElements(); ++e)
    EXPECT_GT(SignedMeasure(r.Points, mesh.Cell(e), 4), 0.0) << "element " << e << " inverted";
  EXPECT_NEAR(r.ObjectMeasureAfter / r.ObjectMeasureBefore, 1.0, 0.1);
}

TEST(MultiLabel, KeptDistancesOfEveryLabelEqualFreshOnes)
{
  // Three seed kinds on a noisy grid, through one cache: seeds added, removed and moved, one kind at
  // a time and together; every kind's distances equal those made afresh, every node whose distance
  // moved is listed once among its kind's changes, and the last edit's distances, held, stay as
  // they were.
  const ImageGeometry g = Grid(40, 30);
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> value(g.Size());
  for (double& v : value)
    v = 10.0 * u(rng);
  const GraphEdges edges = GraphEdges::Grid(40, 30, 1);
  GeodesicGraph graph;
  graph.Edges = &edges;
  graph.Value = value;
  std::vector<std::uint8_t> hard(g.Size(), 0);
  hard[g.Index(3, 3, 0)] = 1;
  hard[g.Index(30, 20, 0)] = 2;
  hard[g.Index(20, 5, 0)] = 3;
  SeedGeodesicCache cache, threaded;
  const std::vector<std::vector<std::pair<int, int>>> edits = {
    {}, { { g.Index(10, 10, 0), 1 } }, { { g.Index(3, 3, 0), 0 } }, { { g.Index(25, 25, 0), 3 }, { g.Index(20, 5, 0), 0 } },
    { { g.Index(30, 20, 0), 0 }, { g.Index(31, 20, 0), 2 } }, {}
  };
  std::vector<SharedArray<double>> held;
  std::vector<std::vector<double>> was;
  for (const auto& edit : edits)
  {
    for (const auto& e : edit)
      hard[e.first] = static_cast<std::uint8_t>(e.second);
    SeedDistanceChanges changes;
    const auto kept = SeedKindDistances(graph, hard, 3, 10.0, 0.01, NoProgress(), &cache, SerialFor(), &changes);
    ASSERT_EQ(kept.size(), 3u);
    EXPECT_EQ(changes.All, held.empty());
    for (int k = 0; k < 3 && !held.empty(); ++k)
    {
      EXPECT_EQ(held[k].Vector(), was[k]) << "kind " << k + 1;
      std::vector<int> listed(g.Size(), 0);
      for (std::int64_t p : changes.Nodes[k])
        ++listed[p];
      for (std::int64_t p = 0; p < g.Size(); ++p)
      {
        EXPECT_LE(listed[p], 1) << "kind " << k + 1 << " node " << p;
        if (kept[k][p] != was[k][p])
          ASSERT_EQ(listed[p], 1) << "kind " << k + 1 << " node " << p << " changed unlisted";
      }
    }
    held = kept;
    was.assign(kept.size(), {});
    for (int k = 0; k < 3; ++k)
      was[k] = kept[k].Vector();
    // The kinds on two threads: the same distances.
    EXPECT_EQ(SeedKindDistances(graph, hard, 3, 10.0, 0.01, NoProgress(), &threaded, TwoThreads), kept);
    for (int k = 0; k < 3; ++k)
    {
      const std::vector<double> fresh = GeodesicDistances(graph, hard, static_cast<std::uint8_t>(k + 1), 10.0, 0.01);
      for (std::int64_t p = 0; p < g.Size(); ++p)
        ASSERT_NEAR(kept[k][p], fresh[p], 1e-12 * (1.0 + fresh[p])) << "kind " << k + 1 << " node " << p;
    }
  }
}
