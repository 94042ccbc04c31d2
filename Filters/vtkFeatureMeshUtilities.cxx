#include "vtkFeatureMeshUtilities.h"
#include "Memory.h"

#include "Contract.h"
#include "MultiLabelCut.h"
#include "vtkTable.h"
#include "vtkStringArray.h"
#include "vtkAbstractArray.h"

#include "vtkAlgorithm.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkIdTypeArray.h"
#include "vtkMatrix3x3.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"
#include "vtkWeakPointer.h"
#include "vtkDataArray.h"
#include "vtkDataObject.h"
#include "vtkDataSet.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkNew.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationIntegerRequestKey.h"
#include "vtkInformationObjectBaseKey.h"
#include "vtkInformationVector.h"
#include "vtkDemandDrivenPipeline.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkStripper.h"
#include "vtkSMPTools.h"
#include "vtkType.h"
#include "vtkTypeUInt64Array.h"

#include <algorithm>
#include <mutex>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>

namespace featuremesh
{
ParallelFor SMPParallelFor()
{
  return [](std::int64_t n, std::int64_t grain, const RangeFunction& f) {
    if (n <= 0)
    {
      return;
    }
    // VTK 9.2's STDThread backend starts its threads on every For and queues one job per grain
    // under a lock: two jobs per thread at least. Loops here balance well, and their results do
    // not depend on the split.
    const std::int64_t threads = std::max(1, vtkSMPTools::GetEstimatedNumberOfThreads());
    grain = std::max(grain, (n + 2 * threads - 1) / (2 * threads));
    vtkSMPTools::For(0, static_cast<vtkIdType>(n), static_cast<vtkIdType>(grain),
      [&f](vtkIdType b, vtkIdType e) { f(b, e); });
  };
}

ProgressFunction AlgorithmProgress(vtkAlgorithm* algorithm, double begin, double end)
{
  return [=](double t) {
    algorithm->UpdateProgress(begin + (end - begin) * t);
    return !algorithm->CheckAbort();
  };
}

int ReportException(vtkAlgorithm* algorithm, const char* filter, const std::exception_ptr& error)
{
  try
  {
    std::rethrow_exception(error);
  }
  catch (const std::bad_alloc&)
  {
    vtkErrorWithObjectMacro(algorithm, << filter << ": out of memory; try a smaller image or fewer nodes.");
  }
  catch (const std::exception& e)
  {
    vtkErrorWithObjectMacro(algorithm, << filter << ": " << e.what());
  }
  catch (...)
  {
    vtkErrorWithObjectMacro(algorithm, << filter << ": an unknown error.");
  }
  return 0;
}

RunState PipelineState(vtkAlgorithm* algorithm, vtkInformationVector* outputVector)
{
  // Not the inputs' times: the pipeline regenerates and touches them on every pass.
  RunState state;
  vtkDemandDrivenPipeline* executive = vtkDemandDrivenPipeline::SafeDownCast(algorithm->GetExecutive());
  state.Modified = executive ? std::max(executive->GetPipelineMTime(), algorithm->GetMTime()) : algorithm->GetMTime();
  vtkInformation* info = outputVector->GetInformationObject(0);
  if (info && info->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()))
  {
    state.TimeStep = info->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
  }
  return state;
}

bool IsEmptyPiece(vtkInformationVector* outputVector, vtkDataObject* input)
{
  vtkInformation* info = outputVector->GetInformationObject(0);
  const int piece = info->Has(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER())
    ? info->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER())
    : 0;
  vtkDataSet* data = vtkDataSet::SafeDownCast(input);
  return piece > 0 && (!input || (data && data->GetNumberOfPoints() == 0));
}

bool ImageGeometryOf(vtkImageData* image, ImageGeometry& geometry, std::string& error)
{
  if (!image || image->GetNumberOfPoints() == 0)
  {
    error = "the image is empty.";
    return false;
  }
  int dims[3];
  image->GetDimensions(dims);
  if (dims[0] < 2 || dims[1] < 2)
  {
    error = "the image is " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
      std::to_string(dims[2]) +
      " voxels; FeatureMesh needs at least 2 voxels along x and y (2D images lie in the xy plane).";
    return false;
  }
  ImageGeometry g;
  g.Dims = { { dims[0], dims[1], dims[2] } };
  std::copy(image->GetSpacing(), image->GetSpacing() + 3, g.Spacing.begin());
  const double* d = image->GetDirectionMatrix()->GetData();
  std::copy(d, d + 9, g.Direction.begin());
  const int* ext = image->GetExtent();
  image->TransformContinuousIndexToPhysicalPoint(ext[0], ext[2], ext[4], g.Origin.data());
  error = g.Validate();
  if (!error.empty())
  {
    return false;
  }
  geometry = g;
  return true;
}

void AddImageGeometry(const ImageGeometry& g, vtkDataObject* object)
{
  auto add = [&](const char* name, const double* v, int n) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->SetNumberOfComponents(n);
    a->InsertNextTuple(v);
    object->GetFieldData()->AddArray(a);
  };
  const double dims[3] = { double(g.Dims[0]), double(g.Dims[1]), double(g.Dims[2]) };
  add(names::ImageOrigin, g.Origin.data(), 3);
  add(names::ImageSpacing, g.Spacing.data(), 3);
  add(names::ImageDimensions, dims, 3);
  add(names::ImageDirection, g.Direction.data(), 9);
}

bool ImageGeometryFromFieldData(vtkDataObject* object, ImageGeometry& geometry, std::string& error)
{
  vtkFieldData* fd = object->GetFieldData();
  vtkDataArray* o = fd->GetArray(names::ImageOrigin);
  vtkDataArray* s = fd->GetArray(names::ImageSpacing);
  vtkDataArray* d = fd->GetArray(names::ImageDimensions);
  vtkDataArray* r = fd->GetArray(names::ImageDirection);
  if (!o || !s || !d || o->GetNumberOfComponents() != 3 || s->GetNumberOfComponents() != 3 ||
    d->GetNumberOfComponents() != 3 || o->GetNumberOfTuples() < 1 || s->GetNumberOfTuples() < 1 ||
    d->GetNumberOfTuples() < 1)
  {
    error = "the mesh's field data hold no image frame (ImageOrigin, ImageSpacing, ImageDimensions); meshes made by "
            "Delaunay Image Mesh and the filters after it carry one.";
    return false;
  }
  ImageGeometry g;
  for (int a = 0; a < 3; ++a)
  {
    g.Origin[a] = o->GetComponent(0, a);
    g.Spacing[a] = s->GetComponent(0, a);
    const double n = d->GetComponent(0, a);
    g.Dims[a] = n >= 1 && n <= 1e9 ? static_cast<int>(n) : 0;
  }
  // Meshes written before the direction was recorded have an identity frame.
  if (r && r->GetNumberOfComponents() == 9 && r->GetNumberOfTuples() >= 1)
  {
    for (int k = 0; k < 9; ++k)
    {
      g.Direction[k] = r->GetComponent(0, k);
    }
  }
  error = g.Validate();
  if (!error.empty())
  {
    error = "the mesh's image frame (field data): " + error;
    return false;
  }
  geometry = g;
  return true;
}

bool SameFrame(const ImageGeometry& a, const ImageGeometry& b)
{
  if (a.Dims != b.Dims)
  {
    return false;
  }
  const double tol = 1e-9 * std::max({ std::fabs(a.Spacing[0]), std::fabs(a.Spacing[1]), std::fabs(a.Spacing[2]) });
  for (int k = 0; k < 3; ++k)
  {
    if (std::fabs(a.Origin[k] - b.Origin[k]) > tol || std::fabs(a.Spacing[k] - b.Spacing[k]) > tol)
    {
      return false;
    }
  }
  for (int k = 0; k < 9; ++k)
  {
    if (std::fabs(a.Direction[k] - b.Direction[k]) > 1e-9)
    {
      return false;
    }
  }
  return true;
}

bool MeshMatchesImage(vtkDataObject* mesh, const ImageGeometry& frame, std::string& error)
{
  ImageGeometry recorded;
  std::string ignored;
  if (ImageGeometryFromFieldData(mesh, recorded, ignored) && !SameFrame(recorded, frame))
  {
    error = "the mesh was made on another image grid than the connected Image (dimensions, origin, spacing or "
            "direction differ); connect the image the mesh was made from.";
    return false;
  }
  return true;
}

void SetImageFrame(vtkImageData* image, const ImageGeometry& g)
{
  image->SetExtent(0, g.Dims[0] - 1, 0, g.Dims[1] - 1, 0, g.Dims[2] - 1);
  image->SetOrigin(g.Origin.data());
  image->SetSpacing(g.Spacing.data());
  image->SetDirectionMatrix(g.Direction.data());
}

std::vector<std::array<double, 3>> PointsOf(vtkPointSet* points)
{
  const vtkIdType n = points ? points->GetNumberOfPoints() : 0;
  std::vector<std::array<double, 3>> p(n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    points->GetPoint(i, p[i].data());
  }
  return p;
}

bool ObjectAndBackgroundVoxels(vtkDataObject* object, vtkDataObject* background, const ImageGeometry& geometry,
  std::vector<std::int64_t>& objectVoxels, std::vector<std::int64_t>& backgroundVoxels, std::string& error)
{
  std::vector<std::array<double, 3>> objectPoints, backgroundPoints;
  return SeedPointsOf(object, objectPoints, error) && SeedPointsOf(background, backgroundPoints, error) &&
    SeedVoxels(objectPoints, geometry, "object", objectVoxels, error) &&
    SeedVoxels(backgroundPoints, geometry, "background", backgroundVoxels, error);
}

namespace
{
bool SameName(const char* a, const char* b)
{
  if (!a || !b)
  {
    return false;
  }
  for (; *a && *b; ++a, ++b)
  {
    if (std::tolower(static_cast<unsigned char>(*a)) != std::tolower(static_cast<unsigned char>(*b)))
    {
      return false;
    }
  }
  return *a == *b;
}

vtkDataArray* NumericColumn(vtkFieldData* data, const char* name)
{
  for (int i = 0; data && i < data->GetNumberOfArrays(); ++i)
  {
    vtkAbstractArray* a = data->GetAbstractArray(i);
    if (a && SameName(a->GetName(), name))
    {
      return vtkDataArray::SafeDownCast(a);
    }
  }
  return nullptr;
}
} // namespace

bool SeedPointsOf(vtkDataObject* seeds, std::vector<std::array<double, 3>>& world, std::string& error)
{
  world.clear();
  if (!seeds)
  {
    return true;
  }
  if (auto* points = vtkPointSet::SafeDownCast(seeds))
  {
    world = PointsOf(points);
    return true;
  }
  auto* table = vtkTable::SafeDownCast(seeds);
  if (!table)
  {
    error = "the seeds must be a point set or a table (columns x, y, z).";
    return false;
  }
  vtkDataArray* xyz[3] = { NumericColumn(table->GetRowData(), "x"), NumericColumn(table->GetRowData(), "y"),
    NumericColumn(table->GetRowData(), "z") };
  if (table->GetNumberOfRows() > 0 && (!xyz[0] || !xyz[1]))
  {
    error = "the seed table needs numeric columns x, y (and z in 3D).";
    return false;
  }
  for (vtkIdType r = 0; r < table->GetNumberOfRows(); ++r)
  {
    world.push_back({ { xyz[0]->GetComponent(r, 0), xyz[1]->GetComponent(r, 0), xyz[2] ? xyz[2]->GetComponent(r, 0) : 0.0 } });
  }
  return true;
}

bool LabelledSeedVoxels(vtkDataObject* seeds, const char* labelArray, const ImageGeometry& geometry,
  LabelledSeeds& out, std::string& error)
{
  out = LabelledSeeds();
  const std::string name = labelArray && *labelArray ? labelArray : names::Label;
  std::vector<std::array<double, 3>> world;
  if (!SeedPointsOf(seeds, world, error))
  {
    return false;
  }
  vtkFieldData* columns = vtkPointSet::SafeDownCast(seeds) ? static_cast<vtkFieldData*>(vtkPointSet::SafeDownCast(seeds)->GetPointData())
                                                             : vtkTable::SafeDownCast(seeds)->GetRowData();
  vtkDataArray* label = NumericColumn(columns, name.c_str());
  if (!label || label->GetNumberOfComponents() != 1)
  {
    error = "the seeds have no one-component numeric array named " + name + " (0 background, 1..k objects).";
    return false;
  }
  std::vector<double> labels(label->GetNumberOfTuples());
  for (vtkIdType i = 0; i < label->GetNumberOfTuples(); ++i)
  {
    labels[i] = label->GetComponent(i, 0);
  }
  error = ValidateSeedLabels(labels);
  if (!error.empty() || !SeedVoxels(world, geometry, "labelled", out.Voxel, error))
  {
    return false;
  }
  for (double l : labels)
  {
    out.Label.push_back(static_cast<std::uint8_t>(l));
  }
  return true;
}

bool ToSimplexMesh(vtkUnstructuredGrid* grid, const ImageGeometry& geometry, SimplexMesh& mesh, std::string& error)
{
  const vtkIdType nCells = grid ? grid->GetNumberOfCells() : 0;
  if (nCells == 0)
  {
    error = "the mesh is empty.";
    return false;
  }
  const int cellType = grid->GetCellType(0);
  if (cellType != VTK_TRIANGLE && cellType != VTK_TETRA)
  {
    error = "the mesh must consist of triangles (2D) or tetrahedra (3D).";
    return false;
  }
  const int vpc = cellType == VTK_TRIANGLE ? 3 : 4;
  std::vector<std::int64_t> cells(static_cast<size_t>(nCells) * vpc);
  vtkIdType npts;
  const vtkIdType* ids;
  for (vtkIdType c = 0; c < nCells; ++c)
  {
    grid->GetCellPoints(c, npts, ids);
    if (grid->GetCellType(c) != cellType || npts != vpc)
    {
      error = "the mesh mixes cell types; it must be all triangles or all tetrahedra.";
      return false;
    }
    std::copy(ids, ids + vpc, cells.begin() + c * vpc);
  }
  const vtkIdType nPts = grid->GetNumberOfPoints();
  std::vector<std::array<double, 3>> index(nPts);
  for (vtkIdType i = 0; i < nPts; ++i)
  {
    std::array<double, 3> world;
    grid->GetPoint(i, world.data());
    index[i] = geometry.WorldToIndex(world);
    if (geometry.Is2D())
    {
      index[i][2] = 0.0;
    }
  }
  SimplexMesh result(geometry, std::move(index), std::move(cells), vpc);
  error = result.Validate();
  if (!error.empty())
  {
    return false;
  }
  // Whatever the writer's convention or the frame's mirror.
  result.OrientPositively();
  mesh = std::move(result);
  return true;
}

void WriteImageMesh(const SimplexMesh& mesh, const ElementStatistics& stats, const std::vector<double>& minAngle,
  const std::vector<double>& radiusRatio, vtkUnstructuredGrid* output)
{
  const int vpc = mesh.VerticesPerCell();
  const bool is2D = vpc == 3;
  const vtkIdType nPts = mesh.NumberOfPoints();
  const vtkIdType nCells = mesh.NumberOfElements();
  const std::vector<std::array<double, 3>> world = mesh.WorldPoints();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(nPts);
  for (vtkIdType i = 0; i < nPts; ++i)
  {
    points->SetPoint(i, world[i].data());
  }
  output->SetPoints(points);
  vtkNew<vtkIdTypeArray> connectivity, offsets;
  connectivity->SetNumberOfTuples(static_cast<vtkIdType>(mesh.Cells().size()));
  vtkIdType* conn = connectivity->GetPointer(0);
  std::copy(mesh.Cells().begin(), mesh.Cells().end(), conn);
  if (mesh.Geometry().IsMirrored())
  {
    for (vtkIdType c = 0; c < nCells; ++c)
    {
      std::swap(conn[c * vpc + vpc - 2], conn[c * vpc + vpc - 1]);
    }
  }
  offsets->SetNumberOfTuples(nCells + 1);
  for (vtkIdType c = 0; c <= nCells; ++c)
  {
    offsets->SetValue(c, c * vpc);
  }
  vtkNew<vtkCellArray> cells;
  cells->SetData(offsets, connectivity);
  output->SetCells(is2D ? VTK_TRIANGLE : VTK_TETRA, cells);

  auto addCellArray = [&](const char* name, auto* arr, const auto& data) {
    arr->SetName(name);
    arr->SetNumberOfTuples(nCells);
    for (vtkIdType c = 0; c < nCells; ++c)
    {
      arr->SetValue(c, data[c]);
    }
    output->GetCellData()->AddArray(arr);
  };
  vtkNew<vtkIdTypeArray> pixelCount;
  vtkNew<vtkDoubleArray> mean, stddev, angle, ratio;
  vtkNew<vtkUnsignedCharArray> interpolated;
  addCellArray(names::PixelCount, pixelCount.GetPointer(), stats.PixelCount);
  addCellArray(names::MeanIntensity, mean.GetPointer(), stats.Mean);
  addCellArray(names::IntensityStdDev, stddev.GetPointer(), stats.StdDev);
  addCellArray(names::Interpolated, interpolated.GetPointer(), stats.Interpolated);
  addCellArray(is2D ? names::MinAngle : names::MinDihedralAngle, angle.GetPointer(), minAngle);
  addCellArray(names::RadiusRatio, ratio.GetPointer(), radiusRatio);
  // ParaView colours a mesh by its active scalars: the elements' quality, not the nodes' types.
  output->GetCellData()->SetActiveScalars(is2D ? names::MinAngle : names::MinDihedralAngle);

  // Field data: a summary a user (or a report) can read without recomputing, and the frame.
  AddFieldValue(output, names::NumberOfNodes, static_cast<double>(nPts));
  AddFieldValue(output, names::NumberOfElements, static_cast<double>(nCells));
  const auto mm = std::minmax_element(minAngle.begin(), minAngle.end());
  AddFieldValue(output, is2D ? names::MinAngle : names::MinDihedralAngle, nCells ? *mm.first : 0.0);
  AddFieldValue(output, is2D ? names::MaxOfMinAngles : names::MaxOfMinDihedralAngles, nCells ? *mm.second : 0.0);
  AddImageGeometry(mesh.Geometry(), output);
}

void PassNodeArrays(vtkPointData* in, vtkIdType nIn, vtkPointData* out, vtkIdType nOut, vtkIdType firstSteiner)
{
  out->CopyAllocate(in, nOut);
  for (vtkIdType i = 0; i < nIn; ++i)
  {
    out->CopyData(in, i, i);
  }
  for (vtkIdType i = nIn; i < nOut; ++i)
  {
    out->NullData(i);
  }
  auto setAdded = [&](const char* name, int corner, int steiner) {
    vtkDataArray* a = out->GetArray(name);
    if (!a)
    {
      vtkNew<vtkUnsignedCharArray> created;
      created->SetName(name);
      created->SetNumberOfTuples(nOut);
      created->Fill(0);
      out->AddArray(created);
      a = created;
    }
    for (vtkIdType i = nIn; i < nOut; ++i)
    {
      a->SetComponent(i, 0, i < firstSteiner ? corner : steiner);
    }
  };
  const int added = static_cast<int>(NodeType::Added);
  setAdded(names::NodeType, added, added);
  setAdded(names::Fixed, 1, 0);
  // A mesh is coloured by its elements' quality (WriteImageMesh), not by the nodes' types.
  out->SetActiveAttribute(-1, vtkDataSetAttributes::SCALARS);
}

void PutContractVersionFirst(vtkInformationVector* outputVector)
{
  for (int port = 0; port < outputVector->GetNumberOfInformationObjects(); ++port)
  {
    vtkDataObject* object = outputVector->GetInformationObject(port)->Get(vtkDataObject::DATA_OBJECT());
    vtkFieldData* fields = object ? object->GetFieldData() : nullptr;
    if (!fields || (fields->GetNumberOfArrays() > 0 && fields->GetAbstractArray(0)->GetName() &&
                     std::string(fields->GetAbstractArray(0)->GetName()) == names::ContractVersion))
    {
      continue;
    }
    vtkNew<vtkFieldData> ordered;
    vtkNew<vtkUnsignedCharArray> version;
    version->SetName(names::ContractVersion);
    version->InsertNextValue(ContractVersionNumber);
    ordered->AddArray(version);
    for (int i = 0; i < fields->GetNumberOfArrays(); ++i)
    {
      vtkAbstractArray* a = fields->GetAbstractArray(i);
      if (!(a->GetName() && std::string(a->GetName()) == names::ContractVersion))
      {
        ordered->AddArray(a);
      }
    }
    object->SetFieldData(ordered);
  }
}

void RequestWholeImage(vtkInformationVector* portVector)
{
  for (int c = 0; c < portVector->GetNumberOfInformationObjects(); ++c)
  {
    vtkInformation* info = portVector->GetInformationObject(c);
    if (!info->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
    {
      continue;
    }
    int ext[6];
    info->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), ext);
    info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), ext, 6);
    info->Set(vtkStreamingDemandDrivenPipeline::EXACT_EXTENT(), 1);
  }
}

namespace
{
// Values beyond these are refused: float's range for stage 1's float arithmetic, and magnitudes
// whose squares and sums stay finite for the double arithmetic of stages 2 and 4.
template <typename T>
constexpr double LargestValue()
{
  return sizeof(T) == sizeof(float) ? 3.4028234663852886e38 : 1e150;
}

// With `values` null, only checks.
template <typename T>
bool ToValues(vtkDataArray* array, std::vector<T>* values, std::string& error)
{
  if (!array)
  {
    error = "the image has no point scalars to process; choose a point data array.";
    return false;
  }
  if (array->GetNumberOfComponents() != 1)
  {
    error = std::string("the array '") + (array->GetName() ? array->GetName() : "") + "' has " +
      std::to_string(array->GetNumberOfComponents()) +
      " components; choose a single-component array (e.g. extract a component or compute a magnitude first).";
    return false;
  }
  const vtkIdType n = array->GetNumberOfTuples();
  if (values)
  {
    values->resize(static_cast<size_t>(n));
  }
  std::vector<vtkIdType> badPerBlock(64, 0);
  const vtkIdType block = (n + 63) / 64;
  auto convert = [&](auto* data) {
    vtkSMPTools::For(0, 64, 1, [&](vtkIdType b0, vtkIdType b1) {
      for (vtkIdType b = b0; b < b1; ++b)
      {
        // A local count and a raw pointer let the compiler vectorise the conversion.
        vtkIdType bad = 0;
        T* out = values ? values->data() : nullptr;
        for (vtkIdType i = b * block, e = std::min(n, (b + 1) * block); i < e; ++i)
        {
          const double v = static_cast<double>(data[i]);
          const bool ok = std::isfinite(v) && std::fabs(v) <= LargestValue<T>();
          bad += ok ? 0 : 1;
          if (out)
          {
            out[i] = ok ? static_cast<T>(v) : T(0);
          }
        }
        badPerBlock[b] = bad;
      }
    });
  };
  switch (array->GetDataType())
  {
    vtkTemplateMacro(convert(static_cast<VTK_TT*>(array->GetVoidPointer(0))));
    default:
      error = "the array's value type is not supported.";
      return false;
  }
  vtkIdType bad = 0;
  for (vtkIdType c : badPerBlock)
  {
    bad += c;
  }
  if (bad)
  {
    error = std::string("the array '") + (array->GetName() ? array->GetName() : "") + "' holds " +
      std::to_string(bad) + " values that are NaN, infinite or beyond +-" +
      (sizeof(T) == sizeof(float) ? "3.4e38" : "1e150") + "; replace or rescale them (e.g. with a Calculator) first.";
    return false;
  }
  return true;
}
} // namespace

bool ToFloat(vtkDataArray* array, std::vector<float>& values, std::string& error)
{
  return ToValues(array, &values, error);
}

const float* FloatValues(vtkDataArray* array, std::vector<float>& storage, std::string& error)
{
  vtkFloatArray* floats = vtkFloatArray::SafeDownCast(array);
  if (floats && floats->GetNumberOfComponents() == 1)
  {
    const float* data = floats->GetPointer(0);
    const vtkIdType n = floats->GetNumberOfTuples();
    const vtkIdType block = (n + 63) / 64;
    std::vector<vtkIdType> badPerBlock(64, 0);
    vtkSMPTools::For(0, 64, 1, [&](vtkIdType b0, vtkIdType b1) {
      for (vtkIdType b = b0; b < b1; ++b)
      {
        vtkIdType bad = 0;
        for (vtkIdType i = b * block, e = std::min(n, (b + 1) * block); i < e; ++i)
        {
          bad += std::isfinite(data[i]) ? 0 : 1;
        }
        badPerBlock[b] = bad;
      }
    });
    if (std::all_of(badPerBlock.begin(), badPerBlock.end(), [](vtkIdType c) { return c == 0; }))
    {
      return data;
    }
  }
  // Conversion, or the NaN/Inf error message.
  return ToFloat(array, storage, error) ? storage.data() : nullptr;
}

vtkSmartPointer<vtkIntArray> NewVoxelOwnerArray(vtkInformationVector* outputVector, std::int64_t voxels)
{
  vtkInformation* info = outputVector->GetInformationObject(0);
  if (info->Has(VoxelOwnersRequest()) && info->Get(VoxelOwnersRequest()) == 0)
  {
    return nullptr;
  }
  auto owner = vtkSmartPointer<vtkIntArray>::New();
  owner->SetName(names::VoxelOwner);
  owner->SetNumberOfTuples(static_cast<vtkIdType>(voxels));
  AdviseHugePages(owner->GetPointer(0), static_cast<std::size_t>(voxels) * sizeof(std::int32_t));
  return owner;
}

std::uint64_t MeshDigest(vtkUnstructuredGrid* grid)
{
  // FNV-1a over 64-bit words (and the tail bytes) of each array, with its type and length.
  std::uint64_t h = 0xcbf29ce484222325ULL;
  auto mix = [&h](std::uint64_t w) { h = (h ^ w) * 0x100000001b3ULL; };
  auto add = [&](vtkDataArray* a) {
    if (!a)
    {
      mix(0);
      return;
    }
    const size_t bytes = static_cast<size_t>(a->GetDataSize()) * static_cast<size_t>(a->GetDataTypeSize());
    mix(static_cast<std::uint64_t>(a->GetDataType()));
    mix(bytes);
    const unsigned char* p = static_cast<const unsigned char*>(a->GetVoidPointer(0));
    size_t i = 0;
    for (; i + 8 <= bytes; i += 8)
    {
      std::uint64_t w;
      std::memcpy(&w, p + i, 8);
      mix(w);
    }
    for (; i < bytes; ++i)
    {
      mix(p[i]);
    }
  };
  add(grid->GetPoints() ? grid->GetPoints()->GetData() : nullptr);
  vtkCellArray* cells = grid->GetCells();
  add(cells ? cells->GetConnectivityArray() : nullptr);
  add(cells ? cells->GetOffsetsArray() : nullptr);
  return h;
}

namespace
{
// The owner map is not on the data object's arrays, which writers save (4 bytes per voxel): the
// producer's output keeps it in its information, which no writer saves, and a registry finds it
// by the digest of the points and cells it was made for. The consumer's input is a shallow copy
// (ParaView puts a pass-through filter on every port), which shares the points and cells but not
// the information.
vtkInformationObjectBaseKey* OwnerMapKey()
{
  static vtkInformationObjectBaseKey* const key =
    new vtkInformationObjectBaseKey("VOXEL_OWNERS", "FeatureMesh", "vtkIntArray"); // VTK's key manager deletes it
  return key;
}

// A stage output holding a map, and the digest of the points and cells the map was made for.
struct OwnerMapEntry
{
  std::uint64_t Digest;
  vtkWeakPointer<vtkDataObject> Holder;
};

std::mutex OwnerMapsMutex;
std::vector<OwnerMapEntry>& OwnerMaps()
{
  static std::vector<OwnerMapEntry> maps;
  return maps;
}
} // namespace

void AttachVoxelOwners(vtkUnstructuredGrid* mesh, vtkIntArray* owner)
{
  DropVoxelOwners(mesh);
  if (!owner)
  {
    return;
  }
  mesh->GetInformation()->Set(OwnerMapKey(), owner);
  const std::uint64_t digest = MeshDigest(mesh);
  std::lock_guard<std::mutex> lock(OwnerMapsMutex);
  OwnerMaps().push_back({ digest, mesh });
}

namespace
{
// A request key whose data key (what the mesh was made with) is its own.
class VoxelOwnersKey : public vtkInformationIntegerRequestKey
{
public:
  VoxelOwnersKey()
    : vtkInformationIntegerRequestKey("VOXEL_OWNERS_REQUEST", "FeatureMesh")
  {
    this->DataKey = vtkInformationIntegerKey::MakeKey("VOXEL_OWNERS_MADE", "FeatureMesh");
  }
};
} // namespace

vtkInformationIntegerRequestKey* VoxelOwnersRequest()
{
  static vtkInformationIntegerRequestKey* const key = new VoxelOwnersKey; // VTK's key manager deletes it
  return key;
}

void RequestNoVoxelOwners(vtkInformationVector* portVector)
{
  for (int c = 0; c < portVector->GetNumberOfInformationObjects(); ++c)
  {
    vtkInformation* info = portVector->GetInformationObject(c);
    vtkDataSet* made = vtkDataSet::SafeDownCast(info->Get(vtkDataObject::DATA_OBJECT()));
    if (info->Has(VoxelOwnersRequest()) || (made && made->GetNumberOfPoints() == 0))
    {
      info->Set(VoxelOwnersRequest(), 0);
    }
  }
}

void StopVoxelOwnersRequest(vtkInformationVector* portVector)
{
  for (int c = 0; c < portVector->GetNumberOfInformationObjects(); ++c)
  {
    portVector->GetInformationObject(c)->Remove(VoxelOwnersRequest());
  }
}


void ReleaseVoxelOwners(vtkUnstructuredGrid* mesh)
{
  const std::uint64_t digest = MeshDigest(mesh);
  std::vector<vtkSmartPointer<vtkDataObject>> holders;
  {
    std::lock_guard<std::mutex> lock(OwnerMapsMutex);
    for (const OwnerMapEntry& e : OwnerMaps())
    {
      if (e.Digest == digest && e.Holder)
      {
        holders.emplace_back(e.Holder.GetPointer());
      }
    }
  }
  for (vtkDataObject* holder : holders)
  {
    DropVoxelOwners(holder);
  }
}

void DropVoxelOwners(vtkDataObject* object)
{
  object->GetInformation()->Remove(OwnerMapKey());
  // Its entry goes too, with those of outputs that no longer exist.
  std::lock_guard<std::mutex> lock(OwnerMapsMutex);
  auto& maps = OwnerMaps();
  maps.erase(std::remove_if(maps.begin(), maps.end(),
               [object](const OwnerMapEntry& e) { return !e.Holder || e.Holder == object; }),
    maps.end());
}

bool AttachedVoxelOwners(vtkUnstructuredGrid* mesh, std::int64_t voxels, VoxelOwnerMap& owner)
{
  vtkSmartPointer<vtkIntArray> array;
  {
    const std::uint64_t digest = MeshDigest(mesh);
    std::lock_guard<std::mutex> lock(OwnerMapsMutex);
    for (const OwnerMapEntry& e : OwnerMaps())
    {
      vtkIntArray* map = e.Digest == digest && e.Holder
        ? vtkIntArray::SafeDownCast(e.Holder->GetInformation()->Get(OwnerMapKey()))
        : nullptr;
      if (map && map->GetNumberOfComponents() == 1 && map->GetNumberOfTuples() == voxels)
      {
        array = map;
      }
    }
  }
  if (!array)
  {
    return false;
  }
  // No one edits the map (it is on no data object's arrays): the same points and cells, the same ids.
  owner.View(array->GetPointer(0), voxels, std::make_shared<vtkSmartPointer<vtkIntArray>>(array));
  return true;
}

bool ToDouble(vtkDataArray* array, std::vector<double>& values, std::string& error)
{
  return ToValues(array, &values, error);
}

bool CheckDouble(vtkDataArray* array, std::string& error)
{
  return ToValues<double>(array, nullptr, error);
}

ElementStatistics ImageElementStatistics(const ElementRasterizer& raster, vtkDataArray* values,
  const ParallelFor& parallel, const ProgressFunction& progress, std::int32_t* owner)
{
  switch (values->GetDataType())
  {
    vtkTemplateMacro(
      return ComputeElementStatistics(raster, static_cast<const VTK_TT*>(values->GetVoidPointer(0)), parallel, progress, owner));
  }
  // CheckDouble rejected every other type.
  ElementStatistics none;
  none.Aborted = true;
  return none;
}

vtkSmartPointer<vtkImageData> VoxelValuedImage(vtkImageData* image, vtkInformation* arrayInfo)
{
  if (!image)
  {
    return nullptr;
  }
  vtkCellData* cells = image->GetCellData();
  // A cell array named by the selection; pvpython can carry a selection over from another source.
  const bool cellChosen = arrayInfo && arrayInfo->Has(vtkDataObject::FIELD_ASSOCIATION()) &&
    arrayInfo->Get(vtkDataObject::FIELD_ASSOCIATION()) == vtkDataObject::FIELD_ASSOCIATION_CELLS &&
    arrayInfo->Has(vtkDataObject::FIELD_NAME()) && cells->GetArray(arrayInfo->Get(vtkDataObject::FIELD_NAME()));
  const bool onlyCells = image->GetPointData()->GetNumberOfArrays() == 0 && cells->GetNumberOfArrays() > 0;
  if (!(cellChosen || onlyCells) || image->GetNumberOfCells() == 0)
  {
    return image;
  }
  int extent[6];
  image->GetExtent(extent);
  double half[3] = { 0.0, 0.0, 0.0 };
  for (int a = 0; a < 3; ++a)
  {
    if (extent[2 * a + 1] > extent[2 * a])
    {
      extent[2 * a + 1] -= 1;
      half[a] = 0.5;
    }
  }
  // Index i of the new image is the old continuous index i + 1/2: its origin is the old (1/2, ...).
  double origin[3];
  image->TransformContinuousIndexToPhysicalPoint(half[0], half[1], half[2], origin);
  vtkNew<vtkImageData> voxels;
  voxels->SetExtent(extent);
  voxels->SetSpacing(image->GetSpacing());
  voxels->SetDirectionMatrix(image->GetDirectionMatrix());
  voxels->SetOrigin(origin);
  voxels->GetPointData()->ShallowCopy(cells);
  voxels->GetPointData()->RemoveArray(vtkDataSetAttributes::GhostArrayName());
  voxels->GetFieldData()->ShallowCopy(image->GetFieldData());
  return voxels;
}

vtkDataArray* ChosenArray(vtkImageData* image, vtkInformation* arrayInfo, std::string& error, std::string& warning)
{
  const char* name = arrayInfo && arrayInfo->Has(vtkDataObject::FIELD_NAME()) ? arrayInfo->Get(vtkDataObject::FIELD_NAME()) : nullptr;
  vtkDataArray* array = nullptr;
  if (name && *name)
  {
    array = image->GetPointData()->GetArray(name);
    if (array)
    {
      return array;
    }
    // pvpython can carry a name over from a previously active source: fall back to the image's
    // active scalars, and say so.
    array = image->GetPointData()->GetScalars();
    if (!array)
    {
      error = std::string("the image has no point array named '") + name + "'.";
      return nullptr;
    }
    warning = std::string("the image has no point array named '") + name + "'; using its active scalars '" +
      (array->GetName() ? array->GetName() : "") + "'.";
    return array;
  }
  array = image->GetPointData()->GetScalars();
  if (!array)
  {
    error = "the image has no point scalars to process; choose a point data array.";
  }
  return array;
}

bool ChosenValues(vtkImageData* image, vtkInformation* arrayInfo, std::vector<double>& values, std::string& error,
  std::string& warning)
{
  vtkDataArray* array = ChosenArray(image, arrayInfo, error, warning);
  return array && ToDouble(array, values, error);
}

void BoundaryPolyData(vtkPoints* points, const std::vector<std::int64_t>& faces, int faceSize, vtkPolyData* output)
{
  vtkNew<vtkCellArray> cells;
  for (std::size_t f = 0; f < faces.size(); f += faceSize)
  {
    const vtkIdType ids[3] = { faces[f], faces[f + 1], faceSize == 3 ? faces[f + 2] : 0 };
    cells->InsertNextCell(faceSize, ids);
  }
  vtkNew<vtkPolyData> surface;
  surface->SetPoints(points);
  if (faceSize == 2)
  {
    surface->SetLines(cells);
    vtkNew<vtkStripper> stripper;
    stripper->SetInputData(surface);
    stripper->JoinContiguousSegmentsOn();
    stripper->Update();
    output->ShallowCopy(stripper->GetOutput());
  }
  else
  {
    surface->SetPolys(cells);
    output->ShallowCopy(surface);
  }
}

void AddFieldValue(vtkDataObject* object, const char* name, double value)
{
  vtkNew<vtkDoubleArray> a;
  a->SetName(name);
  a->InsertNextValue(value);
  object->GetFieldData()->AddArray(a);
}

void AddObjectComponents(vtkDataObject* object, const std::vector<double>& componentVoxels, double voxelVolume,
  std::int64_t connectivityChanged)
{
  AddFieldValue(object, names::ObjectComponents, static_cast<double>(componentVoxels.size()));
  vtkNew<vtkDoubleArray> volumes;
  volumes->SetName(names::ObjectComponentVolumes);
  volumes->SetNumberOfValues(static_cast<vtkIdType>(componentVoxels.size()));
  for (std::size_t c = 0; c < componentVoxels.size(); ++c)
  {
    volumes->SetValue(static_cast<vtkIdType>(c), componentVoxels[c] * voxelVolume);
  }
  object->GetFieldData()->AddArray(volumes);
  AddFieldValue(object, names::ConnectivityChanged, static_cast<double>(connectivityChanged));
}

} // namespace featuremesh

namespace featuremesh
{
void AddLabelTable(vtkDataObject* object, int labels, const std::string& text)
{
  AddFieldValue(object, names::Labels, labels);
  // Numbers named by their components, not strings: meshio reads no string arrays.
  vtkNew<vtkUnsignedCharArray> list;
  list->SetName(names::LabelNames);
  list->SetNumberOfComponents(labels);
  list->SetNumberOfTuples(1);
  std::size_t from = 0;
  for (int l = 0; l < labels; ++l)
  {
    std::string name;
    if (from <= text.size())
    {
      const std::size_t end = std::min(text.find(';', from), text.size());
      name = text.substr(from, end - from);
      from = end + 1;
    }
    list->SetComponentName(l, name.c_str());
    list->SetComponent(0, l, l);
  }
  object->GetFieldData()->AddArray(list);
}

void AddMultiLabelFields(vtkDataObject* object, const MultiLabelResult& result, const std::string& labelNames)
{
  AddLabelTable(object, result.Labels, labelNames);
  AddFieldValue(object, names::Sigma, result.Sigma);
  AddFieldValue(object, names::Energy, result.Energy);
  AddFieldValue(object, names::ExpansionMoves, result.Moves);
  AddFieldValue(object, names::ExpansionCycles, result.Cycles);
  AddFieldValue(object, names::ExpansionSeconds, result.ExpansionSeconds);
  AddFieldValue(object, names::GeodesicSeconds, result.GeodesicSeconds);
}

void SetLabelImage(vtkImageData* image, const ImageGeometry& geometry, const std::vector<std::uint8_t>& labels)
{
  SetImageFrame(image, geometry);
  vtkNew<vtkUnsignedCharArray> array;
  array->SetName(names::Label);
  array->SetNumberOfTuples(geometry.Size());
  std::copy(labels.begin(), labels.end(), array->GetPointer(0));
  image->GetPointData()->SetScalars(array);
}
} // namespace featuremesh
