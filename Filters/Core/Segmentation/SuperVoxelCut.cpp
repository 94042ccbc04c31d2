#include "SuperVoxelCut.h"
#include "ElementRasterizer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

namespace featuremesh
{
bool SeedConstraints(const VoxelOwnerMap& owner, const std::vector<std::int64_t>& objectVoxels,
  const std::vector<std::int64_t>& backgroundVoxels, const char* node, std::vector<std::uint8_t>& hard,
  std::string& error)
{
  for (std::int64_t v : objectVoxels)
  {
    if (owner[v] < 0)
    {
      error = "an object seed lies outside the mesh.";
      return false;
    }
    hard[owner[v]] = 1;
  }
  for (std::int64_t v : backgroundVoxels)
  {
    if (owner[v] < 0)
    {
      error = "a background seed lies outside the mesh.";
      return false;
    }
    if (hard[owner[v]] == 1)
    {
      error = std::string(node) + " " + std::to_string(owner[v]) +
        " holds both an object and a background seed; move one of them.";
      return false;
    }
    hard[owner[v]] = 2;
  }
  return true;
}

void SeedNeighbourhoodSamples(const VoxelValueFunction& value, const ImageGeometry& g,
  const std::vector<std::int64_t>& seedVoxels, double radius, std::vector<double>& samples)
{
  for (std::int64_t v : seedVoxels)
  {
    ForEachVoxelWithin(g, v, radius, [&](std::int64_t u) { samples.push_back(value(u)); });
  }
}

// Few seeds list their balls' voxels and sort them; many (a scribble) mark them in a mask over the
// balls' bounding box.
std::vector<std::int64_t> SeedElementVoxels(const ImageGeometry& g, const std::int32_t* owner,
  const std::vector<std::uint8_t>& hard, std::vector<std::int64_t> seedVoxels, std::uint8_t kind, double radius)
{
  std::vector<std::int64_t> voxels;
  std::sort(seedVoxels.begin(), seedVoxels.end());
  seedVoxels.erase(std::unique(seedVoxels.begin(), seedVoxels.end()), seedVoxels.end());
  if (seedVoxels.empty())
  {
    return voxels;
  }
  const int r = static_cast<int>(std::floor(radius));
  std::array<int, 3> lo = g.Dims, hi{ { -1, -1, -1 } };
  for (std::int64_t v : seedVoxels)
  {
    const std::array<int, 3> ijk = g.Coordinates(v);
    for (int a = 0; a < 3; ++a)
    {
      const int reach = a == 2 && g.Is2D() ? 0 : r;
      lo[a] = std::min(lo[a], std::max(0, ijk[a] - reach));
      hi[a] = std::max(hi[a], std::min(g.Dims[a] - 1, ijk[a] + reach));
    }
  }
  const std::int64_t nx = hi[0] - lo[0] + 1, ny = hi[1] - lo[1] + 1, nz = hi[2] - lo[2] + 1;
  const std::int64_t box = nx * ny * nz;
  const std::int64_t ball = static_cast<std::int64_t>(2 * r + 1) * (2 * r + 1) * (g.Is2D() ? 1 : 2 * r + 1);
  auto take = [&](std::int64_t u) { return owner[u] >= 0 && hard[owner[u]] == kind; };
  if (static_cast<std::int64_t>(seedVoxels.size()) * ball <= box / 16)
  {
    for (std::int64_t v : seedVoxels)
    {
      ForEachVoxelWithin(g, v, radius, [&](std::int64_t u) {
        if (take(u))
        {
          voxels.push_back(u);
        }
      });
    }
    std::sort(voxels.begin(), voxels.end());
    voxels.erase(std::unique(voxels.begin(), voxels.end()), voxels.end());
    return voxels;
  }
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(box), 0);
  for (std::int64_t v : seedVoxels)
  {
    ForEachVoxelWithin(g, v, radius, [&](std::int64_t u) {
      const std::array<int, 3> c = g.Coordinates(u);
      mask[static_cast<std::size_t>(((c[2] - lo[2]) * ny + (c[1] - lo[1])) * nx + (c[0] - lo[0]))] = 1;
    });
  }
  for (std::int64_t k = 0; k < nz; ++k)
  {
    for (std::int64_t j = 0; j < ny; ++j)
    {
      const std::uint8_t* row = mask.data() + (k * ny + j) * nx;
      const std::int64_t first = g.Index(lo[0], lo[1] + static_cast<int>(j), lo[2] + static_cast<int>(k));
      for (std::int64_t i = 0; i < nx; ++i)
      {
        if (row[i] && take(first + i))
        {
          voxels.push_back(first + i);
        }
      }
    }
  }
  return voxels;
}

std::vector<std::uint8_t> BorderVoxels(const ImageGeometry& g)
{
  std::vector<std::uint8_t> border(g.Size(), 0);
  for (int k = 0; k < g.Dims[2]; ++k)
    for (int j = 0; j < g.Dims[1]; ++j)
      for (int i = 0; i < g.Dims[0]; ++i)
      {
        border[g.Index(i, j, k)] = i == 0 || j == 0 || i + 1 == g.Dims[0] || j + 1 == g.Dims[1] ||
          (!g.Is2D() && (k == 0 || k + 1 == g.Dims[2]));
      }
  return border;
}

namespace
{
// Appends the values of the voxels `owner` gives to element e, in raster order.
void ElementVoxelValues(const SimplexMesh& mesh, const VoxelOwnerMap& owner, const NodeVoxelValues& voxels,
  std::int64_t e, std::vector<double>& out)
{
  ForEachElementVoxel(mesh, owner.data(), e, [&](std::int64_t v) { out.push_back(voxels.Value(v)); });
}
} // namespace

std::vector<double> CentreDistances(const SimplexMesh& mesh, const FaceAdjacency& adj)
{
  const std::int64_t m = mesh.NumberOfElements();
  const int k = mesh.VerticesPerCell();
  std::vector<std::array<double, 3>> centre(m, { { 0.0, 0.0, 0.0 } });
  for (std::int64_t e = 0; e < m; ++e)
  {
    for (int v = 0; v < k; ++v)
    {
      const auto& q = mesh.Points()[mesh.Cell(e)[v]];
      for (int a = 0; a < 3; ++a)
      {
        centre[e][a] += q[a] / k;
      }
    }
  }
  std::vector<double> step(adj.A.size());
  for (std::size_t f = 0; f < step.size(); ++f)
  {
    const auto& a = centre[adj.A[f]];
    const auto& b = centre[adj.B[f]];
    step[f] = std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
  }
  return step;
}

std::vector<double> ContactInVoxelFaces(const SimplexMesh& mesh, bool scale)
{
  const FaceAdjacency& adj = mesh.Faces();
  const auto& s = mesh.Geometry().Spacing;
  const double sx = std::fabs(s[0]), sy = std::fabs(s[1]), sz = std::fabs(s[2]);
  const double unit = mesh.VerticesPerCell() == 3 ? 0.5 * (sx + sy) : std::pow(sx * sy * sz, 2.0 / 3.0);
  std::vector<double> contact(adj.Measure.size(), 1.0);
  if (scale)
  {
    for (std::size_t e = 0; e < contact.size(); ++e)
    {
      contact[e] = adj.Measure[e] / unit;
    }
  }
  return contact;
}

SharedArray<double> MeshCentreSteps(const SimplexMesh& mesh, const SuperVoxelCutData& data)
{
  const FaceAdjacency& adj = mesh.Faces();
  return data.CentreSteps.size() == adj.A.size() ? data.CentreSteps : SharedArray<double>(CentreDistances(mesh, adj));
}

namespace
{
// The binary cut's reach term: the object seeds are label 1, the background seeds label 0.
SharedArray<double> BinaryReach(const NodeCentres& nodes, const std::vector<std::int64_t>& objectVoxels,
  const std::vector<std::int64_t>& backgroundVoxels, const SeedReachParameters& p, const ParallelFor& parallel,
  double& distance)
{
  std::vector<std::int64_t> voxels(objectVoxels);
  voxels.insert(voxels.end(), backgroundVoxels.begin(), backgroundVoxels.end());
  std::vector<std::uint8_t> labels(objectVoxels.size(), 1);
  labels.resize(voxels.size(), 0);
  std::vector<double> object, reach;
  const bool any = SeedReachCosts(nodes, voxels, labels, 2, p, parallel, object, &reach);
  distance = any ? reach[1] : 0.0;
  return any ? SharedArray<double>(std::move(object)) : SharedArray<double>();
}
} // namespace

NodeCentres MeshCentres(const SimplexMesh& mesh, const SuperVoxelCutData& data)
{
  return static_cast<std::int64_t>(data.Centres.Centre.size()) == mesh.NumberOfElements() ? data.Centres
                                                                                           : ElementCentres(mesh);
}

SharedArray<double> MeshContact(const SimplexMesh& mesh, const SuperVoxelCutData& data, bool scale)
{
  return scale && data.Contact.size() == mesh.Faces().A.size() ? data.Contact
                                                                 : SharedArray<double>(ContactInVoxelFaces(mesh, scale));
}

GraphEdges VoxelContactsOf(const SimplexMesh& mesh, const VoxelOwnerMap& owner, const std::vector<std::int64_t>& elements)
{
  const ImageGeometry& g = mesh.Geometry();
  if (static_cast<std::int64_t>(owner.size()) != g.Size() || mesh.NumberOfElements() >= (std::int64_t(1) << 31))
  {
    return GraphEdges::Owned({}, {});
  }
  const auto key = [](std::int64_t a, std::int64_t b) {
    return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint64_t>(std::max(a, b));
  };
  // Two elements of a conforming mesh share a face when they share all but one vertex.
  const int vpc = mesh.VerticesPerCell();
  const auto shareFace = [&](std::int64_t a, std::int64_t c) {
    int common = 0;
    for (int i = 0; i < vpc; ++i)
    {
      common += static_cast<int>(std::count(mesh.Cell(c), mesh.Cell(c) + vpc, mesh.Cell(a)[i]));
    }
    return common == vpc - 1;
  };
  const std::array<std::int64_t, 3> stride{ { 1, g.Dims[0], g.SliceStride() } };
  std::vector<std::uint64_t> found;
  for (const std::int64_t e : elements)
  {
    ForEachVoxelOf(mesh, owner, e, [&](std::int64_t v) {
      const std::array<int, 3> at = g.Coordinates(v);
      for (int a = 0; a < 3; ++a)
      {
        for (const int s : { -1, 1 })
        {
          if (at[a] + s < 0 || at[a] + s >= g.Dims[a])
          {
            continue;
          }
          const std::int32_t c = owner[v + s * stride[a]];
          if (c >= 0 && c != e && !shareFace(e, c))
          {
            found.push_back(key(e, c));
          }
        }
      }
    });
  }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  std::vector<std::int64_t> a(found.size()), b(found.size());
  for (std::size_t e = 0; e < found.size(); ++e)
  {
    a[e] = static_cast<std::int64_t>(found[e] >> 32);
    b[e] = static_cast<std::int64_t>(found[e] & 0xffffffffu);
  }
  return GraphEdges::Owned(std::move(a), std::move(b));
}

bool PrepareVoxelOwners(const SimplexMesh& mesh, SuperVoxelCutData& data, const ParallelFor& parallel,
  const ProgressFunction& progress)
{
  if (static_cast<std::int64_t>(data.Owner.size()) != mesh.Geometry().Size())
  {
    data.Owner.Own(VoxelOwners(ElementRasterizer(mesh), parallel, progress));
  }
  data.CentreSteps = CentreDistances(mesh, mesh.Faces());
  data.Contact = ContactInVoxelFaces(mesh, true);
  data.Centres = ElementCentres(mesh);
  return !data.Owner.empty();
}

SuperVoxelCutResult SuperVoxelCut(const SimplexMesh& mesh, const SuperVoxelCutData& data, const SharedArray<double>& mean,
  const SharedArray<double>& voxelCount, const std::vector<std::int64_t>& objectVoxels,
  const std::vector<std::int64_t>& backgroundVoxels, const VoxelValueFunction& voxelValue,
  const SuperVoxelCutParameters& parameters, const ParallelFor& parallel, const ProgressFunction& progress,
  MaxFlowCache* flow)
{
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  SuperVoxelCutResult result;
  const std::int64_t m = mesh.NumberOfElements();
  const VoxelOwnerMap& owner = data.Owner;
  if (static_cast<std::int64_t>(owner.size()) != mesh.Geometry().Size() ||
    (data.HasVoxelValues() && data.Voxels.Nodes != m))
  {
    result.Error = "the voxel owners do not match the mesh's image.";
    return result;
  }

  CutProblem pr;
  double reach = 0.0;
  pr.Hard.assign(m, 0);
  if (!SeedConstraints(owner, objectVoxels, backgroundVoxels, "element", pr.Hard, result.Error))
  {
    return result;
  }
  pr.Value = mean;
  pr.Size = voxelCount;
  pr.Parallel = parallel;
  // Shared with the mesh: a kept flow holds the same lists instead of a copy.
  const std::shared_ptr<const FaceAdjacency> faces = mesh.SharedFaces();
  const FaceAdjacency& adj = *faces;
  pr.Edges = GraphEdges(adj.A, adj.B, faces);
  pr.Contact = MeshContact(mesh, data, parameters.ScaleByContact);
  // Seed histograms: the voxels of the seed elements when the values are there, else their means
  // weighted by their voxel counts.
  if (data.HasVoxelValues())
  {
    const NodeVoxelValues& grouped = data.Voxels;
    if (SamplesSeedElements(parameters) && parameters.SeedElementRadius > 0.0 && voxelValue)
    {
      for (const std::uint8_t kind : { 1, 2 })
      {
        std::vector<double>& samples = kind == 1 ? pr.ObjectSamples : pr.BackgroundSamples;
        for (const std::int64_t u : SeedElementVoxels(mesh.Geometry(), owner.data(), pr.Hard,
               kind == 1 ? objectVoxels : backgroundVoxels, kind, parameters.SeedElementRadius))
        {
          samples.push_back(voxelValue(u));
        }
      }
    }
    else if (SamplesSeedElements(parameters) || !voxelValue)
    {
      for (std::int64_t e = 0; e < m; ++e)
      {
        if (pr.Hard[e])
        {
          std::vector<double>& samples = pr.Hard[e] == 1 ? pr.ObjectSamples : pr.BackgroundSamples;
          if (grouped.Sorted())
          {
            grouped.Visit([&](const auto* all) { samples.insert(samples.end(), all + grouped.Offset[e], all + grouped.Offset[e + 1]); });
          }
          else
          {
            const std::size_t first = samples.size();
            ElementVoxelValues(mesh, owner, grouped, e, samples);
            std::sort(samples.begin() + static_cast<std::ptrdiff_t>(first), samples.end());
          }
        }
      }
    }
    else
    {
      SeedNeighbourhoodSamples(voxelValue, mesh.Geometry(), objectVoxels, parameters.SeedRadius, pr.ObjectSamples);
      SeedNeighbourhoodSamples(voxelValue, mesh.Geometry(), backgroundVoxels, parameters.SeedRadius, pr.BackgroundSamples);
    }
    if (parameters.VoxelRegionTerm)
    {
      pr.NodeVoxels = &grouped;
    }
  }
  else
  {
    for (std::int64_t c = 0; c < m; ++c)
    {
      if (pr.Hard[c])
      {
        (pr.Hard[c] == 1 ? pr.ObjectSamples : pr.BackgroundSamples).push_back(pr.Value[c]);
        (pr.Hard[c] == 1 ? pr.ObjectWeights : pr.BackgroundWeights).push_back(std::max(1.0, pr.Size[c]));
      }
    }
  }
  if (parameters.Task == Task::Object)
  {
    pr.Geodesic = parameters.Geodesic;
    pr.Step = MeshCentreSteps(mesh, data);
    pr.Reach = BinaryReach(MeshCentres(mesh, data), objectVoxels, backgroundVoxels, parameters.Reach, parallel, reach);
  }
  result.SetupSeconds = std::chrono::duration<double>(Clock::now() - t0).count();
  result.Cut = BoykovJollyCut(pr, parameters, progress, flow);
  result.Cut.ReachDistance = reach;
  result.Aborted = result.Cut.Aborted;
  if (!result.Cut.Error.empty() || result.Aborted)
  {
    result.Error = result.Cut.Error;
    return result;
  }
  std::vector<std::uint8_t> border(m, 0);
  for (std::int64_t e : adj.HullElement)
  {
    border[e] = 1;
  }
  const Connectivity rule = ConnectivityFor(parameters.Connectivity, parameters.Task);
  result.Cut.ConnectivityChanged = ApplyWithContacts(result.Cut.Label,
    [&](const std::vector<std::int64_t>& elements) { return VoxelContactsOf(mesh, owner, elements); },
    [&](std::vector<std::uint8_t>& label, const GraphEdges& contacts, LabelComponentsOf& components) {
      return ApplyConnectivity(rule, label, pr.Edges, pr.Hard, border, NoProgress(), &result.Cut.ObjectComponentVoxels,
        voxelCount.Vector(), &result.ObjectComponent, contacts, &components);
    });
  result.BoundaryFaces = LabelBoundaryFaces(mesh, adj, result.Cut.Label);
  return result;
}

void VoxelLabels(const VoxelOwnerMap& owner, const std::vector<std::uint8_t>& label, std::uint8_t* out,
  const ParallelFor& parallel)
{
  parallel(static_cast<std::int64_t>(owner.size()), 65536, [&](std::int64_t b, std::int64_t e) {
    for (std::int64_t v = b; v < e; ++v)
    {
      out[v] = owner[v] >= 0 ? label[owner[v]] : 0;
    }
  });
}

bool PatchVoxelLabels(const SimplexMesh& mesh, const VoxelOwnerMap& owner, const std::vector<std::uint8_t>& before,
  const std::vector<std::uint8_t>& label, std::uint8_t* out, const ParallelFor& parallel)
{
  const std::int64_t m = mesh.NumberOfElements();
  const ImageGeometry& g = mesh.Geometry();
  if (static_cast<std::int64_t>(before.size()) != m || static_cast<std::int64_t>(label.size()) != m ||
    static_cast<std::int64_t>(owner.size()) != g.Size())
  {
    return false;
  }
  // Each changed element's voxel box: the voxel centres its index-space bounds hold, one voxel of
  // slack either side.
  struct Box
  {
    std::int64_t Element;
    std::array<int, 3> Low, High;
  };
  std::vector<Box> boxes;
  std::int64_t scanned = 0;
  const int vpc = mesh.VerticesPerCell();
  for (std::int64_t e = 0; e < m; ++e)
  {
    if (before[e] == label[e])
    {
      continue;
    }
    Box b{ e, {}, {} };
    const std::int64_t* cell = mesh.Cell(e);
    for (int c = 0; c < 3; ++c)
    {
      double lo = mesh.Points()[cell[0]][c], hi = lo;
      for (int k = 1; k < vpc; ++k)
      {
        lo = std::min(lo, mesh.Points()[cell[k]][c]);
        hi = std::max(hi, mesh.Points()[cell[k]][c]);
      }
      b.Low[c] = std::max(0, static_cast<int>(std::floor(lo)) - 1);
      b.High[c] = std::min(g.Dims[c] - 1, static_cast<int>(std::ceil(hi)) + 1);
    }
    std::int64_t voxels = 1;
    for (int c = 0; c < 3; ++c)
    {
      voxels *= std::max(0, b.High[c] - b.Low[c] + 1); // none for an element beside the image
    }
    scanned += voxels;
    if (scanned > g.Size() / 4)
    {
      return false;
    }
    boxes.push_back(b);
  }
  // Elements own disjoint voxels: the writes of two elements never meet.
  parallel(static_cast<std::int64_t>(boxes.size()), 256, [&](std::int64_t first, std::int64_t last) {
    for (std::int64_t i = first; i < last; ++i)
    {
      const Box& b = boxes[i];
      const std::int32_t e = static_cast<std::int32_t>(b.Element);
      for (int z = b.Low[2]; z <= b.High[2]; ++z)
      {
        for (int y = b.Low[1]; y <= b.High[1]; ++y)
        {
          const std::int64_t row = g.Index(0, y, z);
          for (int x = b.Low[0]; x <= b.High[0]; ++x)
          {
            if (owner[row + x] == e)
            {
              out[row + x] = label[b.Element];
            }
          }
        }
      }
    }
  });
  return true;
}

std::string ValidateParameters(const SeededCutParameters& p)
{
  std::string error = ValidateParameters(static_cast<const BoykovJollyParameters&>(p));
  if (error.empty() && !(p.SeedRadius >= 0.0 && p.SeedRadius <= 50.0))
  {
    error = "the seed radius must lie in [0, 50] voxels.";
  }
  if (error.empty() && p.Task != Task::Object && p.Task != Task::Class)
  {
    error = "the task must be 0 (Object) or 1 (Class).";
  }
  if (error.empty() && !(static_cast<int>(p.Connectivity) >= 0 && static_cast<int>(p.Connectivity) <= 3))
  {
    error = "the connectivity must be 0 (Off), 1 (Fill Holes), 2 (Seeded Object) or 3 (From Task).";
  }
  if (error.empty() && !(static_cast<int>(p.Intensity) >= 0 && static_cast<int>(p.Intensity) <= 2))
  {
    error = "the intensity must be 0 (Image), 1 (Local Contrast) or 2 (From Task).";
  }
  if (error.empty() && !(p.ContrastScale >= 0.5 && p.ContrastScale <= 100.0))
  {
    error = "the contrast scale must lie in [0.5, 100] voxels.";
  }
  if (error.empty())
  {
    error = ValidateParameters(p.Reach);
  }
  if (error.empty())
  {
    error = ValidateParameters(p.Geodesic);
  }
  return error;
}

std::string ValidateParameters(const SuperVoxelCutParameters& p)
{
  std::string error = ValidateParameters(static_cast<const SeededCutParameters&>(p));
  if (error.empty() && !(p.SeedElementRadius >= 0.0 && p.SeedElementRadius <= 50.0))
  {
    error = "the seed element radius must lie in [0, 50] voxels.";
  }
  if (error.empty() && !(p.VoxelRefinement >= 0 && p.VoxelRefinement <= 8))
  {
    error = "the voxel refinement must lie in [0, 8] rings of elements.";
  }
  return error;
}

CutResult VoxelCut(std::vector<double> values, const ImageGeometry& g,
  const std::vector<std::int64_t>& objectVoxels, const std::vector<std::int64_t>& backgroundVoxels,
  const VoxelCutParameters& parameters, const ProgressFunction& progress, const ParallelFor& parallel)
{
  CutResult failed;
  const std::int64_t n = g.Size();
  double reach = 0.0;
  CutProblem pr;
  pr.Parallel = parallel;
  pr.Value = std::move(values);
  pr.Hard.assign(n, 0);
  for (std::int64_t v : objectVoxels)
  {
    pr.Hard[v] = 1;
  }
  for (std::int64_t v : backgroundVoxels)
  {
    if (pr.Hard[v] == 1)
    {
      failed.Error = "a voxel is seeded both as object and as background; move one of the seeds.";
      return failed;
    }
    pr.Hard[v] = 2;
  }
  const VoxelValueFunction value = [&pr](std::int64_t v) { return pr.Value[v]; };
  SeedNeighbourhoodSamples(value, g, objectVoxels, parameters.SeedRadius, pr.ObjectSamples);
  SeedNeighbourhoodSamples(value, g, backgroundVoxels, parameters.SeedRadius, pr.BackgroundSamples);
  if (!progress(0.1))
  {
    failed.Aborted = true;
    return failed;
  }
  // Voxels sharing a face: enumerated, not stored.
  pr.Edges = GraphEdges::Grid(g.Dims[0], g.Dims[1], g.Dims[2]);
  if (parameters.Task == Task::Object)
  {
    pr.Geodesic = parameters.Geodesic;
    pr.Reach = BinaryReach(VoxelCentres(g), objectVoxels, backgroundVoxels, parameters.Reach, parallel, reach);
  }
  // Size and Contact stay empty: 1 for every voxel and every voxel face.
  CutResult cut = BoykovJollyCut(pr, parameters, SubProgress(progress, 0.1, 0.95));
  cut.ReachDistance = reach;
  if (!cut.Error.empty() || cut.Aborted || !progress(0.95))
  {
    cut.Aborted = cut.Error.empty();
    return cut;
  }
  const std::vector<std::uint8_t> border = BorderVoxels(g);
  cut.ConnectivityChanged = ApplyConnectivity(ConnectivityFor(parameters.Connectivity, parameters.Task), cut.Label, pr.Edges, pr.Hard, border,
    SubProgress(progress, 0.95, 1.0), &cut.ObjectComponentVoxels);
  if (cut.ConnectivityChanged < 0)
  {
    CutResult aborted;
    aborted.Aborted = true;
    return aborted;
  }
  return cut;
}
} // namespace featuremesh
