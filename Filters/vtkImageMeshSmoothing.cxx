#include "vtkImageMeshSmoothing.h"

#include "Contract.h"
#include "ImageMeshSmoothing.h"
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

namespace
{
// The nodes' Fixed flags (stage 1's array, passed on by stage 2); without the array every node is
// free (the box corners still stay).
std::vector<std::uint8_t> FixedNodes(vtkUnstructuredGrid* input)
{
  const vtkIdType n = input->GetNumberOfPoints();
  std::vector<std::uint8_t> fixed(n, 0);
  if (vtkDataArray* array = input->GetPointData()->GetArray(featuremesh::names::Fixed))
  {
    for (vtkIdType i = 0; i < n; ++i)
    {
      fixed[i] = array->GetComponent(i, 0) != 0 ? 1 : 0;
    }
  }
  return fixed;
}

// The field data of a smoothing run: the smallest angle before, the counts of each step and the seconds.
void AddSmoothingFields(vtkDataObject* output, const featuremesh::ImageMeshSmoothingResult& result, bool is2D, double before,
  double smoothingSeconds, double statisticsSeconds, double totalSeconds)
{
  namespace names = featuremesh::names;
  featuremesh::AddFieldValues(output,
    { { is2D ? names::MinAngleBefore : names::MinDihedralAngleBefore, before }, { names::IterationsRun, result.IterationsRun },
      { names::SmoothingMoves, double(result.Moves) }, { names::EdgeFlips, double(result.Flips) },
      { names::SliverMoves, double(result.Perturbed) }, { names::SliverFlips, double(result.SliverFlips) },
      { names::RefinementRuns, double(result.RefinementRuns) }, { names::AddedNodes, double(result.AddedNodes) },
      { names::SnappedNodes, double(result.SnappedNodes) }, { names::SmoothingSeconds, smoothingSeconds },
      { names::SweepSeconds, result.SweepSeconds }, { names::RefinementSeconds, result.RefinementSeconds },
      { names::SliverSeconds, result.SliverSeconds }, { names::StatisticsSeconds, statisticsSeconds },
      { names::TotalSeconds, totalSeconds } });
}
} // namespace

vtkStandardNewMacro(vtkImageMeshSmoothing);

vtkImageMeshSmoothing::vtkImageMeshSmoothing()
  : featuremesh::FilterBase(this, "Image Mesh Smoothing")
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
  return this->Run(outputVector, [&]() -> int {
    using namespace featuremesh;
    vtkUnstructuredGrid* input = vtkUnstructuredGrid::GetData(inputVector[0], 0);
    vtkSmartPointer<vtkImageData> image =
      VoxelValuedImage(vtkImageData::GetData(inputVector[1], 0), this->GetInputArrayInformation(0));
    vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector, 0);
    DropVoxelOwners(output); // the last run's map, which the executive's reset leaves on the object
    if (input)
    {
      ReleaseVoxelOwners(input); // this stage rasterises its own moved mesh
    }
    if (const int done = this->Start(outputVector, { input, image }); done >= 0)
    {
      return done;
    }
    std::string error = ImageMeshProblem(input);
    if (error.empty() && !image)
    {
      error = "the Image input is required: the moved elements' statistics are recomputed from it.";
    }
    // The image's frame; a mesh that records its own must match it.
    ImageGeometry geometry;
    if (!error.empty() || !ImageGeometryOf(image, geometry, error) || !MeshMatchesImage(input, geometry, error))
    {
      return this->Fail(error);
    }
    const ImageMeshSmoothingParameters& par = *this;
    if (par.Iterations == 0)
    {
      output->ShallowCopy(input);
      return 1;
    }
    SimplexMesh mesh;
    if (!ToSimplexMesh(input, geometry, mesh, error))
    {
      return this->Fail(error);
    }
    this->UpdateProgress(0.02);
    // The exact statistics read the array in its own type; the density reads floats (the array
    // itself when it is float).
    vtkDataArray* array = this->ChosenImageArray(image, this->GetInputArrayInformation(0));
    std::vector<float> floatStorage;
    const float* floats = array && CheckDouble(array, error) ? FloatValues(array, floatStorage, error) : nullptr;
    if (!floats)
    {
      return array ? this->Fail(error) : 0;
    }
    const ParallelFor parallel = SMPParallelFor();
    std::vector<double> minAngle, radiusRatio;
    ElementQuality(mesh, minAngle, radiusRatio, parallel);
    const double before = minAngle.empty() ? 0.0 : *std::min_element(minAngle.begin(), minAngle.end());
    this->UpdateProgress(0.05);

    double smoothingSeconds = this->Seconds();
    ImageMeshSmoothingResult result =
      SmoothImageMesh(mesh, FixedNodes(input), floats, par, parallel, AlgorithmProgress(this, 0.05, 0.6));
    if (result.Aborted || !result.Error.empty())
    {
      return result.Aborted ? 1 : this->Fail(result.Error);
    }
    smoothingSeconds = this->Seconds() - smoothingSeconds;
    std::vector<float>().swap(floatStorage); // the statistics read the array in its own type

    double statisticsSeconds = this->Seconds();
    const vtkSmartPointer<vtkIntArray> owner = NewVoxelOwnerArray(outputVector, geometry.Size());
    const ElementStatistics stats = ImageElementStatistics(ElementRasterizer(result.Mesh), array, parallel,
      AlgorithmProgress(this, 0.6, 0.95), owner ? owner->GetPointer(0) : nullptr);
    if (stats.Aborted)
    {
      return 1;
    }
    ElementQuality(result.Mesh, minAngle, radiusRatio, parallel);
    this->UpdateProgress(0.97);
    statisticsSeconds = this->Seconds() - statisticsSeconds;
    WriteImageMesh(result.Mesh, stats, minAngle, radiusRatio, output);
    AttachVoxelOwners(output, owner);
    const vtkIdType nPts = input->GetNumberOfPoints();
    PassNodeArrays(input->GetPointData(), nPts, output->GetPointData(), result.Mesh.NumberOfPoints(), nPts);
    AddSmoothingFields(output, result, geometry.Is2D(), before, smoothingSeconds, statisticsSeconds, this->Seconds());
    this->UpdateProgress(1.0);
    return 1;
  });
}

std::string vtkImageMeshSmoothing::ValidateProperties()
{
  return featuremesh::ValidateParameters(static_cast<const featuremesh::ImageMeshSmoothingParameters&>(*this));
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
  os << indent << "DihedralFloor: " << this->DihedralFloor << "\n";
  os << indent << "SliverRemoval: " << this->SliverRemoval << "\n";
  os << indent << "MaxDihedralAngle: " << this->MaxDihedralAngle << "\n";
  os << indent << "SliverAngle: " << this->SliverAngle << "\n";
}
