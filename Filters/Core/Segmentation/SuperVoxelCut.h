// Stage 4 without VTK: the Boykov-Jolly cut (BoykovJolly.h) on the elements of a mesh (super-voxel
// cut) and on the voxel grid (voxel cut), from seed voxels. The two build their graphs here and
// share the energy, so a comparison of the two compares the graphs, nothing else.
#pragma once

#include "BoykovJolly.h"
#include "ElementRasterizer.h"
#include "Parallel.h"
#include "SeedConnectivity.h"
#include "SeedReach.h"
#include "SimplexMesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace featuremesh
{
// What the cut reads at each voxel.
enum class CutIntensity : int
{
  // The image's values.
  Image = 0,
  // Their local contrast (LocalContrast, ImageFilters.h): shading and each object's own brightness
  // drop out, so a class of objects of varying brightness (nuclei, cells, vessels) shares one histogram.
  LocalContrast = 1,
  // Local Contrast for Task Class, the image's values for Task Object.
  FromTask = 2,
};

// What both cuts share besides the energy.
struct SeededCutParameters : BoykovJollyParameters
{
  // What the seeds ask for: the one object they lie in, or every object like them.
  featuremesh::Task Task = featuremesh::Task::Object;
  // The rule applied to the cut's labels (SeedConnectivity.h); FromTask: Seeded Object for Task
  // Object, Fill Holes for Task Class.
  featuremesh::Connectivity Connectivity = featuremesh::Connectivity::FromTask;
  // The seeds' spatial term (SeedGeodesics.h), applied for Task Object: an object that looks like
  // the seeded one elsewhere is not the one asked for. Task Class has none.
  SeedGeodesicParameters Geodesic;
  // The seeds' reach (SeedReach.h), for Task Object too: the object stays within reach of its
  // seeds, where the geodesic term fades (docs/cut.md).
  SeedReachParameters Reach;
  // Radius (voxels) of the neighbourhood of each seed whose voxels build the histograms.
  double SeedRadius = 2.0;
  // What the cut reads at each voxel, and the Gaussian scale (voxels) of the local contrast's
  // neighbourhood: intensity changes over more than it count as shading (docs/cut.md).
  CutIntensity Intensity = CutIntensity::FromTask;
  double ContrastScale = 8.0;
};

// Whether the cut reads the local contrast (FromTask resolved).
inline bool UsesLocalContrast(const SeededCutParameters& p)
{
  return p.Intensity == CutIntensity::LocalContrast || (p.Intensity == CutIntensity::FromTask && p.Task == Task::Class);
}

struct SuperVoxelCutParameters : SeededCutParameters
{
  // Boundary weights scaled by the shared edge length / face area in voxel-face units: the
  // element energy is then the voxel cut's energy on super-voxels, so lambda and sigma mean the
  // same in both.
  bool ScaleByContact = true;
  // With voxel values given: an element's region cost is the sum of its voxels' costs rather than
  // its voxel count times the cost of its mean.
  bool VoxelRegionTerm = true;
  // The histograms' samples: the voxels of the elements that hold seeds (true), or those within
  // SeedRadius of each seed voxel, as the voxel cut (false, default: on seeds drawn anew the seed
  // elements made the worse model, their unequal sizes weighing some seeds over others, docs/cut.md).
  // The local contrast always takes the latter, and so do labelled seeds of several objects or channels.
  bool SampleSeedElements = false;
  // With SampleSeedElements: only the seed elements' voxels within this distance (voxels) of a seed
  // of their kind; 0 every voxel of theirs. The Delaunay mesh's long seed elements reach past the
  // object; the smoothed mesh's compact ones mostly lie within it (docs/cut.md).
  double SeedElementRadius = 5.0;
  // Rings of elements along the cut whose voxels are labelled again by the voxel cut's energy
  // (VoxelRefinement.h): 1 the elements with a neighbour of another label, each more ring their
  // neighbours too (2 by default: docs/cut.md); 0 off. The label image then follows the voxels
  // where an element straddles the boundary; the elements keep their labels.
  int VoxelRefinement = 2;
};

// Whether the histograms sample the seed elements' voxels: SampleSeedElements, not with the local contrast.
inline bool SamplesSeedElements(const SuperVoxelCutParameters& p)
{
  return p.SampleSeedElements && !UsesLocalContrast(p);
}

struct VoxelCutParameters : SeededCutParameters
{
};

struct SuperVoxelCutResult
{
  CutResult Cut;
  // LabelBoundaryFaces of the labels, and each element's index among the object components of
  // Cut.ObjectComponentVoxels (-1 background).
  std::vector<std::int64_t> BoundaryFaces, ObjectComponent;
  double SetupSeconds = 0.0;
  std::string Error;
  bool Aborted = false;
};

// Hard constraints (0 free, 1 object, 2 background) of the nodes owning the seed voxels; false
// with a sentence when a seed voxel has no owner (-1) or a node holds seeds of both kinds.
// `node` names a node in messages ("element", "voxel").
bool SeedConstraints(const VoxelOwnerMap& owner, const std::vector<std::int64_t>& objectVoxels,
  const std::vector<std::int64_t>& backgroundVoxels, const char* node, std::vector<std::uint8_t>& hard,
  std::string& error);

// Distance in voxels between the centroids of the two elements of each interior face: the step
// of a geodesic across it.
std::vector<double> CentreDistances(const SimplexMesh& mesh, const FaceAdjacency& adj);

// Contact of each interior face of the mesh in voxel faces: a 2D edge in pixel lengths, a 3D face in
// voxel-face areas; 1 everywhere when `scale` is off.
std::vector<double> ContactInVoxelFaces(const SimplexMesh& mesh, bool scale);

// What the super-voxel cut keeps of a mesh and its image across cuts: it depends on them alone, so
// a seed edit or a parameter change reuses it.
struct SuperVoxelCutData
{
  // The element owning each voxel (-1 none).
  VoxelOwnerMap Owner;
  // The voxel values with their elements (viewed); empty without voxel values.
  NodeVoxelValues Voxels;
  // CentreDistances of the mesh, for the geodesic spatial term (made by PrepareVoxelOwners); the
  // cuts' problems and caches share it.
  SharedArray<double> CentreSteps;
  // ContactInVoxelFaces of the mesh, scaled (made by PrepareVoxelOwners), shared the same way.
  SharedArray<double> Contact;
  // The elements' centroids in frame coordinates, for the seeds' reach (made by PrepareVoxelOwners).
  NodeCentres Centres;
  bool HasVoxelValues() const { return !this->Voxels.Empty(); }
};

// The mesh's centre steps and contacts as `data` keeps them, else made afresh (a mesh prepared
// without them): what both cuts put in their problems.
SharedArray<double> MeshCentreSteps(const SimplexMesh& mesh, const SuperVoxelCutData& data);
SharedArray<double> MeshContact(const SimplexMesh& mesh, const SuperVoxelCutData& data, bool scale);
NodeCentres MeshCentres(const SimplexMesh& mesh, const SuperVoxelCutData& data);

// The element pairs, one of them in `elements` (ascending), whose voxels share a voxel face while
// the elements share no face (they meet at an edge or a vertex): the label image joins them where
// the mesh's faces do not, so the connectivity rules count them as connected (ApplyWithContacts).
// Each pair once (A < B), ascending.
GraphEdges VoxelContactsOf(const SimplexMesh& mesh, const VoxelOwnerMap& owner, const std::vector<std::int64_t>& elements);

// The element owning each voxel into `data.Owner`, by rasterising the mesh unless it already holds
// them (stage 2's, say). False when progress asked to abort.
bool PrepareVoxelOwners(const SimplexMesh& mesh, SuperVoxelCutData& data, const ParallelFor& parallel,
  const ProgressFunction& progress = NoProgress());

// The owners, and `voxelValues` (optional, one per voxel of the mesh's image, in the image's own type)
// grouped by element (BoykovJolly.h, sorted up to `sortedLimit` voxels); `keep` (optional) keeps the
// values alive. False with a sentence for a bad value, without one when progress asked to abort.
template <typename T>
bool PrepareSuperVoxelCut(const SimplexMesh& mesh, const T* voxelValues, SuperVoxelCutData& data, std::string& error,
  const ParallelFor& parallel, const ProgressFunction& progress = NoProgress(), std::shared_ptr<const void> keep = nullptr,
  std::int64_t sortedLimit = SortedVoxelLimit)
{
  return PrepareVoxelOwners(mesh, data, parallel, SubProgress(progress, 0.0, voxelValues ? 0.6 : 1.0)) &&
    (!voxelValues ||
      GroupVoxelValues(data.Owner.data(), voxelValues, mesh.Geometry().Size(), mesh.NumberOfElements(), data.Voxels,
        error, parallel, SubProgress(progress, 0.6, 1.0), std::move(keep), sortedLimit));
}

// A voxel's value by index (the image, however it is stored).
using VoxelValueFunction = std::function<double(std::int64_t)>;

// The super-voxel cut of a prepared mesh. `mean` and `voxelCount` per element (stage 2's
// MeanIntensity and PixelCount). With voxel values prepared, the seed histograms take the voxels of
// the seed elements (or, without SampleSeedElements, those near each seed voxel, read through
// `voxelValue`) and the voxel region term is available. `flow` (optional) keeps the max-flow for
// the next cut of the same mesh.
SuperVoxelCutResult SuperVoxelCut(const SimplexMesh& mesh, const SuperVoxelCutData& data, const SharedArray<double>& mean,
  const SharedArray<double>& voxelCount, const std::vector<std::int64_t>& objectVoxels,
  const std::vector<std::int64_t>& backgroundVoxels, const VoxelValueFunction& voxelValue,
  const SuperVoxelCutParameters& parameters, const ParallelFor& parallel, const ProgressFunction& progress = NoProgress(),
  MaxFlowCache* flow = nullptr);

// The labels of the elements on the voxel grid, into `out` (one per owner; 0 where no element owns a voxel).
void VoxelLabels(const VoxelOwnerMap& owner, const std::vector<std::uint8_t>& label, std::uint8_t* out,
  const ParallelFor& parallel);

// VoxelLabels by difference: `out` holds the voxel labels of `before`; the voxels of the elements
// whose label differs in `label` are rewritten, each element's searched within its bounding box.
// False, `out` untouched, when the labels' sizes differ or the boxes hold over a quarter of the image
// (then VoxelLabels is cheaper).
bool PatchVoxelLabels(const SimplexMesh& mesh, const VoxelOwnerMap& owner, const std::vector<std::uint8_t>& before,
  const std::vector<std::uint8_t>& label, std::uint8_t* out, const ParallelFor& parallel);

// The voxel cut on the 4-/6-connected grid, each neighbour pair one voxel face; `values` (one per
// voxel) is moved in, not copied. Its loops run on `parallel` as the super-voxel cut's do (the
// same labels for any thread count).
CutResult VoxelCut(std::vector<double> values, const ImageGeometry& geometry,
  const std::vector<std::int64_t>& objectVoxels, const std::vector<std::int64_t>& backgroundVoxels,
  const VoxelCutParameters& parameters, const ProgressFunction& progress = NoProgress(),
  const ParallelFor& parallel = SerialFor());

// Empty when usable, else a sentence.
std::string ValidateParameters(const SeededCutParameters& p);
std::string ValidateParameters(const SuperVoxelCutParameters& p);

// The voxels within `radius` (voxels) of a seed voxel that `owner` gives to an element whose `hard`
// is `kind` (the elements holding seeds of that kind), in raster order: what the seed elements
// sample with SeedElementRadius.
std::vector<std::int64_t> SeedElementVoxels(const ImageGeometry& g, const std::int32_t* owner,
  const std::vector<std::uint8_t>& hard, std::vector<std::int64_t> seedVoxels, std::uint8_t kind, double radius);

// f(voxel) for each voxel within `radius` (voxels, index space) of voxel v, the image's own in 2D.
template <typename F>
void ForEachVoxelWithin(const ImageGeometry& g, std::int64_t v, double radius, F&& f)
{
  const int r = static_cast<int>(std::floor(radius));
  const int rk = g.Is2D() ? 0 : r;
  const int k = static_cast<int>(v / g.SliceStride());
  const int j = static_cast<int>((v % g.SliceStride()) / g.Dims[0]);
  const int i = static_cast<int>(v % g.Dims[0]);
  for (int dk = -rk; dk <= rk; ++dk)
    for (int dj = -r; dj <= r; ++dj)
      for (int di = -r; di <= r; ++di)
      {
        if (di * di + dj * dj + dk * dk <= radius * radius && g.Contains(i + di, j + dj, k + dk))
        {
          f(g.Index(i + di, j + dj, k + dk));
        }
      }
}

// f(voxel) for each voxel `owner` (one per voxel) gives to element e, in raster order: a scan of the
// element's box widened by a voxel (the map may come from the points before a world round trip,
// within rounding).
template <typename F>
void ForEachElementVoxel(const SimplexMesh& mesh, const std::int32_t* owner, std::int64_t e, F&& f)
{
  const ImageGeometry& g = mesh.Geometry();
  std::array<int, 3> lo = g.Dims, hi{ { -1, -1, -1 } };
  for (int k = 0; k < mesh.VerticesPerCell(); ++k)
  {
    const auto& q = mesh.Points()[mesh.Cell(e)[k]];
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::min(lo[a], std::max(0, static_cast<int>(std::floor(q[a])) - 1));
      hi[a] = std::max(hi[a], std::min(g.Dims[a] - 1, static_cast<int>(std::ceil(q[a])) + 1));
    }
  }
  for (int z = lo[2]; z <= hi[2]; ++z)
  {
    for (int y = lo[1]; y <= hi[1]; ++y)
    {
      for (std::int64_t v = g.Index(lo[0], y, z), end = v + (hi[0] - lo[0]) + 1; v < end; ++v)
      {
        if (owner[v] == e)
        {
          f(v);
        }
      }
    }
  }
}

// 1 for the voxels on the image's border (its box faces), else 0.
std::vector<std::uint8_t> BorderVoxels(const ImageGeometry& g);

// Appends to `samples` the values of the voxels within `radius` (voxels) of each seed voxel.
void SeedNeighbourhoodSamples(const VoxelValueFunction& value, const ImageGeometry& geometry,
  const std::vector<std::int64_t>& seedVoxels, double radius, std::vector<double>& samples);
} // namespace featuremesh
