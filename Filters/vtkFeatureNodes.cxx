#include "vtkFeatureNodes.h"

#include "Contract.h"
#include "FeatureNodes.h"
#include "vtkFeatureMeshUtilities.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkUnsignedCharArray.h"


namespace
{
// The edge map on the input's grid: RSP Edge Enhancement's EdgeMap beside its active EdgeConfidence,
// else the image's scalars or first point array, nonzero = edge.
bool EdgeMapValues(vtkImageData* edgeInput, const featuremesh::ImageGeometry& grid, std::vector<std::uint8_t>& edge,
  std::string& error)
{
  vtkDataArray* edgeArray = edgeInput->GetPointData()->GetArray(featuremesh::names::EdgeMap);
  if (!edgeArray)
  {
    edgeArray = edgeInput->GetPointData()->GetScalars();
  }
  if (!edgeArray && edgeInput->GetPointData()->GetNumberOfArrays() > 0)
  {
    edgeArray = edgeInput->GetPointData()->GetArray(0);
  }
  int dims[3];
  edgeInput->GetDimensions(dims);
  if (!edgeArray || dims[0] != grid.Dims[0] || dims[1] != grid.Dims[1] || dims[2] != grid.Dims[2] ||
    edgeArray->GetNumberOfTuples() != grid.Size())
  {
    error = "the edge map must be an image with a point array on the same grid as the input (" +
      std::to_string(grid.Dims[0]) + "x" + std::to_string(grid.Dims[1]) + "x" + std::to_string(grid.Dims[2]) + ").";
    return false;
  }
  edge.resize(static_cast<size_t>(grid.Size()));
  for (vtkIdType i = 0; i < static_cast<vtkIdType>(grid.Size()); ++i)
  {
    edge[i] = edgeArray->GetComponent(i, 0) != 0.0 ? 1 : 0;
  }
  return true;
}

// Output 0: the nodes at voxel-centre world coordinates with NodeType, Fixed and SampleRadius, the
// node counts per kind, the noise estimate and the seconds per step.
void WriteFeatureNodes(const featuremesh::FeatureNodeResult& result, const featuremesh::ImageGeometry& grid,
  double prepareSeconds, vtkPolyData* output)
{
  namespace names = featuremesh::names;
  const vtkIdType n = static_cast<vtkIdType>(result.Positions.size());
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n);
  vtkNew<vtkUnsignedCharArray> type, fixed;
  vtkNew<vtkFloatArray> radius;
  type->SetName(names::NodeType);
  fixed->SetName(names::Fixed);
  radius->SetName(names::SampleRadius);
  type->SetNumberOfTuples(n);
  fixed->SetNumberOfTuples(n);
  radius->SetNumberOfTuples(n);
  vtkNew<vtkCellArray> verts;
  verts->AllocateExact(n, n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    const auto& ijk = result.Positions[i];
    points->SetPoint(i, grid.IndexToWorld({ { double(ijk[0]), double(ijk[1]), double(ijk[2]) } }).data());
    type->SetValue(i, static_cast<unsigned char>(result.Type[i]));
    fixed->SetValue(i, result.Fixed[i]);
    radius->SetValue(i, result.SampleRadius[i]);
    verts->InsertNextCell(1, &i);
  }
  output->SetPoints(points);
  output->SetVerts(verts);
  output->GetPointData()->AddArray(type);
  output->GetPointData()->AddArray(fixed);
  output->GetPointData()->AddArray(radius);
  output->GetPointData()->SetActiveScalars(names::NodeType);

  vtkNew<vtkIntArray> counts;
  counts->SetName(names::NodeCounts);
  counts->SetNumberOfComponents(4);
  counts->SetComponentName(0, "Canny");
  counts->SetComponentName(1, "Halftone");
  counts->SetComponentName(2, "Uniform");
  counts->SetComponentName(3, "Boundary");
  counts->InsertNextTuple4(result.Counts[0], result.Counts[1], result.Counts[2], result.Counts[3]);
  output->GetFieldData()->AddArray(counts);
  featuremesh::AddFieldValue(output, names::NoiseSigma, result.NoiseSigma);
  vtkNew<vtkDoubleArray> timing;
  timing->SetName(names::StepSeconds);
  timing->SetNumberOfComponents(static_cast<int>(result.StepSeconds.size()) + 1);
  timing->SetComponentName(0, "prepare");
  std::vector<double> tuple = { prepareSeconds };
  for (size_t s = 0; s < result.StepSeconds.size(); ++s)
  {
    timing->SetComponentName(static_cast<vtkIdType>(s) + 1, result.StepSeconds[s].first.c_str());
    tuple.push_back(result.StepSeconds[s].second);
  }
  timing->InsertNextTuple(tuple.data());
  output->GetFieldData()->AddArray(timing);
}
} // namespace

vtkStandardNewMacro(vtkFeatureNodes);

vtkFeatureNodes::vtkFeatureNodes()
  : featuremesh::FilterBase(this, "Feature Nodes")
{
  this->SetNumberOfInputPorts(2);
  this->SetNumberOfOutputPorts(2);
  this->SetInputArrayToProcess(
    0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

int vtkFeatureNodes::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  if (port == 1)
  {
    info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  }
  return 1;
}

int vtkFeatureNodes::FillOutputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkDataObject::DATA_TYPE_NAME(), port == 0 ? "vtkPolyData" : "vtkImageData");
  return 1;
}

int vtkFeatureNodes::RequestInformation(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // The edge map's extent starts at 0; its frame comes with the data.
  vtkInformation* edgeInfo = outputVector->GetInformationObject(1);
  int ext[6];
  inputVector[0]->GetInformationObject(0)->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), ext);
  const int whole[6] = { 0, ext[1] - ext[0], 0, ext[3] - ext[2], 0, ext[5] - ext[4] };
  edgeInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole, 6);
  vtkDataObject::SetPointDataActiveScalarInfo(edgeInfo, VTK_UNSIGNED_CHAR, 1);
  return 1;
}

int vtkFeatureNodes::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // Every stage needs the whole image: request it, never a piece.
  featuremesh::RequestWholeImage(inputVector[0]);
  featuremesh::RequestWholeImage(inputVector[1]);
  return 1;
}

int vtkFeatureNodes::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return this->Run(outputVector, [&]() -> int {
    using namespace featuremesh;
    vtkSmartPointer<vtkImageData> input =
      VoxelValuedImage(vtkImageData::GetData(inputVector[0], 0), this->GetInputArrayInformation(0));
    vtkImageData* edgeInput = vtkImageData::GetData(inputVector[1], 0);
    if (const int done = this->Start(outputVector, { input }); done >= 0)
    {
      return done;
    }
    ImageGeometry grid;
    vtkDataArray* array = this->Frame(input, grid) ? this->ChosenImageArray(input, this->GetInputArrayInformation(0)) : nullptr;
    std::string error;
    std::vector<float> values;
    const float* image = array ? FloatValues(array, values, error) : nullptr;
    std::vector<std::uint8_t> edgeValues;
    if (!image || (edgeInput && !EdgeMapValues(edgeInput, grid, edgeValues, error)))
    {
      return array ? this->Fail(error) : 0;
    }
    const double prepareSeconds = this->Seconds();
    this->UpdateProgress(0.05);

    const FeatureNodeParameters& p = *this;
    FeatureNodeResult result = ComputeFeatureNodes(image, edgeInput ? edgeValues.data() : nullptr, grid, p,
      SMPParallelFor(), AlgorithmProgress(this, 0.05, 0.95));
    if (result.Aborted)
    {
      return 1;
    }
    if (result.EdgeVoxels == 0)
    {
      this->Warn("no edges were found (a constant or very smooth image?); the nodes are uniform and boundary nodes only.");
    }
    WriteFeatureNodes(result, grid, prepareSeconds, vtkPolyData::GetData(outputVector, 0));
    // Output 1: the edge map used.
    vtkImageData* edgeOutput = vtkImageData::GetData(outputVector, 1);
    SetImageFrame(edgeOutput, grid);
    vtkNew<vtkUnsignedCharArray> edgeArray;
    edgeArray->SetName(names::EdgeMap);
    edgeArray->SetNumberOfTuples(static_cast<vtkIdType>(result.EdgeMap.size()));
    std::copy(result.EdgeMap.begin(), result.EdgeMap.end(), edgeArray->GetPointer(0));
    edgeOutput->GetPointData()->SetScalars(edgeArray);
    this->UpdateProgress(1.0);
    return 1;
  });
}

std::string vtkFeatureNodes::ValidateProperties()
{
  return featuremesh::ValidateParameters(static_cast<const featuremesh::FeatureNodeParameters&>(*this));
}

void vtkFeatureNodes::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "GaussianSigma: " << this->GaussianSigma << "\n";
 os << indent << "HessianSigma: " << this->HessianSigma << "\n";
  os << indent << "LowThreshold: " << this->LowThreshold << "\n";
  os << indent << "HighThreshold: " << this->HighThreshold << "\n";
  os << indent << "MaximumPercentile: " << this->MaximumPercentile << "\n";
  os << indent << "NoiseFloor: " << this->NoiseFloor << "\n";
  os << indent << "CovarianceNeighbourhood: " << this->CovarianceNeighbourhood << "\n";
  os << indent << "Halftoning: " << this->Halftoning << "\n";
  os << indent << "HalftoneThreshold: " << this->HalftoneThreshold << "\n";
  os << indent << "HalftoneGamma: " << this->HalftoneGamma << "\n";
  os << indent << "ExclusionWindow: " << this->ExclusionWindow << "\n";
  os << indent << "UniformSpacing: " << this->UniformSpacing << "\n";
  os << indent << "BoundarySpacing: " << this->BoundarySpacing << "\n";
  os << indent << "SeedAware: " << this->SeedAware << "\n";
  os << indent << "EdgeGateRadius: " << this->EdgeGateRadius << "\n";
  os << indent << "CoarseningLevels: " << this->CoarseningLevels << "\n";
}
