// VTK plumbing shared by the FeatureMesh filters: thread backend, parallel-for and progress
// adapters for the VTK-free core, the image checks every stage makes the same way, and the
// adapters between VTK data and the core's ImageGeometry and SimplexMesh.
#ifndef vtkFeatureMeshUtilities_h
#define vtkFeatureMeshUtilities_h

#include "ElementRasterizer.h"
#include "ImageGeometry.h"
#include "Parallel.h"
#include "SimplexMesh.h"

#include "vtkIntArray.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"

#include <cstdint>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

class vtkAlgorithm;
class vtkDataObject;
class vtkDataArray;
class vtkImageData;
class vtkInformation;
class vtkInformationIntegerRequestKey;
class vtkInformationVector;
class vtkPointData;
class vtkPoints;
class vtkPointSet;
class vtkPolyData;
class vtkUnstructuredGrid;

namespace featuremesh
{
struct LabelledSeeds;
struct MultiLabelResult;

// Reports an exception that escaped a filter's body as its error (out of memory, or a library's
// failure); returns 0.
int ReportException(vtkAlgorithm* algorithm, const char* filter, const std::exception_ptr& error);

// A property's setter where the filter's Core parameter differs in name or type (an enumeration,
// an unsigned or 64-bit count): the parameter takes the value, and the filter is Modified when it changed.
template <typename Parameter, typename Value>
void SetParameter(vtkObject* filter, Parameter& parameter, Value value)
{
  const Parameter v = static_cast<Parameter>(value);
  if (parameter != v)
  {
    parameter = v;
    filter->Modified();
  }
}

// What a run depends on: the newest modification of the filter or of anything upstream, and the
// requested time step (a time series changes the data, not the modification times).
struct RunState
{
  vtkMTimeType Modified = 0;
  double TimeStep = 0.0;
  bool operator==(const RunState& other) const
  {
    return this->Modified == other.Modified && this->TimeStep == other.TimeStep;
  }
};
RunState PipelineState(vtkAlgorithm* algorithm, vtkInformationVector* outputVector);

// Puts the field array ContractVersion (Contract.h) first in the field data of every output.
void PutContractVersionFirst(vtkInformationVector* outputVector);

// Runs a filter's body (returning int): on the STDThread SMP backend when VTK runs its Sequential
// default and the user chose none with VTK_SMP_BACKEND_IN_USE (the host's backend is left as it
// was), and with every exception caught at the VTK boundary. A failure is not run (and reported)
// again until the filter or its inputs change: ParaView updates every output port, and a failed
// run leaves them all out of date. `failedAt` and `failedAtTime` are the filter's record of it.
template <typename Body>
int RunFilter(vtkAlgorithm* algorithm, const char* filter, vtkInformationVector* outputVector,
  vtkMTimeType& failedAt, double& failedAtTime, Body&& body)
{
  const RunState state = PipelineState(algorithm, outputVector);
  if (failedAt && state == RunState{ failedAt, failedAtTime })
  {
    return 0;
  }
  int result = 0;
  try
  {
    if (std::getenv("VTK_SMP_BACKEND_IN_USE") || std::string(vtkSMPTools::GetBackend()) != "Sequential")
    {
      result = body();
    }
    else
    {
      vtkSMPTools::LocalScope(vtkSMPTools::Config(std::string("STDThread")), [&]() { result = body(); });
    }
  }
  catch (...)
  {
    result = ReportException(algorithm, filter, std::current_exception());
  }
  if (result)
  {
    PutContractVersionFirst(outputVector);
  }
  failedAt = result ? 0 : state.Modified;
  failedAtTime = state.TimeStep;
  return result;
}

// True on a parallel process that holds no piece of the data: the input is empty and this is not
// piece 0. The filters then succeed with empty outputs and say nothing (the whole image is on one
// process; see docs/CONTRACT.md).
bool IsEmptyPiece(vtkInformationVector* outputVector, vtkDataObject* input);

// A parallel-for on vtkSMPTools.
ParallelFor SMPParallelFor();

// Maps core progress [0,1] to [begin,end] of the algorithm's progress; false once abort is asked
// (CheckAbort: the executive then clears the outputs and re-executes on the next update).
ProgressFunction AlgorithmProgress(vtkAlgorithm* algorithm, double begin, double end);

// The frame of an image (its extent's first voxel is index 0), or an error sentence: the image
// must have at least 2 voxels along x and y, and a usable spacing and direction.
bool ImageGeometryOf(vtkImageData* image, ImageGeometry& geometry, std::string& error);

// The image frame in field data (ImageOrigin, ImageSpacing, ImageDimensions, ImageDirection), so
// that later stages can rasterise onto the grid without the image.
void AddImageGeometry(const ImageGeometry& geometry, vtkDataObject* object);
bool ImageGeometryFromFieldData(vtkDataObject* object, ImageGeometry& geometry, std::string& error);

// True when two frames describe the same grid (to 1e-9 of the spacing).
bool SameFrame(const ImageGeometry& a, const ImageGeometry& b);

// False, with a sentence, when `mesh` records an image frame (field data) that differs from the
// connected image's `frame`; a mesh without a recorded frame matches.
bool MeshMatchesImage(vtkDataObject* mesh, const ImageGeometry& frame, std::string& error);

// Gives `image` the frame's extent (from 0), origin, spacing and direction.
void SetImageFrame(vtkImageData* image, const ImageGeometry& geometry);

// The points of a point set, world coordinates (empty for null).
std::vector<std::array<double, 3>> PointsOf(vtkPointSet* points);

// The world positions of seeds given as a point set, or as a table with columns x, y (and z),
// matched without case, as ParaView's CSV reader gives them (empty for null); false with a sentence
// for another data type or a table without the columns.
bool SeedPointsOf(vtkDataObject* seeds, std::vector<std::array<double, 3>>& world, std::string& error);

// The voxels of the object and background seeds (point sets or tables, SeedPointsOf; SeedVoxels for
// each); false with the sentence of the first that fails.
bool ObjectAndBackgroundVoxels(vtkDataObject* object, vtkDataObject* background, const ImageGeometry& geometry,
  std::vector<std::int64_t>& objectVoxels, std::vector<std::int64_t>& backgroundVoxels, std::string& error);

// Labelled seeds from a point set (a point array named `labelArray`) or a table (columns x, y, z and
// `labelArray`, as a CSV reader gives them), names matched without case: their voxels and labels
// (0 background, 1..k objects, checked by ValidateSeedLabels). False with a sentence.
bool LabelledSeedVoxels(vtkDataObject* seeds, const char* labelArray, const ImageGeometry& geometry,
  LabelledSeeds& out, std::string& error);

// A triangle (2D) / tetrahedral (3D) unstructured grid as a SimplexMesh on `geometry`'s index
// space, every element positively oriented there; false with a sentence for mixed or other cell
// types, or a cell type that does not match the image's dimension.
bool ToSimplexMesh(vtkUnstructuredGrid* grid, const ImageGeometry& geometry, SimplexMesh& mesh, std::string& error);

// The image-mesh output of stages 2 and 3: world points, cells (positively oriented in world
// coordinates), the statistics and quality cell arrays, the image frame and summary field data.
void WriteImageMesh(const SimplexMesh& mesh, const ElementStatistics& statistics, const std::vector<double>& minAngle,
  const std::vector<double>& radiusRatio, vtkUnstructuredGrid* output);

// The owner map of stages 2 and 3 (Contract.h, VoxelOwner): a fresh array of `voxels` tuples to fill
// (ComputeElementStatistics), or null when the consumers of `outputVector`'s port 0 asked for none
// (VoxelOwnersRequest); kept (when not null) in the written mesh's information and registered
// under the digest of its points and cells, off the arrays that writers save.
vtkSmartPointer<vtkIntArray> NewVoxelOwnerArray(vtkInformationVector* outputVector, std::int64_t voxels);
void AttachVoxelOwners(vtkUnstructuredGrid* mesh, vtkIntArray* owner);
// The owner map registered for `mesh`'s points and cells as they are now (any shallow copy of the
// mesh a stage wrote) when it has `voxels` tuples; else false (the caller rasterises).
// `owner` views the array (no copy) and keeps it alive.
bool AttachedVoxelOwners(vtkUnstructuredGrid* mesh, std::int64_t voxels, VoxelOwnerMap& owner);
// The request a consumer makes of a mesh's owner map, on the mesh's output information: 0 = none
// wanted. Stage 3 rasterises its own moved mesh, so it asks its input for none (0.54 GB at 512^3);
// any other consumer leaves it unset and the map is made. A request key: a change of request
// re-executes the producer. The executive passes it upstream through any filter (ParaView puts a
// pass-through filter on every output port); the stages stop it at their inputs.
vtkInformationIntegerRequestKey* VoxelOwnersRequest();
// Stage 3's request on every mesh connected to `port`: none, unless the mesh is already made and no
// request stands (asking now would make it again: ParaView's Apply runs stages one by one).
void RequestNoVoxelOwners(vtkInformationVector* portVector);
// Removes the request from every input connected to `port` (called in RequestUpdateExtent).
void StopVoxelOwnersRequest(vtkInformationVector* portVector);
// Releases the owner map registered for `mesh`'s points and cells from the stage output that keeps
// it: stage 3, which rasterises its own moved mesh, frees its input's map (0.54 GB at 512^3) when
// that mesh was made with one (ParaView's Apply runs stages one by one). A cut on that mesh
// afterwards rasterises it again.
void ReleaseVoxelOwners(vtkUnstructuredGrid* mesh);
// Releases the owner map kept in `object`'s information (a stage's output before it runs again).
void DropVoxelOwners(vtkDataObject* object);
// A 64-bit digest of a grid's points and cells as stored.
std::uint64_t MeshDigest(vtkUnstructuredGrid* grid);

// Point arrays of a mesh whose first nIn points are the nodes of `in`: copied for those, and for the
// nOut - nIn points added after them NodeType Added and Fixed 1 (ids below firstSteiner: box
// corners) or 0 (refinement), other arrays zero.
void PassNodeArrays(vtkPointData* in, vtkIdType nIn, vtkPointData* out, vtkIdType nOut, vtkIdType firstSteiner);

// Sets the update extent of every image connected to `port` to its whole extent.
void RequestWholeImage(vtkInformationVector* portVector);

// Copies a one-component array to double, rejecting NaN/Inf.
bool ToDouble(vtkDataArray* array, std::vector<double>& values, std::string& error);
// What ToDouble checks, without the copy (a stage that reads the array in its own type).
bool CheckDouble(vtkDataArray* array, std::string& error);

// ComputeElementStatistics on the array's own values (no double copy: 71 MB of fresh pages on BraTS);
// `values` passed CheckDouble.
ElementStatistics ImageElementStatistics(const ElementRasterizer& raster, vtkDataArray* values,
  const ParallelFor& parallel, const ProgressFunction& progress, std::int32_t* owner);

// Copies a one-component array to float, rejecting NaN/Inf (error names how many).
bool ToFloat(vtkDataArray* array, std::vector<float>& values, std::string& error);

// The values of a one-component array as floats: the array's own memory when it is a float array
// (no copy: copying BraTS costs ~50 ms, most of it page faults), else converted into `storage`.
// Null with `error` set when the array is unusable (components, type, NaN/Inf).
const float* FloatValues(vtkDataArray* array, std::vector<float>& storage, std::string& error);

// The image as the filters read it: values on voxel centres (point data). An image whose values
// are cell data (each cell a voxel, as ParaView's GDAL reader gives a PNG or TIFF) becomes the image
// of its cell centres carrying those values; so does one whose chosen array (`arrayInfo`) is a cell
// array. Any other image is returned as it is. Null stays null.
vtkSmartPointer<vtkImageData> VoxelValuedImage(vtkImageData* image, vtkInformation* arrayInfo);

// The image point array named by SetInputArrayToProcess (looked up on `image`, whatever port the
// selection names), or the active point scalars when no name was given (ParaView sends an empty
// name when the input had not run yet). A missing named array falls back to the active scalars with
// a warning sentence; null with an error sentence when there are none.
vtkDataArray* ChosenArray(vtkImageData* image, vtkInformation* arrayInfo, std::string& error, std::string& warning);

// The values of the chosen array (ChosenArray) as doubles; false with `error` set when unusable.
// `warning` is set when the chosen name fell back to the active scalars.
bool ChosenValues(vtkImageData* image, vtkInformation* arrayInfo, std::vector<double>& values, std::string& error,
  std::string& warning);

// A label boundary (faces of `faceSize` ids on `points`, as LabelBoundaryFaces gives them) as poly
// data: 2D segments joined into polylines, 3D triangles.
void BoundaryPolyData(vtkPoints* points, const std::vector<std::int64_t>& faces, int faceSize, vtkPolyData* output);

// Adds a one-value double array `name` to the object's field data (summaries, timings).
void AddFieldValue(vtkDataObject* object, const char* name, double value);

// Field data Labels (the count) and LabelNames (uint8, one tuple of the label values 0..k whose
// component names are the labels' names, from `names` split at ';', empty where it gives none).
void AddLabelTable(vtkDataObject* object, int labels, const std::string& names);

// A multi-label cut's field data: the label table, Sigma, Energy, ExpansionMoves, ExpansionCycles,
// ExpansionSeconds, GeodesicSeconds.
void AddMultiLabelFields(vtkDataObject* object, const MultiLabelResult& result, const std::string& labelNames);

// `image` in the frame of `geometry` with the uint8 point scalars Label (one per voxel).
void SetLabelImage(vtkImageData* image, const ImageGeometry& geometry, const std::vector<std::uint8_t>& labels);

// Adds the object components of a cut to the field data: ObjectComponents (their number),
// ObjectComponentVolumes (world units, largest first) and ConnectivityChanged.
void AddObjectComponents(vtkDataObject* object, const std::vector<double>& componentVoxels, double voxelVolume,
  std::int64_t connectivityChanged);
} // namespace featuremesh

#endif
