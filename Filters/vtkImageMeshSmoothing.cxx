#include "vtkImageMeshSmoothing.h"

#include "Contract.h"
#include "MeshSmoothing.h"
#include "vtkFeatureMeshUtilities.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <chrono>

vtkStandardNewMacro(vtkImageMeshSmoothing);

vtkImageMeshSmoothing::vtkImageMeshSmoothing()
{
  this->SetNumberOfInputPorts(2);
  this->SetInputArrayToProcess(
    0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

void vtkImageMeshSmoothing::SetMethod(int method)
{
  featuremesh::SetClampedParameter(this, this->Method, method, CVT, ODT);
}

int vtkImageMeshSmoothing::GetMethod()
{
  return static_cast<int>(this->Method);
}

int vtkImageMeshSmoothing::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), port == 0 ? "vtkUnstructuredGrid" : "vtkImageData");
  // Required, but checked in RequestData so that a missing image gets this filter's own sentence.
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), port == 1 ? 1 : 0);
  return 1;
}

int vtkImageMeshSmoothing::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  featuremesh::RequestWholeImage(inputVector[1]);
  featuremesh::RequestNoVoxelOwners(inputVector[0]);
  featuremesh::StopVoxelOwnersRequest(inputVector[1]);
  return 1;
}

int vtkImageMeshSmoothing::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return featuremesh::RunFilter(this, "Image Mesh Smoothing", outputVector, this->FailedAt, this->FailedAtTime, [&]() -> int {
    using namespace featuremesh;
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    vtkUnstructuredGrid* input = vtkUnstructuredGrid::GetData(inputVector[0], 0);
    vtkSmartPointer<vtkImageData> image =
      VoxelValuedImage(vtkImageData::GetData(inputVector[1], 0), this->GetInputArrayInformation(0));
    vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector, 0);
    DropVoxelOwners(output); // the last run's map, which the executive's reset leaves on the object
    if (input)
    {
      ReleaseVoxelOwners(input); // this stage rasterises its own moved mesh
    }
    std::string error, warning;
    auto fail = [&](const std::string& why) {
      vtkErrorMacro("Image Mesh Smoothing: " << why);
      return 0;
    };

    const MeshSmoothingParameters& par = *this;
    error = this->ValidateProperties();
    if (!error.empty())
    {
      return fail(error);
    }
    if (IsEmptyPiece(outputVector, input) || IsEmptyPiece(outputVector, image))
    {
      return 1;
    }
    if (!input || input->GetNumberOfCells() == 0)
    {
      return fail("the mesh is empty.");
    }
    if (!image)
    {
      return fail("the Image input is required: the moved elements' statistics are recomputed from it.");
    }
    if (!input->GetCellData()->GetArray(names::PixelCount) || !input->GetCellData()->GetArray(names::MeanIntensity))
    {
      return fail("the mesh has no PixelCount and MeanIntensity cell arrays; make it with Delaunay Image Mesh.");
    }
    // The image's frame; a mesh that records its own must match it.
    ImageGeometry geometry;
    if (!ImageGeometryOf(image, geometry, error) || !MeshMatchesImage(input, geometry, error))
    {
      return fail(error);
    }
    if (par.Iterations == 0)
    {
      output->ShallowCopy(input);
      return 1;
    }
    SimplexMesh mesh;
    if (!ToSimplexMesh(input, geometry, mesh, error))
    {
      return fail(error);
    }
    this->UpdateProgress(0.02);
    // The exact statistics read the array in its own type; the density reads floats (the array
    // itself when it is float).
    vtkDataArray* array = ChosenArray(image, this->GetInputArrayInformation(0), error, warning);
    if (!warning.empty())
    {
      vtkWarningMacro("Image Mesh Smoothing: " << warning);
    }
    std::vector<float> floatStorage;
    const float* floats = array && CheckDouble(array, error) ? FloatValues(array, floatStorage, error) : nullptr;
    if (!floats)
    {
      return fail(error);
    }
    // Nodes without a Fixed array are all free (box corners still stay).
    const vtkIdType nPts = input->GetNumberOfPoints();
    std::vector<std::uint8_t> fixed(nPts, 0);
    if (vtkDataArray* fixedArray = input->GetPointData()->GetArray(names::Fixed))
    {
      for (vtkIdType i = 0; i < nPts; ++i)
      {
        fixed[i] = fixedArray->GetComponent(i, 0) != 0 ? 1 : 0;
      }
    }
    const ParallelFor parallel = SMPParallelFor();
    std::vector<double> minAngle, radiusRatio;
    ElementQuality(mesh, minAngle, radiusRatio, parallel);
    const double before = minAngle.empty() ? 0.0 : *std::min_element(minAngle.begin(), minAngle.end());
    this->UpdateProgress(0.05);

    auto t0 = Clock::now();
    MeshSmoothingResult result = SmoothImageMesh(mesh, fixed, floats, par, parallel, AlgorithmProgress(this, 0.05, 0.6));
    if (result.Aborted)
    {
      return 1;
    }
    if (!result.Error.empty())
    {
      return fail(result.Error);
    }
    const double smoothingSeconds = std::chrono::duration<double>(Clock::now() - t0).count();
    std::vector<float>().swap(floatStorage); // the statistics read the array in its own type

    t0 = Clock::now();
    const vtkSmartPointer<vtkIntArray> owner = NewVoxelOwnerArray(outputVector, geometry.Size());
    const ElementStatistics stats = ImageElementStatistics(ElementRasterizer(result.Mesh), array, parallel,
      AlgorithmProgress(this, 0.6, 0.95), owner ? owner->GetPointer(0) : nullptr);
    if (stats.Aborted)
    {
      return 1;
    }
    ElementQuality(result.Mesh, minAngle, radiusRatio, parallel);
    this->UpdateProgress(0.97);
    const double statisticsSeconds = std::chrono::duration<double>(Clock::now() - t0).count();
    WriteImageMesh(result.Mesh, stats, minAngle, radiusRatio, output);
    AttachVoxelOwners(output, owner);
    PassNodeArrays(input->GetPointData(), nPts, output->GetPointData(), result.Mesh.NumberOfPoints(), nPts);
    const bool is2D = geometry.Is2D();
    AddFieldValue(output, is2D ? names::MinAngleBefore : names::MinDihedralAngleBefore, before);
    AddFieldValue(output, names::IterationsRun, result.IterationsRun);
    AddFieldValue(output, names::SmoothingMoves, static_cast<double>(result.Moves));
    AddFieldValue(output, names::EdgeFlips, static_cast<double>(result.Flips));
    AddFieldValue(output, names::SliverMoves, static_cast<double>(result.Perturbed));
    AddFieldValue(output, names::AddedNodes, static_cast<double>(result.AddedNodes));
    AddFieldValue(output, names::SnappedNodes, static_cast<double>(result.SnappedNodes));
    AddFieldValue(output, names::SmoothingSeconds, smoothingSeconds);
    AddFieldValue(output, names::SweepSeconds, result.SweepSeconds);
    AddFieldValue(output, names::RefinementSeconds, result.RefinementSeconds);
    AddFieldValue(output, names::SliverSeconds, result.SliverSeconds);
    AddFieldValue(output, names::StatisticsSeconds, statisticsSeconds);
    AddFieldValue(output, names::TotalSeconds, std::chrono::duration<double>(Clock::now() - start).count());
    this->UpdateProgress(1.0);
    return 1;
  });
}

std::string vtkImageMeshSmoothing::ValidateProperties()
{
  return featuremesh::ValidateParameters(static_cast<const featuremesh::MeshSmoothingParameters&>(*this));
}

void vtkImageMeshSmoothing::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Method: " << (this->GetMethod() == CVT ? "CVT" : "ODT") << "\n";
  os << indent << "Iterations: " << this->Iterations << "\n";
  os << indent << "Sigma: " << this->Sigma << "\n";
  os << indent << "FeatureWeight: " << this->FeatureWeight << "\n";
  os << indent << "FixedNodeSlack: " << this->FixedNodeSlack << "\n";
  os << indent << "Flips: " << this->Flips << "\n";
  os << indent << "QualityRefinement: " << this->QualityRefinement << "\n";
  os << indent << "MinAngle: " << this->MinAngle << "\n";
  os << indent << "MinDihedralAngle: " << this->MinDihedralAngle << "\n";
  os << indent << "SliverRemoval: " << this->SliverRemoval << "\n";
  os << indent << "SliverAngle: " << this->SliverAngle << "\n";
}
