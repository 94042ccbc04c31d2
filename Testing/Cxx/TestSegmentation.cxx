// Unit tests of the Segmentation library (Boykov-Jolly cut, graphs, seeds' connectivity and geodesics, the task).
#include "BoykovJolly.h"
#include "Contract.h"
#include "GraphEdges.h"
#include "SeedConnectivity.h"
#include "SeedGeodesics.h"
#include "SeedReach.h"
#include "SuperVoxelCut.h"
#include "VoxelRefinement.h"
#include "ElementRasterizer.h"
#include "ImageFilters.h"
#include "DelaunayImageMesh.h"
#include "TestHelpers.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <thread>

using namespace featuremesh;
using namespace featuremesh_test;

// A chain of unit nodes with the given values, object seed first, background seed last.
CutProblem SeededChain(const std::vector<double>& values)
{
  CutProblem pr;
  const std::int64_t n = static_cast<std::int64_t>(values.size());
  std::vector<std::int64_t> A, B;
  for (std::int64_t i = 0; i < n; ++i)
  {
    pr.Value.Mutable().push_back(values[i]);
    pr.Size.Mutable().push_back(1.0);
    pr.Hard.push_back(i == 0 ? 1 : (i == n - 1 ? 2 : 0));
    if (i > 0)
    {
      A.push_back(i - 1);
      B.push_back(i);
      pr.Contact.Mutable().push_back(1.0);
    }
  }
  pr.Edges = GraphEdges::Owned(std::move(A), std::move(B));
  return pr;
}

TEST(BoykovJolly, SeparatesTwoPlateausAndHonoursSeeds)
{
  // A chain of 20 nodes: values 10 then 0, a seed at each end.
  std::vector<double> values;
  for (int i = 0; i < 20; ++i)
  {
    values.push_back(i < 8 ? 10.0 : 0.0);
  }
  CutProblem pr = SeededChain(values);
  pr.ObjectSamples = { 10.0, 10.0, 9.5 };
  pr.BackgroundSamples = { 0.0, 0.5, 0.0 };
  const CutResult r = BoykovJollyCut(pr, BoykovJollyParameters());
  ASSERT_TRUE(r.Error.empty());
  for (int i = 0; i < 20; ++i)
    EXPECT_EQ(r.Label[i], i < 8 ? 1 : 0) << i;
  BoykovJollyParameters bad;
  bad.Lambda = -1;
  EXPECT_FALSE(ValidateParameters(bad).empty());
}

TEST(BoykovJolly, TheGeodesicWeightFollowsTheSeedDensitiesOverlap)
{
  // A noisy ramp: the spatial term decides where the region term is unsure.
  std::vector<double> values;
  for (int i = 0; i < 40; ++i)
    values.push_back(10.0 - 0.25 * i + ((i * 7) % 5) * 0.3);
  auto cut = [&](std::vector<double> object, std::vector<double> background, bool adaptive, double weight) {
    CutProblem pr = SeededChain(values);
    pr.ObjectSamples = std::move(object);
    pr.BackgroundSamples = std::move(background);
    pr.Geodesic.Weight = weight;
    pr.Geodesic.Adaptive = adaptive;
    const CutResult r = BoykovJollyCut(pr, BoykovJollyParameters());
    EXPECT_TRUE(r.Error.empty()) << r.Error;
    return r;
  };
  const double w = SeedGeodesicParameters().Weight;
  // The same samples: the densities are one, the weight the most it gets.
  const CutResult same = cut({ 4.0, 5.0, 6.0, 5.5 }, { 4.0, 5.0, 6.0, 5.5 }, true, w);
  EXPECT_NEAR(same.SeedOverlap, 1.0, 1e-9);
  EXPECT_NEAR(same.SpatialWeight, w / SeedOverlapReference, 1e-9);
  // Apart: appearance decides, the spatial term weighs little.
  const CutResult apart = cut({ 10.0, 9.5, 9.8 }, { 0.0, 0.4, 0.2 }, true, w);
  EXPECT_LT(apart.SeedOverlap, 0.2);
  EXPECT_NEAR(apart.SpatialWeight, w * apart.SeedOverlap / SeedOverlapReference, 1e-12);
  // Overlapping: the adaptive cut is the fixed cut at the weight it reports.
  const std::vector<double> object = { 10.0, 8.0, 6.5, 7.0 }, background = { 7.5, 3.0, 1.0, 0.5 };
  const CutResult adaptive = cut(object, background, true, w);
  EXPECT_GT(adaptive.SeedOverlap, 0.2);
  EXPECT_LT(adaptive.SeedOverlap, 0.9);
  const CutResult fixed = cut(object, background, false, adaptive.SpatialWeight);
  EXPECT_EQ(fixed.SpatialWeight, adaptive.SpatialWeight);
  EXPECT_EQ(fixed.Label, adaptive.Label);
  EXPECT_NEAR(fixed.Flow, adaptive.Flow, 1e-9 * fixed.Flow);
  // Off, or without the term: the weight as given, or none.
  EXPECT_EQ(cut(object, background, false, w).SpatialWeight, w);
  EXPECT_EQ(cut(object, background, true, 0.0).SpatialWeight, 0.0);
}

TEST(BoykovJolly, AutomaticBinsResolveNarrowDensitiesInAWideRange)
{
  // A CT in miniature: object tissue near 52, background tissue near 44 and air near -1000. With 64
  // bins over the range both tissues share a bin and the background tissue looks like the object;
  // the automatic bins resolve the seeds' densities and tell them apart.
  std::vector<double> values;
  const double wobble[3] = { -1.5, 0.0, 1.5 };
  for (int i = 0; i < 30; ++i)
  {
    values.push_back((i < 10 ? 52.0 : (i < 20 ? 44.0 : -1000.0)) + wobble[i % 3]);
  }
  CutProblem pr = SeededChain(values);
  for (int i = 0; i < 6; ++i)
  {
    pr.ObjectSamples.push_back(52.0 + wobble[i % 3]);
    pr.BackgroundSamples.push_back(44.0 + wobble[i % 3]);
    pr.BackgroundSamples.push_back(-1000.0 + wobble[i % 3]);
  }
  BoykovJollyParameters par;
  par.Lambda = 5.0;
  const CutResult fine = BoykovJollyCut(pr, par);
  ASSERT_TRUE(fine.Error.empty());
  EXPECT_GT(fine.Bins, 64);
  for (int i = 0; i < 30; ++i)
    EXPECT_EQ(fine.Label[i], i < 10 ? 1 : 0) << i;
  par.Bins = 64;
  const CutResult coarse = BoykovJollyCut(pr, par);
  ASSERT_TRUE(coarse.Error.empty());
  EXPECT_EQ(coarse.Label[15], 1);
  // Wide densities keep 64 bins.
  const std::vector<double> wide = { 0.0, 10.0, 20.0, 30.0, 40.0 };
  EXPECT_EQ(AutomaticBins({ { &wide, nullptr } }, 0.0, 40.0, 1.0), 64);
  const std::vector<double> narrow = { 20.0, 20.1, 20.2, 20.3 };
  EXPECT_GT(AutomaticBins({ { &wide, nullptr }, { &narrow, nullptr } }, 0.0, 40.0, 1.0), 64);
  const std::vector<double> spike = { 7.0, 7.0, 7.0 };
  EXPECT_EQ(AutomaticBins({ { &spike, nullptr } }, 0.0, 40.0, 1.0), 64);
}

TEST(BoykovJolly, VoxelRegionTermSumsVoxelCosts)
{
  // Super-nodes of one voxel each: the voxel region term must equal the mean-based one.
  std::vector<double> pixels;
  std::vector<std::int32_t> owner;
  for (int i = 0; i < 30; ++i)
  {
    pixels.push_back((i < 12 ? 10.0 : 0.0) + ((i * 7) % 5) * 0.6);
    owner.push_back(i);
  }
  CutProblem pr = SeededChain(pixels);
  pr.ObjectSamples = { 10.0, 11.0, 12.4 };
  pr.BackgroundSamples = { 0.0, 1.2, 2.4 };
  const CutResult byMean = BoykovJollyCut(pr, BoykovJollyParameters());
  NodeVoxelValues grouped;
  std::string error;
  ASSERT_TRUE(GroupVoxelValues(owner.data(), pixels.data(), 30, 30, grouped, error, SerialFor()));
  pr.NodeVoxels = &grouped;
  const CutResult byVoxel = BoykovJollyCut(pr, BoykovJollyParameters());
  ASSERT_TRUE(byMean.Error.empty() && byVoxel.Error.empty());
  EXPECT_EQ(byMean.Label, byVoxel.Label);
  EXPECT_NEAR(byMean.Flow, byVoxel.Flow, 1e-9 * byMean.Flow);

  // One element holding 3 object-like voxels and 1 background-like voxel, mean in between: the
  // voxel term counts what its voxels are, the mean term what its mean looks like.
  CutProblem two;
  two.Value = { 10.0, 0.0, 7.5 };
  two.Size = { 1.0, 1.0, 4.0 };
  two.Hard = { 1, 2, 0 };
  two.Edges = GraphEdges::Owned({ 0, 1 }, { 2, 2 });
  two.Contact = { 0.01, 0.01 };
  const std::vector<double> v = { 10.0, 0.0, 10.0, 10.0, 10.0, 0.0 };
  const std::vector<std::int32_t> o = { 0, 1, 2, 2, 2, 2 };
  two.ObjectSamples = { 10.0, 9.0, 11.0 };
  two.BackgroundSamples = { 0.0, 1.0, -1.0 };
  NodeVoxelValues twoGrouped;
  ASSERT_TRUE(GroupVoxelValues(o.data(), v.data(), 6, 3, twoGrouped, error, SerialFor()));
  EXPECT_EQ(twoGrouped.Offset, (std::vector<std::int64_t>{ 0, 1, 2, 6 }));
  EXPECT_EQ(std::vector<double>(twoGrouped.Double.get(), twoGrouped.Double.get() + 6), (std::vector<double>{ 10.0, 0.0, 0.0, 10.0, 10.0, 10.0 }));
  NodeVoxelValues twoBounded;
  ASSERT_TRUE(GroupVoxelValues(o.data(), v.data(), 6, 3, twoBounded, error, SerialFor(), NoProgress(), nullptr, 0));
  EXPECT_FALSE(twoBounded.Sorted());
  EXPECT_EQ(twoBounded.Min, (std::vector<float>{ 10.f, 0.f, 0.f }));
  EXPECT_EQ(twoBounded.Max, (std::vector<float>{ 10.f, 0.f, 10.f }));
  EXPECT_EQ(twoBounded.Shared, (std::vector<std::uint8_t>{ 0, 0, 1 })); // voxels 2-5 lie in chunks 2-5 of 8
  two.NodeVoxels = &twoGrouped;
  const std::vector<double> nan = { 1.0, std::nan(""), 2.0, 3.0, 4.0, 5.0 };
  NodeVoxelValues badGrouped;
  EXPECT_FALSE(GroupVoxelValues(o.data(), nan.data(), 6, 3, badGrouped, error, SerialFor()));
  EXPECT_EQ(error.rfind("1 intensities are NaN", 0), 0u) << error;
  const CutResult exact = BoykovJollyCut(two, BoykovJollyParameters());
  ASSERT_TRUE(exact.Error.empty());
  EXPECT_EQ(exact.Label[2], 1);
}

TEST(BoykovJolly, SeedSamplesBeyondTheRobustRangeAddBinsOfItsWidth)
{
  // 100 nodes of values 0..99: 64 bins of ~1.53 over the robust range. Object samples beyond it add
  // bins of that width (a seed edit moves how far the histogram reaches, not its bins' edges), up to
  // 64 more on each side; a sample beyond those counts in the end bin.
  std::vector<double> values;
  for (int i = 0; i < 100; ++i)
  {
    values.push_back(i);
  }
  CutProblem pr = SeededChain(values);
  pr.BackgroundSamples = { 0.0, 1.0, 2.0, 3.0 };
  BoykovJollyParameters par;
  par.Bins = 64;
  auto bins = [&](double farthest) {
    pr.ObjectSamples = { 96.0, 97.0, 98.0, farthest };
    const CutResult r = BoykovJollyCut(pr, par);
    EXPECT_TRUE(r.Error.empty()) << r.Error;
    return r.Bins;
  };
  const double width = 98.0 / 64;
  EXPECT_EQ(bins(99.0), 64);
  EXPECT_NEAR(bins(150.0) - bins(120.0), 30.0 / width, 1.0);
  EXPECT_EQ(bins(1e6), 128);
  pr.BackgroundSamples = { -1e6, 1.0, 2.0, 3.0 };
  EXPECT_EQ(bins(1e6), 192);
}

TEST(BoykovJolly, AnOutlierFarBeyondTheRangeCountsInTheLastBin)
{
  // 40 nodes of 5 voxels in [0, 20]; the largest voxel is 25, 1e12 or 1e150, far more bins beyond
  // the range than an int counts: all fall in the last bin (the percentile range and the means stay the same), so the
  // cut is the same, and it finishes; with the values sorted and bounded.
  std::vector<double> mean;
  std::vector<std::int32_t> owner;
  std::vector<double> voxels;
  for (int p = 0; p < 40; ++p)
  {
    double sum = 0.0;
    for (int k = 0; k < 5; ++k)
    {
      voxels.push_back((p < 15 ? 15.0 : 3.0) + (k * 7 + p) % 5);
      owner.push_back(p);
      sum += voxels.back();
    }
    mean.push_back(sum / 5);
  }
  CutProblem pr = SeededChain(mean);
  pr.ObjectSamples = { 15, 16, 17, 19 };
  pr.BackgroundSamples = { 3, 4, 5, 7 };
  std::vector<double> flows;
  std::vector<std::vector<std::uint8_t>> labels;
  for (const double outlier : { 25.0, 1e12, 1e150, 25.0, 1e12, 1e150 })
  {
    voxels[7] = outlier;
    NodeVoxelValues grouped;
    std::string error;
    ASSERT_TRUE(GroupVoxelValues(owner.data(), voxels.data(), static_cast<std::int64_t>(voxels.size()), 40, grouped,
      error, SerialFor(), NoProgress(), nullptr, flows.size() < 3 ? SortedVoxelLimit : 0));
    pr.NodeVoxels = &grouped;
    MaxFlowCache cache;
    const CutResult r = BoykovJollyCut(pr, BoykovJollyParameters(), NoProgress(), &cache);
    ASSERT_TRUE(r.Error.empty()) << r.Error;
    flows.push_back(r.Flow);
    labels.push_back(r.Label);
  }
  for (size_t k = 1; k < flows.size(); ++k)
  {
    EXPECT_EQ(flows[k], flows[0]) << k;
    EXPECT_EQ(labels[k], labels[0]) << k;
  }
}

TEST(BoykovJolly, VoxelRegionTermCountsEveryVoxelInItsBin)
{
  // 50 nodes whose voxels (300 k, more than one pass block, some owned by none) lie scattered
  // through the volume, spanning several bins each. With no boundary term each free node pays the
  // cheaper of its two region costs, so the flow is the sum of those minima: computed here voxel by
  // voxel, it must equal the cut's: sorted or bounded values, a serial or a chunked (any thread
  // split) pass, one or two words of bins per node.
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> node(-1, 49);
  std::normal_distribution<double> noise(0.0, 4.0);
  const std::int64_t voxels = 300000;
  std::vector<std::int32_t> owner(voxels);
  std::vector<float> values(voxels);
  std::vector<double> sum(50, 0.0), count(50, 0.0);
  for (std::int64_t v = 0; v < voxels; ++v)
  {
    owner[v] = node(rng);
    values[v] = static_cast<float>((owner[v] >= 0 && owner[v] < 20 ? 30.0 : 10.0) + noise(rng));
    if (owner[v] >= 0)
    {
      sum[owner[v]] += values[v];
      count[owner[v]] += 1.0;
    }
  }
  std::vector<double> mean(50);
  for (int p = 0; p < 50; ++p)
  {
    mean[p] = sum[p] / count[p];
  }
  CutProblem pr = SeededChain(mean);
  pr.Size = count;
  std::vector<double>& contact = pr.Contact.Mutable();
  std::fill(contact.begin(), contact.end(), 0.0);
  pr.ObjectSamples = { 28, 30, 33, 31, 26 };
  pr.BackgroundSamples = { 8, 12, 10, 9, 14 };
  const std::vector<std::pair<std::int64_t, int>> forms = { { SortedVoxelLimit, 64 }, { SortedVoxelLimit, 100 }, { 0, 64 }, { 0, 100 } };
  for (const auto& [sortedLimit, bins] : forms)
  {
    NodeVoxelValues viewed;
    std::string error;
    ASSERT_TRUE(GroupVoxelValues(owner.data(), values.data(), voxels, 50, viewed, error, SerialFor(), NoProgress(), nullptr,
      sortedLimit)) << error;
    EXPECT_EQ(viewed.Sorted(), sortedLimit > 0);
    pr.NodeVoxels = &viewed;
    BoykovJollyParameters par;
    par.Bins = bins;
    pr.Parallel = SerialFor();
    const CutResult serial = BoykovJollyCut(pr, par);
    const ParallelFor chunked = [](std::int64_t n, std::int64_t, const RangeFunction& body) {
      for (std::int64_t b = ((n - 1) / 3) * 3; b >= 0; b -= 3)
        body(b, std::min(n, b + 3));
    };
    pr.Parallel = chunked;
    const CutResult split = BoykovJollyCut(pr, par);
    ASSERT_TRUE(serial.Error.empty() && split.Error.empty());
    EXPECT_EQ(split.Flow, serial.Flow);
    EXPECT_EQ(split.Label, serial.Label);

    double low = viewed.Low, high = viewed.High;
    for (const auto* samples : { &pr.ObjectSamples, &pr.BackgroundSamples })
    {
      for (double x : *samples)
      {
        low = std::min(low, x);
        high = std::max(high, x);
      }
    }
    const double width = (high - low) / bins;
    const std::vector<double> object = SmoothedHistogram(pr.ObjectSamples, {}, low, high, bins);
    const std::vector<double> background = SmoothedHistogram(pr.BackgroundSamples, {}, low, high, bins);
    std::vector<std::vector<double>> perBin(50, std::vector<double>(bins, 0.0));
    for (std::int64_t v = 0; v < voxels; ++v)
    {
      if (owner[v] >= 0)
      {
        const double q = (static_cast<double>(values[v]) - low) / width;
        perBin[owner[v]][q < 1.0 ? 0 : (q >= bins - 1 ? bins - 1 : static_cast<int>(q))] += 1.0;
      }
    }
    double flow = 0.0;
    int spanning = 0;
    for (int p = 1; p < 49; ++p)
    {
      double costObject = 0.0, costBackground = 0.0;
      for (int b = 0; b < bins; ++b)
      {
        if (perBin[p][b] > 0.0)
        {
          costObject += perBin[p][b] * -std::log(object[b]);
          costBackground += perBin[p][b] * -std::log(background[b]);
        }
      }
      spanning += std::count_if(perBin[p].begin(), perBin[p].end(), [](double c) { return c > 0.0; }) > 5 ? 1 : 0;
      flow += std::min(par.Lambda * costObject, par.Lambda * costBackground);
    }
    EXPECT_EQ(spanning, 48);
    EXPECT_NEAR(serial.Flow, flow, 1e-12 * flow) << bins << " " << sortedLimit;
  }
}

TEST(BoykovJolly, KeptCutsEqualFreshCuts)
{
  // 60 super-nodes of 1-40 noisy voxels each (spanning several bins), object-like first; a chain of
  // seed edits through one MaxFlowCache, with the values sorted and bounded: a binning seen first
  // (summed from the sorted values, or binned from the voxels), the same binning again (kept as
  // runs), read from the runs, a seed sample beyond the range (a new binning),
  // then a change of the bins and of sigma (new weights), and of the contacts (which the cache
  // knows by their digest only). Each cut equals a fresh one: the same labels and flow.
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 3.0);
  std::uniform_int_distribution<int> count(1, 40);
  std::vector<double> mean, voxels;
  std::vector<std::int32_t> owner;
  for (int p = 0; p < 60; ++p)
  {
    const int c = count(rng);
    double sum = 0.0;
    for (int k = 0; k < c; ++k)
    {
      voxels.push_back((p < 25 ? 20.0 : 5.0) + noise(rng));
      owner.push_back(p);
      sum += voxels.back();
    }
    mean.push_back(sum / c);
  }
  for (const std::int64_t sortedLimit : { SortedVoxelLimit, std::int64_t(0) })
  {
    CutProblem pr = SeededChain(mean);
    NodeVoxelValues grouped;
    std::string error;
    ASSERT_TRUE(GroupVoxelValues(owner.data(), voxels.data(), static_cast<std::int64_t>(voxels.size()), 60, grouped,
      error, SerialFor(), NoProgress(), nullptr, sortedLimit));
    pr.NodeVoxels = &grouped;
    BoykovJollyParameters par;
    par.Lambda = 1.0;
    const std::vector<std::vector<double>> objectSamples = { { 20, 22, 18, 25 }, { 20, 22, 18, 25 }, { 21, 19, 23, 17 },
      { 21, 19, 23, 60 }, { 21, 19, 23, 60 }, { 21, 19, 23, 60 }, { 21, 19, 23, 60 }, { 21, 19, 23, 60 },
      { 21, 19, 23, 60 } };
    // Edits 0-3 on held (owned) edge lists, which the cache keeps as they are; from 4 on a view of
    // equal lists (compared by value: the kept flow still applies), which the new sigma of edit 6
    // makes the cache copy, and edit 7 reuses.
    const std::vector<std::int64_t> A(pr.Edges.First(), pr.Edges.First() + pr.Edges.Size());
    const std::vector<std::int64_t> B(pr.Edges.Second(), pr.Edges.Second() + pr.Edges.Size());
    MaxFlowCache cache;
    double lastFlow = 0.0;
    for (size_t edit = 0; edit < objectSamples.size(); ++edit)
    {
      if (edit == 4)
      {
        pr.Edges = GraphEdges(A, B);
      }
      if (edit == 8)
      {
        pr.Contact.Mutable()[24] = 1e12; // the edge between the plateaus: its weight is ~1e-12
      }
      pr.ObjectSamples = objectSamples[edit];
      pr.BackgroundSamples = { 5, 3, 7, 4 + static_cast<double>(edit) };
      par.Bins = edit >= 5 ? 16 : 0;
      par.Sigma = edit >= 6 ? 2.0 : 0.0;
      const CutResult kept = BoykovJollyCut(pr, par, NoProgress(), &cache);
      const CutResult fresh = BoykovJollyCut(pr, par);
      ASSERT_TRUE(kept.Error.empty() && fresh.Error.empty()) << edit;
      if (edit == 8)
      {
        EXPECT_GT(std::fabs(fresh.Flow - lastFlow), 1e-5 * fresh.Flow); // the new contact matters
      }
      lastFlow = fresh.Flow;
      EXPECT_EQ(kept.Label, fresh.Label) << edit;
      EXPECT_NEAR(kept.Flow, fresh.Flow, 1e-12 * fresh.Flow) << edit;
      const auto object = std::count(kept.Label.begin(), kept.Label.end(), 1);
      EXPECT_TRUE(object >= 22 && object <= 28) << edit << ": " << object;
    }
  }
}

TEST(SuperVoxelCut, SeedElementVoxelsAreTheSeedElementsVoxelsNearASeed)
{
  // A random owner map with a few seed elements of each kind: the voxels SeedElementVoxels lists are
  // those of the kind's seed elements within the radius of one of its seeds, in raster order, from
  // few seeds (listed balls) and from a scribble of many (a mask over their box), in 3D and 2D.
  for (const int depth : { 24, 1 })
  {
    ImageGeometry g;
    g.Dims = { { 40, 36, depth } };
    std::mt19937 rng(7);
    std::uniform_int_distribution<std::int32_t> element(0, 59);
    std::vector<std::int32_t> owner(g.Size());
    for (auto& o : owner)
      o = element(rng);
    owner[5] = -1;
    std::vector<std::uint8_t> hard(60, 0);
    for (int e = 0; e < 60; e += 7)
      hard[e] = e % 2 ? 1 : 2;
    std::uniform_int_distribution<std::int64_t> voxel(0, g.Size() - 1);
    for (const int seeds : { 3, 400 })
    {
      std::vector<std::int64_t> object;
      for (int n = 0; n < seeds; ++n)
        object.push_back(seeds > 100 ? g.Index(10 + n % 12, 8 + (n / 12) % 10, std::min(depth - 1, n / 120)) : voxel(rng));
      object.push_back(object.front()); // a repeated seed counts once
      for (const double radius : { 2.5, 5.0 })
      {
        std::vector<std::int64_t> expected;
        for (std::int64_t u = 0; u < g.Size(); ++u)
        {
          if (owner[u] < 0 || hard[owner[u]] != 1)
            continue;
          const int i = static_cast<int>(u % g.Dims[0]), j = static_cast<int>((u % g.SliceStride()) / g.Dims[0]),
                    k = static_cast<int>(u / g.SliceStride());
          for (const std::int64_t v : object)
          {
            const int di = i - static_cast<int>(v % g.Dims[0]), dj = j - static_cast<int>((v % g.SliceStride()) / g.Dims[0]),
                      dk = k - static_cast<int>(v / g.SliceStride());
            if (di * di + dj * dj + dk * dk <= radius * radius)
            {
              expected.push_back(u);
              break;
            }
          }
        }
        EXPECT_FALSE(expected.empty());
        EXPECT_EQ(SeedElementVoxels(g, owner.data(), hard, object, 1, radius), expected)
          << depth << " slices, " << seeds << " seeds, radius " << radius;
      }
    }
  }
}

TEST(SuperVoxelCut, BoundedVoxelValuesCutAsSortedOnes)
{
  // A noisy bright ball in a 3D image, meshed off the lattice: the cut with each element's voxel
  // values sorted and with their bounds only (a binning pass over the voxels, seed samples from the
  // elements' boxes in the owner map) gives the same labels and flow, for two seed sets.
  ImageGeometry g;
  g.Dims = { { 30, 28, 26 } };
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.f, 8.f);
  std::vector<float> image(g.Size());
  for (int k = 0; k < g.Dims[2]; ++k)
    for (int j = 0; j < g.Dims[1]; ++j)
      for (int i = 0; i < g.Dims[0]; ++i)
        image[g.Index(i, j, k)] = ((i - 14) * (i - 14) + (j - 13) * (j - 13) + (k - 12) * (k - 12) < 64 ? 100.f : 40.f) + noise(rng);
  std::vector<std::array<double, 3>> pts;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n = 0; n < 700; ++n)
    pts.push_back({ { u(rng) * 29, u(rng) * 27, u(rng) * 25 } });
  for (int c = 0; c < 8; ++c)
    pts.push_back({ { (c & 1) ? 29.0 : 0, (c & 2) ? 27.0 : 0, (c & 4) ? 25.0 : 0 } });
  SimplexMesh mesh;
  ASSERT_TRUE(CGALMeshOfNodes(g, pts, mesh));
  const ElementStatistics stats = ComputeElementStatistics(ElementRasterizer(mesh), image.data(), SerialFor());
  const std::vector<double> count(stats.PixelCount.begin(), stats.PixelCount.end());
  SuperVoxelCutData sorted, bounded;
  std::string error;
  ASSERT_TRUE(PrepareSuperVoxelCut(mesh, image.data(), sorted, error, SerialFor()));
  ASSERT_TRUE(PrepareSuperVoxelCut(mesh, image.data(), bounded, error, SerialFor(), NoProgress(), nullptr, 0));
  ASSERT_TRUE(sorted.Voxels.Sorted() && !bounded.Voxels.Sorted());
  const VoxelValueFunction value = [&](std::int64_t v) { return static_cast<double>(image[v]); };
  const std::vector<std::vector<std::int64_t>> objectSeeds = { { g.Index(14, 13, 12) }, { g.Index(12, 13, 12), g.Index(17, 14, 11) } };
  for (const auto& object : objectSeeds)
  {
    const std::vector<std::int64_t> background = { g.Index(2, 2, 2), g.Index(27, 25, 23) };
    SuperVoxelCutParameters par;
    par.Connectivity = Connectivity::Off;
    const SuperVoxelCutResult a = SuperVoxelCut(mesh, sorted, stats.Mean, count, object, background, value, par, SerialFor());
    const SuperVoxelCutResult b = SuperVoxelCut(mesh, bounded, stats.Mean, count, object, background, value, par, SerialFor());
    ASSERT_TRUE(a.Error.empty() && b.Error.empty()) << a.Error << b.Error;
    EXPECT_EQ(a.Cut.Label, b.Cut.Label);
    EXPECT_EQ(a.Cut.Flow, b.Cut.Flow);
    const auto objectElements = std::count(a.Cut.Label.begin(), a.Cut.Label.end(), 1);
    EXPECT_GT(objectElements, 20);
    EXPECT_LT(objectElements, static_cast<long>(a.Cut.Label.size()) / 2);
  }
}

TEST(SuperVoxelCut, PatchedVoxelLabelsEqualFreshOnes)
{
  // Off-lattice elements in 3D and 2D: the label image of one labelling, patched where a second
  // differs, equals the second's own label image; a change over most of the image is refused.
  for (const bool volume : { true, false })
  {
    ImageGeometry g;
    g.Dims = { { 31, 27, volume ? 23 : 1 } };
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<std::array<double, 3>> pts;
    for (int n = 0; n < (volume ? 600 : 150); ++n)
      pts.push_back({ { u(rng) * 30, u(rng) * 26, volume ? u(rng) * 22 : 0.0 } });
    for (int c = 0; c < (volume ? 8 : 4); ++c)
      pts.push_back({ { (c & 1) ? 30.0 : 0, (c & 2) ? 26.0 : 0, (c & 4) ? 22.0 : 0 } });
    SimplexMesh mesh;
    ASSERT_TRUE(CGALMeshOfNodes(g, pts, mesh));
    SuperVoxelCutData data;
    std::string error;
    ASSERT_TRUE(PrepareSuperVoxelCut(mesh, static_cast<const double*>(nullptr), data, error, SerialFor()));
    const std::int64_t m = mesh.NumberOfElements();
    std::vector<std::uint8_t> before(m), after;
    for (auto& l : before)
      l = static_cast<std::uint8_t>(u(rng) * 3);
    after = before;
    for (std::int64_t e = 0; e < m; e += m / 4) // boxes of four elements: a few thousand voxels
      after[e] = static_cast<std::uint8_t>((after[e] + 1) % 3);
    std::vector<std::uint8_t> patched(g.Size()), fresh(g.Size());
    VoxelLabels(data.Owner, before, patched.data(), SerialFor());
    VoxelLabels(data.Owner, after, fresh.data(), SerialFor());
    ASSERT_NE(patched, fresh);
    ASSERT_TRUE(PatchVoxelLabels(mesh, data.Owner, before, after, patched.data(), SerialFor()));
    EXPECT_EQ(patched, fresh);
    std::vector<std::uint8_t> flipped(after);
    for (auto& l : flipped)
      l = static_cast<std::uint8_t>((l + 1) % 3);
    EXPECT_FALSE(PatchVoxelLabels(mesh, data.Owner, after, flipped, patched.data(), SerialFor()));
    EXPECT_EQ(patched, fresh);
    EXPECT_FALSE(PatchVoxelLabels(mesh, data.Owner, std::vector<std::uint8_t>(), after, patched.data(), SerialFor()));
  }
}

TEST(SuperVoxelCut, ContactAndHardConstraintsOnFourTriangles)
{
  // Anisotropic pixels: a spoke of length sqrt(2^2 0.5^2 + 2^2 1.5^2) counts in units of the mean
  // pixel edge (1.0).
  const SimplexMesh mesh = FourTriangles(0.5, 1.5);
  const std::vector<double> contact = ContactInVoxelFaces(mesh, true);
  for (double c : contact)
    EXPECT_DOUBLE_EQ(c, std::sqrt(1.0 + 9.0) / 1.0);
  for (double c : ContactInVoxelFaces(mesh, false))
    EXPECT_EQ(c, 1.0);

  SuperVoxelCutData data;
  std::string prepareError;
  ASSERT_TRUE(PrepareSuperVoxelCut(mesh, static_cast<const double*>(nullptr), data, prepareError, SerialFor()));
  const VoxelOwnerMap& owner = data.Owner;
  const ImageGeometry& g = mesh.Geometry();
  std::vector<std::uint8_t> hard(4, 0);
  std::string error;
  // Voxel (2, 0) lies in the bottom triangle, (4, 2) in the right one.
  ASSERT_TRUE(SeedConstraints(owner, { g.Index(2, 0, 0) }, { g.Index(4, 2, 0) }, "element", hard, error));
  EXPECT_EQ(hard, (std::vector<std::uint8_t>{ 1, 2, 0, 0 }));
  hard.assign(4, 0);
  EXPECT_FALSE(SeedConstraints(owner, { g.Index(2, 0, 0) }, { g.Index(1, 0, 0) }, "element", hard, error));
  EXPECT_EQ(error, "element 0 holds both an object and a background seed; move one of them.");

  // Bright bottom and left, dark right and top; seeds force bottom and right even when the
  // intensities disagree (the background seed sits in a bright element).
  const std::vector<double> mean = { 100, 10, 10, 100 }, count = { 9, 9, 9, 9 };
  SuperVoxelCutParameters par;
  const SuperVoxelCutResult r =
    SuperVoxelCut(mesh, data, mean, count, { g.Index(2, 0, 0) }, { g.Index(4, 2, 0) }, VoxelValueFunction(), par, SerialFor());
  ASSERT_TRUE(r.Error.empty()) << r.Error;
  EXPECT_EQ(r.Cut.Label[0], LabelObject);
  EXPECT_EQ(r.Cut.Label[1], LabelBackground);
  EXPECT_EQ(r.Cut.Label[3], LabelObject);
  std::vector<std::uint8_t> voxels(owner.size());
  VoxelLabels(owner, r.Cut.Label, voxels.data(), SerialFor());
  EXPECT_EQ(voxels[g.Index(2, 0, 0)], LabelObject);
  EXPECT_EQ(voxels[g.Index(4, 2, 0)], LabelBackground);
}

TEST(Guards, EnergyInputsAreCheckedAndSeedsAlwaysHold)
{
  CutProblem pr = SeededChain({ 5, 5, 5, 5, 0, 0, 0, 0 });
  pr.ObjectSamples = { 5.0 };
  pr.BackgroundSamples = { 0.0 };
  // A tiny sigma with equal neighbours once gave 0 * inf = NaN capacities.
  BoykovJollyParameters tiny;
  tiny.Sigma = 1e-300;
  CutResult r = BoykovJollyCut(pr, tiny);
  ASSERT_TRUE(r.Error.empty()) << r.Error;
  EXPECT_TRUE(std::isfinite(r.Flow));
  EXPECT_EQ(r.Label.front(), 1);
  EXPECT_EQ(r.Label.back(), 0);
  // Non-finite or too large intensities, negative sizes and contacts are errors.
  CutProblem bad = pr;
  bad.Value.Mutable()[2] = std::nan("");
  EXPECT_NE(BoykovJollyCut(bad, BoykovJollyParameters()).Error.find("NaN"), std::string::npos);
  bad = pr;
  bad.Value.Mutable()[2] = 1e300;
  EXPECT_FALSE(BoykovJollyCut(bad, BoykovJollyParameters()).Error.empty());
  bad = pr;
  bad.Size.Mutable()[1] = -1;
  EXPECT_FALSE(BoykovJollyCut(bad, BoykovJollyParameters()).Error.empty());
  bad = pr;
  bad.Contact.Mutable()[0] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(BoykovJollyCut(bad, BoykovJollyParameters()).Error.empty());
  bad = pr;
  std::vector<std::int64_t> A(pr.Edges.First(), pr.Edges.First() + pr.Edges.Size());
  std::vector<std::int64_t> B(pr.Edges.Second(), pr.Edges.Second() + pr.Edges.Size());
  B[0] = 99;
  bad.Edges = GraphEdges::Owned(A, B);
  EXPECT_FALSE(BoykovJollyCut(bad, BoykovJollyParameters()).Error.empty());
  B.pop_back();
  bad.Edges = GraphEdges(A, B);
  EXPECT_FALSE(BoykovJollyCut(bad, BoykovJollyParameters()).Error.empty());
  BoykovJollyParameters huge;
  huge.Lambda = 1e300;
  EXPECT_FALSE(ValidateParameters(huge).empty());
  // An abort before the flow comes back as Aborted, with no labels.
  int calls = 0;
  const CutResult aborted = BoykovJollyCut(pr, BoykovJollyParameters(), [&](double) { return ++calls < 2; });
  EXPECT_TRUE(aborted.Aborted);
  EXPECT_TRUE(aborted.Label.empty());
}

TEST(GraphEdges, GridEdgesAreTheFaceNeighboursInVoxelOrderAndBlocksSplitThem)
{
  for (const std::array<int, 3>& d : std::vector<std::array<int, 3>>{
         { { 5, 4, 3 } }, { { 7, 6, 1 } }, { { 1, 3, 4 } }, { { 2, 1, 1 } }, { { 6000, 3, 2 } }, { { 3, 2000, 3 } } })
  {
    // The list the voxel cut used to store: each voxel in raster order with its +x, +y, +z neighbour.
    std::vector<std::int64_t> A, B;
    const std::int64_t sy = d[0], sz = static_cast<std::int64_t>(d[0]) * d[1];
    for (int k = 0; k < d[2]; ++k)
      for (int j = 0; j < d[1]; ++j)
        for (int i = 0; i < d[0]; ++i)
        {
          const std::int64_t v = i + sy * j + sz * k;
          for (const auto& step : { std::make_pair(i + 1 < d[0], std::int64_t(1)), std::make_pair(j + 1 < d[1], sy),
                 std::make_pair(k + 1 < d[2], sz) })
          {
            if (step.first)
            {
              A.push_back(v);
              B.push_back(v + step.second);
            }
          }
        }
    const GraphEdges grid = GraphEdges::Grid(d[0], d[1], d[2]);
    ASSERT_EQ(grid.Size(), static_cast<std::int64_t>(A.size())) << d[0] << " " << d[1] << " " << d[2];
    std::int64_t seen = 0;
    for (std::int64_t k = 0; k < grid.Blocks(); ++k)
    {
      EXPECT_EQ(grid.BlockStart(k), seen);
      grid.ForEach(k, k + 1, [&](std::int64_t e, std::int64_t a, std::int64_t b) {
        EXPECT_EQ(e, seen);
        EXPECT_EQ(a, A[e]);
        EXPECT_EQ(b, B[e]);
        ++seen;
      });
    }
    EXPECT_EQ(seen, grid.Size());
    EXPECT_EQ(grid.BlockStart(grid.Blocks()), grid.Size());
    EXPECT_TRUE(grid.Same(GraphEdges::Grid(d[0], d[1], d[2])));
    const GraphEdges held = GraphEdges::Owned(A, B), copy = held;
    EXPECT_TRUE(held.Held() && copy.Same(held) && !GraphEdges(A, B).Held());
    EXPECT_FALSE(grid.Same(GraphEdges(A, B)));
    EXPECT_TRUE(GraphEdges(A, B).Same(GraphEdges::Owned(A, B)));
  }
}

TEST(SeedConnectivity, ComponentsAreNumberedInNodeOrder)
{
  // A chain 0-1-2-3-4-5 with labels 1 1 0 1 0 0, edges listed backwards.
  const std::vector<std::uint8_t> label = { 1, 1, 0, 1, 0, 0 };
  const std::vector<std::int64_t> A = { 4, 3, 2, 1, 0 }, B = { 5, 4, 3, 2, 1 };
  std::int64_t count = 0;
  const std::vector<std::int64_t> id = LabelComponents(label, GraphEdges(A, B), count);
  EXPECT_EQ(count, 4);
  EXPECT_EQ(id, (std::vector<std::int64_t>{ 0, 0, 1, 2, 3, 3 }));
  EXPECT_EQ(ObjectComponentSizes(label, GraphEdges(A, B), { 1, 2, 4, 8, 16, 32 }), (std::vector<double>{ 8, 3 }));
}

TEST(SeedConnectivity, ContactsJoinComponentsOfOneLabel)
{
  // A chain 0-1-2-3-4 with labels 1 0 1 0 1; object seed on node 0, background seed on node 3.
  // Node 2 is a piece of its own along the edges; a contact 0-2 (their voxels touch) joins it to the
  // seeded piece, so Seeded Object keeps it, and node 1 (no seed, off the border) becomes a hole
  // that is filled; node 4 stays unseeded and is dropped.
  const std::vector<std::int64_t> A = { 0, 1, 2, 3 }, B = { 1, 2, 3, 4 };
  const std::vector<std::int64_t> CA = { 0, 1 }, CB = { 2, 4 }; // 1-4: labels differ, no join
  const std::vector<std::uint8_t> hard = { 1, 0, 0, 2, 0 }, border(5, 0);
  std::vector<std::uint8_t> label = { 1, 0, 1, 0, 1 };
  std::int64_t count = 0;
  std::vector<std::int64_t> id = LabelComponents(label, GraphEdges(A, B), count);
  ASSERT_EQ(count, 5);
  JoinContacts(label, GraphEdges(CA, CB), id, count);
  EXPECT_EQ(count, 4);
  EXPECT_EQ(id, (std::vector<std::int64_t>{ 0, 1, 0, 2, 3 }));
  std::vector<std::uint8_t> without = label;
  ApplyConnectivity(Connectivity::SeededObject, without, GraphEdges(A, B), hard, border);
  EXPECT_EQ(without, (std::vector<std::uint8_t>{ 1, 0, 0, 0, 0 }));
  std::vector<double> sizes;
  ApplyConnectivity(Connectivity::SeededObject, label, GraphEdges(A, B), hard, border, NoProgress(), &sizes, {}, nullptr,
    GraphEdges(CA, CB));
  EXPECT_EQ(label, (std::vector<std::uint8_t>{ 1, 1, 1, 0, 0 }));
  EXPECT_EQ(sizes, (std::vector<double>{ 3 })); // one object component
  // ApplyWithContacts asks only for the contacts of the nodes the rule relabels (2 and 4, then 1
  // too) and reaches the same labels.
  std::vector<std::uint8_t> lazy = { 1, 0, 1, 0, 1 };
  std::vector<std::vector<std::int64_t>> asked;
  const ContactsFunction contactsOf = [&](const std::vector<std::int64_t>& nodes) {
    asked.push_back(nodes);
    std::vector<std::int64_t> a, b;
    for (std::size_t c = 0; c < CA.size(); ++c)
      if (std::binary_search(nodes.begin(), nodes.end(), CA[c]) || std::binary_search(nodes.begin(), nodes.end(), CB[c]))
      {
        a.push_back(CA[c]);
        b.push_back(CB[c]);
      }
    return GraphEdges::Owned(a, b);
  };
  // Every run starts from the labels as given, so the components the first run keeps serve the
  // others: they stay those of the given labels, without the contacts' joins.
  const std::vector<std::uint8_t> given = lazy;
  std::vector<LabelComponentsOf> seen;
  ApplyWithContacts(lazy, contactsOf, [&](std::vector<std::uint8_t>& l, const GraphEdges& contacts, LabelComponentsOf& components) {
    EXPECT_EQ(l, given);
    const std::int64_t changed = ApplyConnectivity(
      Connectivity::SeededObject, l, GraphEdges(A, B), hard, border, NoProgress(), nullptr, {}, nullptr, contacts, &components);
    seen.push_back(components);
    return changed;
  });
  EXPECT_EQ(lazy, label);
  EXPECT_EQ(asked, (std::vector<std::vector<std::int64_t>>{ { 2, 4 }, { 1, 2, 4 } }));
  ASSERT_EQ(seen.size(), 3u);
  for (const LabelComponentsOf& c : seen)
  {
    EXPECT_EQ(c.Count, 5);
    EXPECT_EQ(c.Id, (std::vector<std::int64_t>{ 0, 1, 2, 3, 4 }));
    EXPECT_EQ(c.Between.size(), 12u); // the four edges, each between two labels
  }
  // Components kept from other labels are not taken for these: fewer ids than nodes are made afresh.
  LabelComponentsOf stale;
  stale.Id = { 0, 0 };
  std::vector<std::uint8_t> again = given;
  ApplyConnectivity(Connectivity::SeededObject, again, GraphEdges(A, B), hard, border, NoProgress(), nullptr, {}, nullptr,
    GraphEdges(CA, CB), &stale);
  EXPECT_EQ(again, label);
  EXPECT_EQ(stale.Count, 5);
}

TEST(SuperVoxelCut, VoxelContactsAreTheVoxelFacesTheMeshFacesMiss)
{
  // Random Delaunay meshes of a 2D and a 3D grid: the contacts of a set of elements are exactly the
  // element pairs, one of them in the set, of face-adjacent voxels that share no mesh face, ascending.
  for (const int depth : { 1, 14 })
  {
    ImageGeometry g;
    g.Dims = { { 30, 26, depth } };
    std::mt19937 rng(19);
    std::vector<std::array<double, 3>> pts;
    for (int n = 0; n < (depth == 1 ? 120 : 400); ++n)
      pts.push_back({ { std::uniform_real_distribution<double>(0.0, 29.0)(rng), std::uniform_real_distribution<double>(0.0, 25.0)(rng),
        depth == 1 ? 0.0 : std::uniform_real_distribution<double>(0.0, depth - 1.0)(rng) } });
    for (int c = 0; c < (depth == 1 ? 4 : 8); ++c)
      pts.push_back({ { (c & 1) ? 29.0 : 0.0, (c & 2) ? 25.0 : 0.0, (c & 4) ? depth - 1.0 : 0.0 } });
    SimplexMesh mesh;
    ASSERT_TRUE(CGALMeshOfNodes(g, pts, mesh));
    SuperVoxelCutData data;
    ASSERT_TRUE(PrepareVoxelOwners(mesh, data, SerialFor()));
    std::set<std::pair<std::int64_t, std::int64_t>> faces;
    for (std::size_t f = 0; f < mesh.Faces().A.size(); ++f)
      faces.insert({ mesh.Faces().A[f], mesh.Faces().B[f] });
    for (const int every : { 1, 3 })
    {
      std::vector<std::int64_t> elements;
      for (std::int64_t e = 0; e < mesh.NumberOfElements(); e += every)
        elements.push_back(e);
      std::set<std::pair<std::int64_t, std::int64_t>> want;
      for (int k = 0; k < g.Dims[2]; ++k)
        for (int j = 0; j < g.Dims[1]; ++j)
          for (int i = 0; i < g.Dims[0]; ++i)
            for (const std::array<int, 3> d : { std::array<int, 3>{ { 1, 0, 0 } }, { { 0, 1, 0 } }, { { 0, 0, 1 } } })
            {
              if (!g.Contains(i + d[0], j + d[1], k + d[2]))
                continue;
              const std::int64_t a = data.Owner[g.Index(i, j, k)], b = data.Owner[g.Index(i + d[0], j + d[1], k + d[2])];
              const std::pair<std::int64_t, std::int64_t> ab{ std::min(a, b), std::max(a, b) };
              if (a >= 0 && b >= 0 && a != b && !faces.count(ab) && (a % every == 0 || b % every == 0))
                want.insert(ab);
            }
      EXPECT_FALSE(want.empty()) << "depth " << depth; // elements meeting at a vertex or an edge
      std::vector<std::pair<std::int64_t, std::int64_t>> got;
      VoxelContactsOf(mesh, data.Owner, elements).ForEach([&](std::int64_t, std::int64_t a, std::int64_t b) { got.push_back({ a, b }); });
      const std::vector<std::pair<std::int64_t, std::int64_t>> expected(want.begin(), want.end());
      EXPECT_EQ(got, expected) << "depth " << depth << ", every " << every << " elements";
    }
  }
}

TEST(SeedConnectivity, VoxelCutKeepsWhatTheSeedsReachAndFillsHoles)
{
  // Two bright disks; the right one has a dark hole. One object seed, in the left disk.
  ImageGeometry g;
  g.Dims = { { 64, 32, 1 } };
  std::vector<double> values(g.Size());
  auto inside = [](int i, int j, int ci, double r) { return (i - ci) * (i - ci) + (j - 16) * (j - 16) <= r * r; };
  for (int j = 0; j < 32; ++j)
    for (int i = 0; i < 64; ++i)
      values[g.Index(i, j, 0)] = (inside(i, j, 16, 9) || (inside(i, j, 48, 9) && !inside(i, j, 48, 3))) ? 100.0 : 0.0;
  const std::vector<std::int64_t> object = { g.Index(16, 16, 0) }, background = { g.Index(1, 1, 0) };
  auto cut = [&](Connectivity mode) {
    VoxelCutParameters p;
    p.Connectivity = mode;
    p.Lambda = 1.0;
    const CutResult r = VoxelCut(values, g, object, background, p);
    EXPECT_TRUE(r.Error.empty()) << r.Error;
    return r;
  };
  const CutResult off = cut(Connectivity::Off), fill = cut(Connectivity::FillHoles),
                  seeded = cut(Connectivity::SeededObject);
  const std::int64_t left = g.Index(16, 20, 0), ring = g.Index(48, 22, 0), hole = g.Index(48, 16, 0);
  EXPECT_EQ(off.Label[left], 1);
  EXPECT_EQ(off.Label[ring], 1);
  EXPECT_EQ(off.Label[hole], 0);
  EXPECT_EQ(off.ObjectComponentVoxels.size(), 2u);
  EXPECT_EQ(off.ConnectivityChanged, 0);
  EXPECT_EQ(fill.Label[ring], 1);
  EXPECT_EQ(fill.Label[hole], 1);
  EXPECT_EQ(fill.ConnectivityChanged, 29); // the hole: the lattice points within radius 3
  EXPECT_EQ(seeded.Label[left], 1);
  EXPECT_EQ(seeded.Label[ring], 0);
  EXPECT_EQ(seeded.Label[hole], 0);
  ASSERT_EQ(seeded.ObjectComponentVoxels.size(), 1u);
  EXPECT_EQ(seeded.ObjectComponentVoxels[0], off.ObjectComponentVoxels[0]);
  EXPECT_EQ(seeded.Label[background[0]], 0);
}

namespace
{
// Two bright disks of one intensity on a dark background, noise-free; object seeds in the left disk.
struct TwoDisks
{
  ImageGeometry G;
  std::vector<float> Image;
  std::vector<std::int64_t> Object, Background;
  std::int64_t Left, Right;
  TwoDisks()
  {
    G.Dims = { { 72, 36, 1 } };
    Image.resize(G.Size());
    for (int j = 0; j < 36; ++j)
      for (int i = 0; i < 72; ++i)
        Image[G.Index(i, j, 0)] = (std::hypot(i - 18, j - 18) <= 10 || std::hypot(i - 54, j - 18) <= 10) ? 100.f : 10.f;
    Object = { G.Index(18, 18, 0), G.Index(15, 20, 0) };
    Background = { G.Index(2, 2, 0), G.Index(36, 18, 0), G.Index(69, 33, 0) };
    Left = G.Index(20, 14, 0);
    Right = G.Index(54, 18, 0);
  }
};

// A flat image with a little noise (the same intensities inside and out) crossed by a faint ring
// of radius 20: the seed histograms cannot tell object from background, and the boundary term alone
// prefers a small cut around the object seed to the ring's long one.
struct RingImage
{
  ImageGeometry G;
  std::vector<float> Image;
  std::vector<std::int64_t> Object, Background;
  RingImage()
  {
    const int n = 64;
    const double c = n / 2;
    G.Dims = { { n, n, 1 } };
    Image.resize(G.Size());
    std::mt19937 rng(7);
    std::normal_distribution<float> noise(0.f, 1.f);
    const float low = 40.f;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
      {
        const double r = std::hypot(i - c, j - c);
        Image[G.Index(i, j, 0)] = (r >= 20 && r <= 22 ? low : 60.f) + noise(rng);
      }
    Object = { G.Index(n / 2, n / 2, 0) };
    Background = { G.Index(2, 2, 0), G.Index(n - 3, n - 3, 0), G.Index(2, n - 3, 0), G.Index(n - 3, 2, 0) };
  }
  double Radius(std::int64_t v) const { return std::hypot(v % G.Dims[0] - G.Dims[0] / 2, v / G.Dims[0] - G.Dims[0] / 2); }
  bool Inside(std::int64_t v) const { return Radius(v) < 19.5; }
  bool Outside(std::int64_t v) const { return Radius(v) > 22.5; }
};

// A 2D mesh of the image's box on a lattice of spacing 2 (so elements are super-pixels of ~2 pixels),
// with its statistics and prepared cut data.
struct LatticeMesh
{
  SimplexMesh Mesh;
  ElementStatistics Stats;
  std::vector<double> Count;
  SuperVoxelCutData Data;
  bool Make(const ImageGeometry& g, const std::vector<float>& image)
  {
    std::vector<std::array<double, 3>> pts = LatticeNodes(g);
    if (!CGALMeshOfNodes(g, pts, this->Mesh))
      return false;
    this->Stats = ComputeElementStatistics(ElementRasterizer(this->Mesh), image.data(), SerialFor());
    this->Count.assign(this->Stats.PixelCount.begin(), this->Stats.PixelCount.end());
    std::string error;
    return PrepareSuperVoxelCut(this->Mesh, image.data(), this->Data, error, SerialFor());
  }
  // The cut's labels on the pixel grid.
  std::vector<std::uint8_t> Cut(const std::vector<float>& image, const std::vector<std::int64_t>& object,
    const std::vector<std::int64_t>& background, const SuperVoxelCutParameters& par)
  {
    const VoxelValueFunction value = [&](std::int64_t v) { return static_cast<double>(image[v]); };
    const SuperVoxelCutResult r =
      SuperVoxelCut(this->Mesh, this->Data, this->Stats.Mean, this->Count, object, background, value, par, SerialFor());
    EXPECT_TRUE(r.Error.empty()) << r.Error;
    std::vector<std::uint8_t> pixels(this->Mesh.Geometry().Size(), 0);
    if (r.Error.empty())
      VoxelLabels(this->Data.Owner, r.Cut.Label, pixels.data(), SerialFor());
    return pixels;
  }
};
} // namespace

TEST(Task, ObjectKeepsTheSeededDiskAndClassKeepsBoth)
{
  // Both disks look alike: by the histograms either is object. Task Object asks for the one the
  // seeds lie in, Task Class for every object like it; both cuts, default connectivity (From Task).
  const TwoDisks d;
  const std::vector<double> values(d.Image.begin(), d.Image.end());
  LatticeMesh m;
  ASSERT_TRUE(m.Make(d.G, d.Image));
  for (Task task : { Task::Object, Task::Class })
  {
    VoxelCutParameters vp;
    vp.Task = task;
    const CutResult voxel = VoxelCut(values, d.G, d.Object, d.Background, vp);
    ASSERT_TRUE(voxel.Error.empty()) << voxel.Error;
    SuperVoxelCutParameters sp;
    sp.Task = task;
    const std::vector<std::uint8_t> super = m.Cut(d.Image, d.Object, d.Background, sp);
    for (const auto* label : { &voxel.Label, &super })
    {
      EXPECT_EQ((*label)[d.Left], 1);
      EXPECT_EQ((*label)[d.Right], task == Task::Class ? 1 : 0);
    }
    EXPECT_EQ(voxel.ObjectComponentVoxels.size(), task == Task::Class ? 2u : 1u);
  }
}

TEST(Task, TheLocalContrastFindsEveryObjectOfAClassUnderShading)
{
  // Three disks, each 30 above a background that rises from 0 to 43 across the image; seeds by the
  // left disk. The right background is as bright as the seeded disk and the right disk brighter
  // than any seed: the image's values mislabel them, their local contrast (the filters' Intensity
  // From Task for Task Class) does not. Both cuts, Task Class.
  ImageGeometry g;
  g.Dims = { { 72, 36, 1 } };
  std::vector<float> image(g.Size());
  for (int j = 0; j < 36; ++j)
    for (int i = 0; i < 72; ++i)
    {
      const bool disk = std::hypot(i - 12, j - 18) <= 7 || std::hypot(i - 36, j - 18) <= 7 || std::hypot(i - 60, j - 18) <= 7;
      image[g.Index(i, j, 0)] = 0.6f * i + (disk ? 30.f : 0.f);
    }
  const std::vector<std::int64_t> object = { g.Index(12, 18, 0) }, background = { g.Index(2, 2, 0), g.Index(12, 30, 0) };
  const std::vector<std::int64_t> disks = { g.Index(12, 18, 0), g.Index(36, 18, 0), g.Index(60, 18, 0) };
  const std::vector<std::int64_t> around = { g.Index(24, 18, 0), g.Index(48, 18, 0), g.Index(60, 32, 0), g.Index(70, 3, 0) };
  std::vector<float> contrast(image.size());
  LocalContrast(image.data(), contrast.data(), g, SeededCutParameters().ContrastScale, SerialFor());
  for (const auto* values : { &image, &contrast })
  {
    const bool local = values == &contrast;
    VoxelCutParameters vp;
    vp.Task = Task::Class;
    const CutResult voxel = VoxelCut(std::vector<double>(values->begin(), values->end()), g, object, background, vp);
    ASSERT_TRUE(voxel.Error.empty()) << voxel.Error;
    LatticeMesh m;
    ASSERT_TRUE(m.Make(g, *values));
    SuperVoxelCutParameters sp;
    sp.Task = Task::Class;
    const std::vector<std::uint8_t> super = m.Cut(*values, object, background, sp);
    for (const auto* label : { &voxel.Label, &super })
    {
      int right = 0;
      for (std::int64_t v : disks)
        right += (*label)[v] == 1;
      for (std::int64_t v : around)
        right += (*label)[v] == 0;
      if (local)
        EXPECT_EQ(right, 7) << (label == &super ? "elements" : "voxels");
      else
        EXPECT_LT(right, 7) << (label == &super ? "elements" : "voxels");
    }
  }
}

TEST(Task, TheGeodesicTermFindsWhatTheHistogramsCannot)
{
  // Inside and outside the ring have the same intensities: without the spatial term the object
  // shrinks to its seed; with it the object is the ring's inside, on the voxel grid and on the
  // elements. Connectivity off: the term alone decides.
  const RingImage ring;
  const std::vector<double> values(ring.Image.begin(), ring.Image.end());
  LatticeMesh m;
  ASSERT_TRUE(m.Make(ring.G, ring.Image));
  auto score = [&](const std::vector<std::uint8_t>& label) {
    std::int64_t inside = 0, insideObject = 0, outsideObject = 0;
    for (std::int64_t v = 0; v < ring.G.Size(); ++v)
    {
      inside += ring.Inside(v);
      insideObject += ring.Inside(v) && label[v];
      outsideObject += ring.Outside(v) && label[v];
    }
    return std::make_pair(static_cast<double>(insideObject) / inside, outsideObject);
  };
  for (double weight : { 0.0, SeedGeodesicParameters().Weight })
  {
    VoxelCutParameters vp;
    vp.Connectivity = Connectivity::Off;
    vp.Geodesic.Weight = weight;
    const CutResult voxel = VoxelCut(values, ring.G, ring.Object, ring.Background, vp);
    ASSERT_TRUE(voxel.Error.empty()) << voxel.Error;
    SuperVoxelCutParameters sp;
    sp.Connectivity = Connectivity::Off;
    sp.Geodesic.Weight = weight;
    const std::vector<std::uint8_t> super = m.Cut(ring.Image, ring.Object, ring.Background, sp);
    for (const auto* label : { &voxel.Label, &super })
    {
      const auto [filled, leaked] = score(*label);
      if (weight > 0)
      {
        EXPECT_GT(filled, 0.97) << (label == &super ? "elements" : "voxels");
        // Elements of the 2-pixel lattice may straddle the ring's outer edge by a pixel.
        EXPECT_LE(leaked, label == &super ? 8 : 0) << (label == &super ? "elements" : "voxels");
      }
      else
      {
        EXPECT_LT(filled, 0.05) << (label == &super ? "elements" : "voxels");

      }
    }
  }
}

TEST(SeedReach, CostsStartAtReachTimesRAndGrowLinearly)
{
  // A row of 40 voxels 0.5 mm apart: the object seed at x = 5 mm, the background seed at 9 mm, so
  // R = 4 mm. Reach 1, weight 2: nothing within 4 mm of the object seed, 2 x (d / 4 - 1) beyond.
  ImageGeometry g;
  g.Dims = { { 40, 1, 1 } };
  g.Spacing = { { 0.5, 1.0, 1.0 } };
  SeedReachParameters p;
  p.Weight = 2.0;
  p.Reach = 1.0;
  std::vector<double> R, c;
  ASSERT_TRUE(SeedReachCosts(VoxelCentres(g), { 10, 18 }, { 1, 0 }, 2, p, SerialFor(), c, &R));
  ASSERT_EQ(c.size(), 40u);
  EXPECT_EQ(R, (std::vector<double>{ 0.0, 4.0 }));
  for (int i = 0; i < 40; ++i)
  {
    const double d = std::fabs(0.5 * i - 5.0);
    EXPECT_NEAR(c[i], d <= 4.0 ? 0.0 : 2.0 * (d / 4.0 - 1.0), 1e-12) << "voxel " << i;
  }
  // Off, or no background seed to measure R by: no term.
  p.Weight = 0.0;
  EXPECT_FALSE(SeedReachCosts(VoxelCentres(g), { 10, 18 }, { 1, 0 }, 2, p, SerialFor(), c));
  EXPECT_TRUE(c.empty());
  p.Weight = 2.0;
  EXPECT_FALSE(SeedReachCosts(VoxelCentres(g), { 10, 12 }, { 1, 1 }, 2, p, SerialFor(), c));
}

TEST(SeedReach, ThousandsOfSeedsCostWhatTheirNearestDoes)
{
  // 3000 object seeds filling a ball (a brushed region), background seeds on a shell around it.
  // The seeds are thinned to cells of R / 8 before the nodes are measured: each cost lies within
  // Weight x half a cell's diagonal / R of the exact one, and the thinning is the same on every run.
  ImageGeometry g;
  g.Dims = { { 48, 48, 48 } };
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> u(0, 47);
  std::vector<std::int64_t> voxels;
  std::vector<std::uint8_t> labels;
  while (voxels.size() < 3000)
  {
    const int i = u(rng), j = u(rng), k = u(rng);
    if (std::hypot(i - 24.0, j - 24.0, k - 24.0) <= 8.0)
    {
      voxels.push_back(g.Index(i, j, k));
      labels.push_back(1);
    }
  }
  for (int t = 0; t < 40; ++t)
  {
    const double a = 0.157 * t, b = 0.41 * t;
    voxels.push_back(g.Index(int(24 + 15 * std::cos(a) * std::cos(b)), int(24 + 15 * std::sin(a) * std::cos(b)), int(24 + 15 * std::sin(b))));
    labels.push_back(0);
  }
  const SeedReachParameters p;
  std::vector<double> R, c;
  ASSERT_TRUE(SeedReachCosts(VoxelCentres(g), voxels, labels, 2, p, SerialFor(), c, &R));
  ASSERT_EQ(c.size(), static_cast<std::size_t>(g.Size()));
  ASSERT_GT(R[1], 0.0);
  double worst = 0.0, positive = 0.0;
  for (std::int64_t v = 0; v < g.Size(); v += 7)
  {
    const auto x = g.Coordinates(v);
    double d2 = std::numeric_limits<double>::infinity();
    for (std::size_t s = 0; s < voxels.size(); ++s)
      if (labels[s] == 1)
      {
        const auto y = g.Coordinates(voxels[s]);
        d2 = std::min(d2, double((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) + (x[2] - y[2]) * (x[2] - y[2])));
      }
    const double exact = p.Weight * std::max(0.0, std::sqrt(d2) / R[1] - p.Reach);
    worst = std::max(worst, std::fabs(c[v] - exact));
    positive += exact > 0.0;
  }
  EXPECT_GT(positive, 0);
  EXPECT_LE(worst, p.Weight * std::sqrt(3.0) / 16.0 + 1e-12);
  const ParallelFor twoThreads = [](std::int64_t n, std::int64_t, const RangeFunction& body) {
    std::thread t([&] { body(0, n / 2); });
    body(n / 2, n);
    t.join();
  };
  std::vector<double> threaded;
  SeedReachCosts(VoxelCentres(g), voxels, labels, 2, p, twoThreads, threaded);
  EXPECT_EQ(threaded, c);
}

TEST(Task, TheSeedReachStopsALeakAlongABridge)
{
  // Two bright disks joined by a bright bridge; object seeds in the left one, background seeds
  // around it. By appearance the right disk is object, the geodesic term sees no edge along the
  // bridge, and Seeded Object keeps what is joined: without the reach term both cuts take the right
  // disk, with it (default) neither does, and the left disk stays object.
  ImageGeometry g;
  g.Dims = { { 96, 32, 1 } };
  std::vector<float> image(g.Size());
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.f, 3.f);
  for (int j = 0; j < 32; ++j)
    for (int i = 0; i < 96; ++i)
    {
      const bool bright = std::hypot(i - 14, j - 16) <= 7 || std::hypot(i - 80, j - 16) <= 7 || (std::abs(j - 16) <= 2 && i > 14 && i < 80);
      image[g.Index(i, j, 0)] = (bright ? 100.f : 20.f) + noise(rng);
    }
  const std::vector<std::int64_t> object = { g.Index(14, 16, 0), g.Index(11, 14, 0), g.Index(16, 19, 0) };
  std::vector<std::int64_t> background;
  for (double a : { 0.8, 1.57, 2.36, 3.14, 3.93, 4.71, 5.5 })
    background.push_back(g.Index(int(14 + 11 * std::cos(a)), int(16 + 11 * std::sin(a)), 0));
  const std::vector<double> values(image.begin(), image.end());
  LatticeMesh m;
  ASSERT_TRUE(m.Make(g, image));
  for (double weight : { 0.0, SeedReachParameters().Weight })
  {
    VoxelCutParameters vp;
    vp.Reach.Weight = weight;
    const CutResult voxel = VoxelCut(values, g, object, background, vp);
    ASSERT_TRUE(voxel.Error.empty()) << voxel.Error;
    SuperVoxelCutParameters sp;
    sp.Reach.Weight = weight;
    const std::vector<std::uint8_t> super = m.Cut(image, object, background, sp);
    for (const auto* label : { &voxel.Label, &super })
    {
      const char* what = label == &super ? "elements" : "voxels";
      EXPECT_EQ((*label)[g.Index(14, 16, 0)], 1) << what << ", reach weight " << weight;
      EXPECT_EQ((*label)[g.Index(80, 16, 0)], weight > 0 ? 0 : 1) << what << ", reach weight " << weight;
    }
  }
}

// A noisy 40 x 30 grid (a bright disc) as explicit edges with random steps, for the kept-distance tests.
struct NoisyGridGraph
{
  explicit NoisyGridGraph(unsigned seed)
    : g(Grid2(40, 30))
  {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<double> value(g.Size());
    for (int j = 0; j < 30; ++j)
      for (int i = 0; i < 40; ++i)
        value[g.Index(i, j, 0)] = (std::hypot(i - 15, j - 15) < 9 ? 50.0 : 10.0) + 5.0 * u(rng);
    std::vector<std::int64_t> a, b;
    std::vector<double> step;
    GraphEdges::Grid(40, 30, 1).ForEach([&](std::int64_t, std::int64_t p, std::int64_t q) {
      a.push_back(p);
      b.push_back(q);
      step.push_back(0.5 + u(rng));
    });
    edges = GraphEdges::Owned(std::move(a), std::move(b));
    graph.Edges = &edges;
    graph.Value = value;
    graph.Step = step;
  }
  NoisyGridGraph(const NoisyGridGraph&) = delete;
  // Seed kinds per node: 1 on `object`, 2 on `background`.
  std::vector<std::uint8_t> Hard(const std::vector<std::int64_t>& object, const std::vector<std::int64_t>& background) const
  {
    std::vector<std::uint8_t> hard(g.Size(), 0);
    for (std::int64_t v : object)
      hard[v] = 1;
    for (std::int64_t v : background)
      hard[v] = 2;
    return hard;
  }
  ImageGeometry g;
  GraphEdges edges;
  GeodesicGraph graph;
};

TEST(SeedGeodesics, KeptDistancesEqualFreshOnes)
{
  // A noisy 40 x 30 grid as explicit edges with random steps; a chain of seed edits through one
  // cache: seeds added, removed, moved, both kinds at once, nothing changed, a new weight. Every
  // cut's costs (redone where the distances changed) equal those computed afresh (up to the rounding of equal-length paths summed in another order).
  const NoisyGridGraph grid(5);
  const ImageGeometry& g = grid.g;
  const GeodesicGraph& graph = grid.graph;
  const std::vector<std::vector<std::int64_t>> object = { { g.Index(15, 15, 0) }, { g.Index(15, 15, 0), g.Index(12, 18, 0) },
    { g.Index(12, 18, 0) }, { g.Index(13, 18, 0) }, { g.Index(13, 18, 0), g.Index(18, 12, 0) }, { g.Index(13, 18, 0), g.Index(18, 12, 0) },
    { g.Index(16, 16, 0) } };
  const std::vector<std::vector<std::int64_t>> background = { { g.Index(1, 1, 0) }, { g.Index(1, 1, 0) },
    { g.Index(1, 1, 0), g.Index(38, 28, 0) }, { g.Index(38, 28, 0) }, { g.Index(2, 1, 0), g.Index(30, 5, 0) },
    { g.Index(2, 1, 0), g.Index(30, 5, 0) }, { g.Index(39, 29, 0), g.Index(0, 29, 0) } };
  SeedGeodesicCache cache;
  SeedGeodesicParameters p;
  // The costs of every other edit held on: the cache redoes its own copy, never what a holder has.
  SharedArray<double> held;
  std::vector<double> heldWas;
  for (std::size_t edit = 0; edit < object.size(); ++edit)
  {
    // One edit at another weight: every cost is redone.
    p.Weight = edit == 4 ? 0.75 : SeedGeodesicParameters().Weight;
    const std::vector<std::uint8_t> hard = grid.Hard(object[edit], background[edit]);
    SharedArray<double> keptObject, keptBackground, freshObject, freshBackground;
    ASSERT_TRUE(SeedGeodesicCosts(graph, hard, 40.0, p, SerialFor(), keptObject, keptBackground, NoProgress(), &cache));
    EXPECT_EQ(held.Vector(), heldWas) << "edit " << edit;
    if (edit % 2 == 0)
    {
      held = keptObject;
      heldWas = keptObject.Vector();
    }
    ASSERT_TRUE(SeedGeodesicCosts(graph, hard, 40.0, p, SerialFor(), freshObject, freshBackground));
    ASSERT_EQ(keptObject.size(), freshObject.size());
    for (std::size_t v = 0; v < freshObject.size(); ++v)
    {
      ASSERT_NEAR(keptObject[v], freshObject[v], 1e-9) << "edit " << edit << " node " << v;
      ASSERT_NEAR(keptBackground[v], freshBackground[v], 1e-9) << "edit " << edit << " node " << v;
    }
    for (int kind : { 1, 2 })
    {
      const std::vector<double> d = GeodesicDistances(graph, hard, static_cast<std::uint8_t>(kind), 40.0, p.LengthWeight);
      for (std::int64_t v : kind == 1 ? object[edit] : background[edit])
        EXPECT_EQ(d[v], 0.0);
    }
  }
}

TEST(SeedGeodesics, KeptDistancesAtANewScaleEqualFreshOnes)
{
  // The intensity unit moves from cut to cut (a seed sample beyond the histogram's range widens it),
  // with and without seed edits: the kept distances, weighed again from their paths' sums and repaired
  // where an edge now shortens them, equal those computed afresh at that scale.
  const NoisyGridGraph grid(9);
  const ImageGeometry& g = grid.g;
  const GeodesicGraph& graph = grid.graph;
  const double scales[] = { 40.0, 44.0, 44.0, 30.0, 400.0, 4.0, 40.0 };
  const std::vector<std::vector<std::int64_t>> object = { { g.Index(15, 15, 0) }, { g.Index(15, 15, 0) },
    { g.Index(12, 18, 0) }, { g.Index(12, 18, 0), g.Index(18, 12, 0) }, { g.Index(18, 12, 0) }, { g.Index(18, 12, 0) },
    { g.Index(16, 16, 0) } };
  const std::vector<std::vector<std::int64_t>> background = { { g.Index(1, 1, 0) }, { g.Index(1, 1, 0) },
    { g.Index(1, 1, 0), g.Index(38, 28, 0) }, { g.Index(38, 28, 0) }, { g.Index(38, 28, 0) }, { g.Index(2, 1, 0) },
    { g.Index(39, 29, 0), g.Index(0, 29, 0) } };
  SeedGeodesicCache cache;
  for (std::size_t edit = 0; edit < object.size(); ++edit)
  {
    const std::vector<std::uint8_t> hard = grid.Hard(object[edit], background[edit]);
    const auto kept = SeedKindDistances(graph, hard, 2, scales[edit], 0.01, NoProgress(), &cache);
    ASSERT_EQ(kept.size(), 2u);
    for (int kind : { 1, 2 })
    {
      const std::vector<double> fresh = GeodesicDistances(graph, hard, static_cast<std::uint8_t>(kind), scales[edit], 0.01);
      for (std::size_t v = 0; v < fresh.size(); ++v)
        ASSERT_NEAR(kept[kind - 1][v], fresh[v], 1e-12 * (1.0 + fresh[v])) << "edit " << edit << " kind " << kind << " node " << v;
    }
  }
}

TEST(SeedGeodesics, DijkstraMatchesBellmanFord)
{
  // A random graph with random values, steps and seeds, and a plateau where many paths tie: the
  // heap's distances equal those of Bellman-Ford relaxation (no heap at all).
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::int64_t n = 600;
  std::vector<std::int64_t> a, b;
  std::vector<double> step;
  for (int e = 0; e < 2400; ++e)
  {
    const std::int64_t p = rng() % n, q = rng() % n;
    if (p != q)
    {
      a.push_back(p);
      b.push_back(q);
      step.push_back(e % 3 ? 1.0 : 0.5 + 2.0 * u(rng));
    }
  }
  std::vector<double> value(n);
  for (std::int64_t p = 0; p < n; ++p)
    value[p] = p < 200 ? 3.0 : 10.0 * u(rng);
  const GraphEdges edges(a, b);
  GeodesicGraph graph;
  graph.Edges = &edges;
  graph.Value = value;
  graph.Step = step;
  std::vector<std::uint8_t> hard(n, 0);
  for (int s = 0; s < 6; ++s)
    hard[rng() % n] = 1;
  const std::vector<double> d = GeodesicDistances(graph, hard, 1, 7.0, 0.01);
  std::vector<double> r(n, std::numeric_limits<double>::infinity());
  for (std::int64_t p = 0; p < n; ++p)
    if (hard[p] == 1)
      r[p] = 0.0;
  for (bool changed = true; changed;)
  {
    changed = false;
    for (std::size_t e = 0; e < a.size(); ++e)
      for (const auto& [p, q] : { std::make_pair(a[e], b[e]), std::make_pair(b[e], a[e]) })
      {
        // The adjacency holds each step as a float.
        const double c = r[p] + std::fabs(value[q] - value[p]) / 7.0 + 0.01 * static_cast<double>(static_cast<float>(step[e]));
        if (c < r[q])
        {
          r[q] = c;
          changed = true;
        }
      }
  }
  ASSERT_EQ(d.size(), static_cast<std::size_t>(n));
  for (std::int64_t p = 0; p < n; ++p)
    if (std::isinf(r[p]))
      EXPECT_TRUE(std::isinf(d[p])) << "node " << p;
    else
      EXPECT_NEAR(d[p], r[p], 1e-12 * (1.0 + r[p])) << "node " << p;
}

TEST(SeedGeodesics, DistancesAddTheStepsAndTheLength)
{
  // A chain 0 - 1 - 2 - 3 of values 0, 0, 10, 10 (range 10): each step costs |dI| / 10 plus the
  // length weight per voxel of step; the spatial costs favour the seed's side.
  const std::vector<std::int64_t> a = { 0, 1, 2 }, b = { 1, 2, 3 };
  const GraphEdges edges(a, b);
  const std::vector<double> value = { 0, 0, 10, 10 }, step = { 1, 2, 1 };
  GeodesicGraph graph;
  graph.Edges = &edges;
  graph.Value = value;
  graph.Step = step;
  const std::vector<std::uint8_t> hard = { 1, 0, 0, 2 };
  const std::vector<double> d = GeodesicDistances(graph, hard, 1, 10.0, 0.1);
  ASSERT_EQ(d.size(), 4u);
  EXPECT_DOUBLE_EQ(d[0], 0.0);
  EXPECT_DOUBLE_EQ(d[1], 0.1);
  EXPECT_DOUBLE_EQ(d[2], 0.1 + 1.0 + 0.2);
  EXPECT_DOUBLE_EQ(d[3], 1.3 + 0.1);
  SharedArray<double> costObject, costBackground;
  SeedGeodesicParameters p;
  ASSERT_TRUE(SeedGeodesicCosts(graph, hard, 10.0, p, SerialFor(), costObject, costBackground));
  ASSERT_EQ(costObject.size(), 4u);
  EXPECT_LT(costObject[1], costBackground[1]);
  EXPECT_GT(costObject[2], costBackground[2]);
  // Without a background seed there is no term.
  ASSERT_TRUE(SeedGeodesicCosts(graph, { 1, 0, 0, 0 }, 10.0, p, SerialFor(), costObject, costBackground));
  EXPECT_TRUE(costObject.empty());
  p.Weight = -1;
  EXPECT_FALSE(ValidateParameters(p).empty());
}

namespace
{
// A random mesh of a 40 x 40 image whose elements take the majority label of `truth` (one disk, or
// two: labels 1 and 2), with its owner map.
struct RefinementCase
{
  ImageGeometry G = Grid2(40, 40);
  SimplexMesh Mesh;
  SuperVoxelCutData Data;
  std::vector<std::uint8_t> Truth, Element;
  std::vector<float> Value;

  explicit RefinementCase(bool twoObjects)
  {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 39.0);
    std::vector<std::array<double, 3>> pts;
    for (int n = 0; n < 160; ++n)
      pts.push_back({ { u(rng), u(rng), 0.0 } });
    for (int c = 0; c < 4; ++c)
      pts.push_back({ { (c & 1) ? 39.0 : 0.0, (c & 2) ? 39.0 : 0.0, 0.0 } });
    EXPECT_TRUE(CGALMeshOfNodes(G, pts, Mesh));
    std::string error;
    EXPECT_TRUE(PrepareSuperVoxelCut(Mesh, static_cast<const double*>(nullptr), Data, error, SerialFor()));
    Truth.assign(G.Size(), 0);
    Value.assign(G.Size(), 10.f);
    for (int j = 0; j < 40; ++j)
      for (int i = 0; i < 40; ++i)
      {
        const std::int64_t v = G.Index(i, j, 0);
        if (std::hypot(i - 14.3, j - 15.1) <= 8.6)
          Truth[v] = 1;
        else if (twoObjects && std::hypot(i - 29.2, j - 27.7) <= 6.4)
          Truth[v] = 2;
        Value[v] = 10.f + 40.f * Truth[v];
      }
    const std::int64_t m = Mesh.NumberOfElements();
    std::vector<std::array<int, 3>> votes(m, { { 0, 0, 0 } });
    for (std::int64_t v = 0; v < G.Size(); ++v)
      ++votes[Data.Owner[v]][Truth[v]];
    Element.resize(m);
    for (std::int64_t e = 0; e < m; ++e)
      Element[e] = static_cast<std::uint8_t>(std::max_element(votes[e].begin(), votes[e].end()) - votes[e].begin());
  }
  // The elements with a face neighbour of another label.
  std::vector<std::uint8_t> Boundary() const
  {
    const FaceAdjacency& f = *Mesh.SharedFaces();
    std::vector<std::uint8_t> b(Element.size(), 0);
    for (std::size_t k = 0; k < f.A.size(); ++k)
      if (Element[f.A[k]] != Element[f.B[k]])
        b[f.A[k]] = b[f.B[k]] = 1;
    return b;
  }
  VoxelRefinementProblem Problem(int labels)
  {
    VoxelRefinementProblem p;
    p.Mesh = &Mesh;
    p.Owner = &Data.Owner;
    p.Label = &Element;
    p.Labels = labels;
    p.Cost = [this, labels](std::int64_t v, std::int64_t, double* c) {
      for (int l = 0; l < labels; ++l)
        c[l] = l == Truth[v] ? 0.0 : 1.0;
    };
    p.Distance2 = [this](std::int64_t a, std::int64_t b) { return double(Value[a] - Value[b]) * (Value[a] - Value[b]); };
    p.Sigma = 1e-3; // a weight of 1 between equal values, 0 across the objects' edges
    return p;
  }
  std::vector<std::uint8_t> Labelled(const VoxelRefinementResult& r) const
  {
    std::vector<std::uint8_t> out(G.Size());
    VoxelLabels(Data.Owner, Element, out.data(), SerialFor());
    ApplyRefinement(r, out.data());
    return out;
  }
};
} // namespace

TEST(VoxelRefinement, TheBandFollowsTheVoxelsAndTheRestKeepsItsElements)
{
  // Costs that favour each voxel's true label and weights that vanish across the objects' edges:
  // every voxel of an element along the cut takes its true label, every other voxel its element's,
  // the seeds' elements keep theirs, and any split of the loops gives the same voxels.
  for (const bool two : { false, true })
  {
    RefinementCase c(two);
    const std::vector<std::uint8_t> boundary = c.Boundary();
    VoxelRefinementProblem p = c.Problem(two ? 3 : 2);
    std::int64_t fixed = -1;
    for (std::size_t e = 0; e < boundary.size() && fixed < 0; ++e)
      fixed = boundary[e] ? static_cast<std::int64_t>(e) : -1;
    p.Fixed.assign(c.Element.size(), 0);
    p.Fixed[fixed] = 1;
    const VoxelRefinementResult serial = RefineOnVoxels(p);
    ASSERT_TRUE(serial.Error.empty()) << serial.Error;
    const std::vector<std::uint8_t> labels = c.Labelled(serial);
    std::int64_t band = 0, changed = 0;
    for (std::int64_t v = 0; v < c.G.Size(); ++v)
    {
      const std::int32_t e = c.Data.Owner[v];
      const bool refined = boundary[e] && e != fixed;
      band += refined;
      changed += refined && c.Truth[v] != c.Element[e];
      EXPECT_EQ(labels[v], refined ? c.Truth[v] : c.Element[e]) << "voxel " << v;
    }
    EXPECT_EQ(serial.BandVoxels, band);
    EXPECT_EQ(static_cast<std::int64_t>(serial.Voxel.size()), changed);
    EXPECT_GT(changed, 20);
    p.Parallel = Chunked;
    VoxelRefinementCache cache;
    for (int run = 0; run < 2; ++run) // the second with the cache's kept buffers
    {
      const VoxelRefinementResult split = RefineOnVoxels(p, NoProgress(), &cache);
      EXPECT_EQ(split.Voxel, serial.Voxel);
      EXPECT_EQ(split.Label, serial.Label);
      EXPECT_EQ(split.Energy, serial.Energy);
    }
  }
}

TEST(VoxelRefinement, VoxelGridSigmaIsTheRootMeanSquareOfFaceDifferences)
{
  // Two channels on a grid of more than one 2^16-voxel slab, 3D and 2D: sigma against a direct
  // sum over every face pair, and the same value for any split of the slabs.
  for (const std::array<int, 3> dims : { std::array<int, 3>{ { 50, 45, 33 } }, std::array<int, 3>{ { 301, 257, 1 } } })
  {
    ImageGeometry g;
    g.Dims = dims;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-5.f, 5.f);
    std::vector<float> values(2 * g.Size());
    for (float& x : values)
      x = u(rng);
    double sum = 0.0, pairs = 0.0;
    for (int k = 0; k < dims[2]; ++k)
      for (int j = 0; j < dims[1]; ++j)
        for (int i = 0; i < dims[0]; ++i)
          for (const std::array<int, 3> d : { std::array<int, 3>{ { 1, 0, 0 } }, std::array<int, 3>{ { 0, 1, 0 } },
                 std::array<int, 3>{ { 0, 0, 1 } } })
          {
            if (!g.Contains(i + d[0], j + d[1], k + d[2]))
              continue;
            const std::int64_t a = g.Index(i, j, k), b = g.Index(i + d[0], j + d[1], k + d[2]);
            for (int c = 0; c < 2; ++c)
            {
              const double x = double(values[2 * a + c]) - double(values[2 * b + c]);
              sum += x * x;
            }
            pairs += 1.0;
          }
    const double sigma = VoxelGridSigma(values.data(), 2, g, SerialFor());
    EXPECT_NEAR(sigma, std::sqrt(sum / pairs), 1e-12 * sigma);
    EXPECT_EQ(VoxelGridSigma(values.data(), 2, g, Chunked), sigma);
  }
}

TEST(VoxelRefinement, TwoLabelComponentsCutApartAsOne)
{
  // Grids with random costs and weights: apart (each its own graph's component), the labels equal
  // those of the same grids joined by edges of weight 0 (one component, one graph), and the energy
  // is the minimum, found by enumeration on the smallest.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const int side : { 2, 3, 12 })
  {
    const int grids = side == 2 ? 3 : 4, per = side * side, n = grids * per;
    std::vector<std::int64_t> a, b;
    for (int g = 0; g < grids; ++g)
      for (int j = 0; j < side; ++j)
        for (int i = 0; i < side; ++i)
        {
          const int v = g * per + j * side + i;
          if (i + 1 < side)
            a.push_back(v), b.push_back(v + 1);
          if (j + 1 < side)
            a.push_back(v), b.push_back(v + side);
        }
    PottsProblem apart;
    apart.Nodes = n;
    apart.Labels = 2;
    for (std::size_t e = 0; e < a.size(); ++e)
      apart.Weight.push_back(0.2 + u(rng));
    for (int i = 0; i < 2 * n; ++i)
      apart.Cost.push_back(2.0 * u(rng));
    const GraphEdges apartEdges = GraphEdges::Owned(a, b);
    apart.Edges = &apartEdges;
    PottsProblem joined = apart;
    for (int g = 0; g + 1 < grids; ++g)
      a.push_back(g * per), b.push_back((g + 1) * per), joined.Weight.push_back(0.0);
    const GraphEdges joinedEdges = GraphEdges::Owned(a, b);
    joined.Edges = &joinedEdges;
    std::vector<std::uint8_t> split, one, chunked;
    const double energy = BinaryPottsCut(apart, split, SerialFor());
    EXPECT_NEAR(BinaryPottsCut(joined, one, SerialFor()), energy, 1e-12 * energy);
    EXPECT_EQ(split, one);
    EXPECT_EQ(BinaryPottsCut(apart, chunked, Chunked), energy);
    EXPECT_EQ(chunked, split);
    const auto ones = std::count(split.begin(), split.end(), 1);
    EXPECT_GT(ones, 0);
    EXPECT_LT(ones, n);
    if (n > 16)
      continue;
    double best = 1e300;
    for (int code = 0; code < (1 << n); ++code)
    {
      double sum = 0.0;
      for (int i = 0; i < n; ++i)
        sum += apart.Cost[2 * i + ((code >> i) & 1)];
      apartEdges.ForEach([&](std::int64_t e, std::int64_t p, std::int64_t q) {
        sum += ((code >> p) & 1) != ((code >> q) & 1) ? apart.Weight[e] : 0.0;
      });
      best = std::min(best, sum);
    }
    EXPECT_NEAR(energy, best, 1e-12 * best);
  }
}

TEST(VoxelRefinement, AKeptDomainGivesWhatAFreshRefinementGives)
{
  // One cache through a chain of edits, each against a fresh refinement: the elements' labels change
  // (the band leaves the kept domain, which grows, or comes back inside it), the voxels' costs change
  // (the kept flow runs on), a seed's element is held, the rings shrink (voxels of the domain held),
  // sigma changes (new weights); noisy costs make pieces for the connectivity rule. One object (one
  // graph, which grows) and two (the band's components on two graphs, built again), and three labels
  // (alpha-expansion with the held voxels as hard nodes, on kept faces); some after an aborted
  // refinement. Each result labels every voxel as the fresh one does, with the same band, energy and
  // components' changes.
  for (const auto& [labels, two] : { std::make_pair(2, false), std::make_pair(2, true), std::make_pair(3, true) })
  {
    RefinementCase c(two);
    for (std::uint8_t& l : c.Element)
      l = labels == 2 && l ? 1 : l;
    const std::vector<std::uint8_t> truthElement = c.Element;
    const FaceAdjacency& faces = *c.Mesh.SharedFaces();
    // Every third object element beside the background goes: a bite into the object.
    std::vector<std::uint8_t> bitten = c.Element;
    for (std::size_t k = 0; k < faces.A.size(); ++k)
      for (const auto& [a, b] : { std::make_pair(faces.A[k], faces.B[k]), std::make_pair(faces.B[k], faces.A[k]) })
        if (truthElement[a] != 0 && truthElement[b] == 0 && a % 3 == 0)
          bitten[a] = 0;
    ASSERT_NE(bitten, truthElement);
    std::vector<std::int64_t> component(c.Element.size(), 0);
    int edit = 0;
    VoxelRefinementProblem p = c.Problem(labels);
    // Weights that vary along each object too (0.3-1 within, 0 across its edge).
    p.Distance2 = [&c](std::int64_t a, std::int64_t b) {
      const double d = double(c.Value[a]) - double(c.Value[b]);
      const std::uint64_t h =
        (static_cast<std::uint64_t>(std::min(a, b)) * 7919u + static_cast<std::uint64_t>(std::max(a, b)) * 104729u) % 97u;
      return d * d + 0.2 * static_cast<double>(h);
    };
    p.Sigma = 3.0;
    p.Rings = 2;
    p.Connectivity = Connectivity::FillHoles;
    p.Component = labels == 2 ? &component : nullptr;
    p.Cost = [&](std::int64_t v, std::int64_t, double* cost) {
      // A deterministic noise per voxel and edit, against the truth on a few voxels.
      const std::uint64_t h = (static_cast<std::uint64_t>(v) * 2654435761u + static_cast<std::uint64_t>(edit) * 40503u) % 1000u;
      if (labels == 2)
      {
        const bool object = (c.Truth[v] != 0) != (h < 150);
        cost[0] = object ? 1.5 + 0.001 * static_cast<double>(h) : 0.001 * static_cast<double>(h % 7);
        cost[1] = !object ? 1.5 + 0.0005 * static_cast<double>(h) : 0.001 * static_cast<double>(h % 5);
        return;
      }
      const int own = h < 150 ? (c.Truth[v] + 1 + static_cast<int>(h % 2)) % 3 : c.Truth[v];
      for (int l = 0; l < 3; ++l)
        cost[l] = l == own ? 0.001 * static_cast<double>(h % (5 + l)) : 1.5 + 0.0005 * static_cast<double>((h + 97 * l) % 1000u);
    };
    VoxelRefinementCache cache;
    const std::vector<std::function<void()>> edits = {
      [] {},                                          // the first refinement builds the domain
      [&] { c.Element = bitten; },                    // the band leaves it
      [&] { c.Element = truthElement; },              // and comes back inside
      [&] { ++edit; },                                // new costs on the kept graph
      [&] { c.Element = bitten; ++edit; },            // inside again, both changed
      [&] { p.Fixed.assign(c.Element.size(), 0); p.Fixed[faces.A[0]] = 1; p.Fixed[faces.B[0]] = 1; },
      [&] { p.Rings = 1; c.Element = truthElement; }, // a narrower band: domain voxels held
      [&] { p.Sigma = 2.0; },                         // new weights: a new domain
      [&] { p.Sigma = 1.0; },                         // the same domain built again, new weights
      [&] { ++edit; },                                // (two objects: two graphs' flows run on)
      [&] { p.Rings = 2; ++edit; },                   // a wider band leaves it
      [&] { c.Element = bitten; ++edit; },
      [&] { p.Rings = 3; },
    };
    int relabelled = 0;
    for (std::size_t step = 0; step < edits.size(); ++step)
    {
      edits[step]();
      for (std::size_t e = 0; e < component.size(); ++e)
        component[e] = c.Element[e] ? 0 : -1;
      // Before every third step an abort, after the domain (0.2) or the costs (0.4), leaves the cache
      // fit for the next (which then builds the domain again); the other steps grow or keep it.
      const double stop = step % 2 ? 0.15 : 0.3;
      if (step % 3 == 1)
        EXPECT_TRUE(RefineOnVoxels(p, [stop](double f) { return f < stop; }, &cache).Aborted);
      // With three labels, also an abort within the expansion (its moves report progress).
      if (labels == 3 && step % 5 == 4)
        EXPECT_TRUE(RefineOnVoxels(p, [](double f) { return f < 0.7; }, &cache).Aborted);
      const VoxelRefinementResult kept = RefineOnVoxels(p, NoProgress(), &cache);
      const VoxelRefinementResult fresh = RefineOnVoxels(p);
      ASSERT_TRUE(kept.Error.empty() && fresh.Error.empty()) << kept.Error << fresh.Error;
      EXPECT_EQ(c.Labelled(kept), c.Labelled(fresh)) << "step " << step << ", " << labels << " labels" << (two ? ", two objects" : "");
      EXPECT_EQ(kept.BandVoxels, fresh.BandVoxels) << "step " << step;
      EXPECT_EQ(kept.Voxel.size(), fresh.Voxel.size()) << "step " << step;
      EXPECT_NEAR(kept.Energy, fresh.Energy, 1e-9 * (1.0 + fresh.Energy)) << "step " << step;
      EXPECT_EQ(kept.ComponentChange, fresh.ComponentChange) << "step " << step;
      relabelled += fresh.Voxel.size() > 10;
    }
    EXPECT_EQ(relabelled, static_cast<int>(edits.size()));
  }
}

TEST(VoxelRefinement, ExpansionLowersTheBandsEnergy)
{
  // Three labels with weights between equal values: the refined voxels' energy (their costs and a
  // weight per face between two labels, the voxels outside the band held) is no higher than the
  // elements' labels give, and labels only move where the band lies.
  RefinementCase c(true);
  VoxelRefinementProblem p = c.Problem(3);
  p.Sigma = 20.0;
  const VoxelRefinementResult r = RefineOnVoxels(p);
  ASSERT_TRUE(r.Error.empty()) << r.Error;
  const std::vector<std::uint8_t> boundary = c.Boundary();
  std::vector<std::uint8_t> before(c.G.Size());
  VoxelLabels(c.Data.Owner, c.Element, before.data(), SerialFor());
  const std::vector<std::uint8_t> after = c.Labelled(r);
  auto energy = [&](const std::vector<std::uint8_t>& x) {
    double sum = 0.0;
    for (std::int64_t v = 0; v < c.G.Size(); ++v)
    {
      if (!boundary[c.Data.Owner[v]])
        continue;
      sum += x[v] == c.Truth[v] ? 0.0 : 1.0;
      const std::array<int, 3> ijk = c.G.Coordinates(v);
      for (const std::array<int, 2>& d : { std::array<int, 2>{ { 1, 0 } }, std::array<int, 2>{ { -1, 0 } },
             std::array<int, 2>{ { 0, 1 } }, std::array<int, 2>{ { 0, -1 } } })
      {
        if (!c.G.Contains(ijk[0] + d[0], ijk[1] + d[1], 0))
          continue;
        const std::int64_t u = c.G.Index(ijk[0] + d[0], ijk[1] + d[1], 0);
        const bool inner = boundary[c.Data.Owner[u]];
        if ((inner && u < v) || x[u] == x[v])
          continue; // each pair within the band once
        const double d2 = p.Distance2(u, v);
        sum += d2 == 0.0 ? 1.0 : std::exp(-d2 / (2.0 * p.Sigma * p.Sigma));
      }
    }
    return sum;
  };
  EXPECT_LT(energy(after), energy(before));
  EXPECT_NEAR(energy(after), r.Energy, 1e-9 * (1.0 + r.Energy));
  for (std::int64_t v = 0; v < c.G.Size(); ++v)
    if (!boundary[c.Data.Owner[v]])
      EXPECT_EQ(after[v], before[v]);
}

TEST(VoxelRefinement, PiecesTheirLabelDoesNotReachTakeTheirNeighbours)
{
  // A voxel of the background side made cheap as object, away from the object: Off keeps it as a
  // speck of object, Seeded Object and Fill Holes' rule for the background give it back.
  RefinementCase c(false);
  const std::vector<std::uint8_t> boundary = c.Boundary();
  std::int64_t speck = -1;
  for (std::int64_t v = 0; v < c.G.Size() && speck < 0; ++v)
  {
    const std::array<int, 3> ijk = c.G.Coordinates(v);
    bool alone = boundary[c.Data.Owner[v]] && c.Truth[v] == 0 && ijk[0] > 0 && ijk[1] > 0 && ijk[0] < 39 && ijk[1] < 39;
    for (const std::int64_t u : { v - 1, v + 1, v - 40, v + 40 })
      alone = alone && c.Truth[u] == 0 && (boundary[c.Data.Owner[u]] || c.Element[c.Data.Owner[u]] == 0);
    speck = alone ? v : -1;
  }
  ASSERT_GE(speck, 0);
  c.Value[speck] = 1000.f; // no weight to its neighbours
  VoxelRefinementProblem p = c.Problem(2);
  p.Cost = [&](std::int64_t v, std::int64_t, double* x) {
    const int want = v == speck ? 1 : c.Truth[v];
    x[0] = want == 0 ? 0.0 : 1.0;
    x[1] = want == 1 ? 0.0 : 1.0;
  };
  p.Connectivity = Connectivity::Off;
  EXPECT_EQ(c.Labelled(RefineOnVoxels(p))[speck], 1);
  p.Connectivity = Connectivity::SeededObject;
  EXPECT_EQ(c.Labelled(RefineOnVoxels(p))[speck], 0);
  p.Connectivity = Connectivity::FillHoles; // an object piece is kept
  EXPECT_EQ(c.Labelled(RefineOnVoxels(p))[speck], 1);
}

TEST(VoxelRefinement, BadInputsAreASentence)
{
  RefinementCase c(false);
  VoxelRefinementProblem p = c.Problem(2);
  p.Sigma = 0.0;
  EXPECT_FALSE(RefineOnVoxels(p).Error.empty());
  p = c.Problem(2);
  std::vector<std::uint8_t> shorter(c.Element.begin(), c.Element.end() - 1);
  p.Label = &shorter;
  EXPECT_FALSE(RefineOnVoxels(p).Error.empty());
  p = c.Problem(2);
  p.Rings = 0;
  EXPECT_FALSE(RefineOnVoxels(p).Error.empty());
}
