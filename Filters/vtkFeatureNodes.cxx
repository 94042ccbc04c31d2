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

#include <chrono>

vtkStandardNewMacro(vtkFeatureNodes);

vtkFeatureNodes::vtkFeatureNodes()
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
  return featuremesh::RunFilter(this, "Feature Nodes", outputVector, this->FailedAt, this->FailedAtTime, [&]() { return this->Execute(inputVector, outputVector); });
}

int vtkFeatureNodes::Execute(vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  using namespace featuremesh;
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  vtkSmartPointer<vtkImageData> input =
    VoxelValuedImage(vtkImageData::GetData(inputVector[0], 0), this->GetInputArrayInformation(0));
  vtkImageData* edgeInput = vtkImageData::GetData(inputVector[1], 0);
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  vtkImageData* edgeOutput = vtkImageData::GetData(outputVector, 1);

  std::string error;
  ImageGeometry grid;
  if (IsEmptyPiece(outputVector, input))
  {
    return 1;
  }
  if (!ImageGeometryOf(input, grid, error))
  {
    vtkErrorMacro("Feature Nodes: " << error);
    return 0;
  }
  const FeatureNodeParameters& p = *this;
  error = this->ValidateProperties();
  if (!error.empty())
  {
    vtkErrorMacro("Feature Nodes: " << error);
    return 0;
  }

  std::vector<float> values;
  std::string warning;
  vtkDataArray* array = ChosenArray(input, this->GetInputArrayInformation(0), error, warning);
  if (!warning.empty())
  {
    vtkWarningMacro("Feature Nodes: " << warning);
  }
  const float* image = array ? FloatValues(array, values, error) : nullptr;
  if (!image)
  {
    vtkErrorMacro("Feature Nodes: " << error);
    return 0;
  }

  std::vector<std::uint8_t> edgeValues;
  if (edgeInput)
  {
    // RSP Edge Enhancement's image carries EdgeMap beside its active EdgeConfidence.
    vtkDataArray* edgeArray = edgeInput->GetPointData()->GetArray(names::EdgeMap);
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
      vtkErrorMacro("Feature Nodes: the edge map must be an image with a point array on the same grid as the input ("
        << grid.Dims[0] << "x" << grid.Dims[1] << "x" << grid.Dims[2] << ").");
      return 0;
    }
    edgeValues.resize(static_cast<size_t>(grid.Size()));
    for (vtkIdType i = 0; i < static_cast<vtkIdType>(grid.Size()); ++i)
    {
      edgeValues[i] = edgeArray->GetComponent(i, 0) != 0.0 ? 1 : 0;
    }
  }
  const double prepSeconds = std::chrono::duration<double>(Clock::now() - start).count();
  this->UpdateProgress(0.05);

  const ParallelFor parallel = SMPParallelFor();
  FeatureNodeResult result = ComputeFeatureNodes(image, edgeInput ? edgeValues.data() : nullptr, grid, p, parallel,
    AlgorithmProgress(this, 0.05, 0.95));
  if (result.Aborted)
  {
    return 1;
  }
  if (result.EdgeVoxels == 0)
  {
    vtkWarningMacro("Feature Nodes: no edges were found (a constant or very smooth image?); "
                    "the nodes are uniform and boundary nodes only.");
  }

  // Output 0: nodes at voxel-centre world coordinates.
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
  AddFieldValue(output, names::NoiseSigma, result.NoiseSigma);
  vtkNew<vtkDoubleArray> timing;
  timing->SetName(names::StepSeconds);
  timing->SetNumberOfComponents(static_cast<int>(result.StepSeconds.size()) + 1);
  timing->SetComponentName(0, "prepare");
  std::vector<double> tuple = { prepSeconds };
  for (size_t s = 0; s < result.StepSeconds.size(); ++s)
  {
    timing->SetComponentName(static_cast<vtkIdType>(s) + 1, result.StepSeconds[s].first.c_str());
    tuple.push_back(result.StepSeconds[s].second);
  }
  timing->InsertNextTuple(tuple.data());
  output->GetFieldData()->AddArray(timing);

  // Output 1: the edge map used.
  SetImageFrame(edgeOutput, grid);
  vtkNew<vtkUnsignedCharArray> edgeArray;
  edgeArray->SetName(names::EdgeMap);
  edgeArray->SetNumberOfTuples(static_cast<vtkIdType>(result.EdgeMap.size()));
  std::copy(result.EdgeMap.begin(), result.EdgeMap.end(), edgeArray->GetPointer(0));
  edgeOutput->GetPointData()->SetScalars(edgeArray);
  this->UpdateProgress(1.0);
  return 1;
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
