#include "vtkRSPEdgeEnhancement.h"

#include "Contract.h"
#include "RSPEdgeEnhancement.h"
#include "vtkFeatureMeshUtilities.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <chrono>

vtkStandardNewMacro(vtkRSPEdgeEnhancement);

vtkRSPEdgeEnhancement::vtkRSPEdgeEnhancement()
{
  this->SetNumberOfInputPorts(3);
  this->SetNumberOfOutputPorts(3);
  this->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

// Properties whose Core parameter has another name or type.
void vtkRSPEdgeEnhancement::SetNumberOfSources(int value)
{
  featuremesh::SetParameter(this, this->Sources, value);
}
int vtkRSPEdgeEnhancement::GetNumberOfSources()
{
  return this->Sources;
}
void vtkRSPEdgeEnhancement::SetNumberOfSinks(int value)
{
  featuremesh::SetParameter(this, this->Sinks, value);
}
int vtkRSPEdgeEnhancement::GetNumberOfSinks()
{
  return this->Sinks;
}
void vtkRSPEdgeEnhancement::SetRandomSeed(int value)
{
  featuremesh::SetParameter(this, this->featuremesh::RSPParameters::RandomSeed, value);
}
int vtkRSPEdgeEnhancement::GetRandomSeed()
{
  return static_cast<int>(this->featuremesh::RSPParameters::RandomSeed);
}
void vtkRSPEdgeEnhancement::SetMaximumPathVoxels(int value)
{
  featuremesh::SetParameter(this, this->featuremesh::RSPParameters::MaximumPathVoxels, value);
}
int vtkRSPEdgeEnhancement::GetMaximumPathVoxels()
{
  return static_cast<int>(this->featuremesh::RSPParameters::MaximumPathVoxels);
}

int vtkRSPEdgeEnhancement::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), port == 0 ? "vtkImageData" : "vtkDataObject");
  return 1;
}

int vtkRSPEdgeEnhancement::FillOutputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkDataObject::DATA_TYPE_NAME(), port == 0 ? "vtkImageData" : "vtkPolyData");
  return 1;
}

int vtkRSPEdgeEnhancement::RequestInformation(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // The output image's extent starts at 0; its frame comes with the data.
  vtkInformation* info = outputVector->GetInformationObject(0);
  int ext[6];
  inputVector[0]->GetInformationObject(0)->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), ext);
  const int whole[6] = { 0, ext[1] - ext[0], 0, ext[3] - ext[2], 0, ext[5] - ext[4] };
  info->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole, 6);
  vtkDataObject::SetPointDataActiveScalarInfo(info, VTK_FLOAT, 1);
  return 1;
}

int vtkRSPEdgeEnhancement::RequestUpdateExtent(vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  featuremesh::RequestWholeImage(inputVector[0]);
  return 1;
}

namespace
{
template <typename Array, typename T>
void AddPointArray(vtkImageData* image, const char* name, const std::vector<T>& values)
{
  vtkNew<Array> a;
  a->SetName(name);
  a->SetNumberOfTuples(static_cast<vtkIdType>(values.size()));
  std::copy(values.begin(), values.end(), a->GetPointer(0));
  image->GetPointData()->AddArray(a);
}
} // namespace

int vtkRSPEdgeEnhancement::RequestData(vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return featuremesh::RunFilter(this, "RSP Edge Enhancement", outputVector, this->FailedAt, this->FailedAtTime, [&]() -> int {
    using namespace featuremesh;
    const auto start = std::chrono::steady_clock::now();
    vtkSmartPointer<vtkImageData> image =
      VoxelValuedImage(vtkImageData::GetData(inputVector[0], 0), this->GetInputArrayInformation(0));
    vtkDataObject* objectSeeds = vtkDataObject::GetData(inputVector[1], 0);
    vtkDataObject* backgroundSeeds = vtkDataObject::GetData(inputVector[2], 0);
    vtkImageData* output = vtkImageData::GetData(outputVector, 0);
    vtkPolyData* contourOutput = vtkPolyData::GetData(outputVector, 1);
    vtkPolyData* samplesOutput = vtkPolyData::GetData(outputVector, 2);
    std::string error, warning;
    auto fail = [&](const std::string& why) {
      vtkErrorMacro("RSP Edge Enhancement: " << why);
      return 0;
    };
    if (IsEmptyPiece(outputVector, image))
    {
      return 1;
    }
    ImageGeometry geometry;
    if (!ImageGeometryOf(image, geometry, error))
    {
      return fail(error);
    }
    const RSPParameters& p = *this;
    error = this->ValidateProperties();
    if (!error.empty())
    {
      return fail(error);
    }
    std::vector<std::int64_t> objectVoxels, backgroundVoxels;
    if (!ObjectAndBackgroundVoxels(objectSeeds, backgroundSeeds, geometry, objectVoxels, backgroundVoxels, error))
    {
      return fail(error);
    }
    std::vector<float> storage;
    vtkDataArray* array = ChosenArray(image, this->GetInputArrayInformation(0), error, warning);
    if (!warning.empty())
    {
      vtkWarningMacro("RSP Edge Enhancement: " << warning);
    }
    const float* values = array ? FloatValues(array, storage, error) : nullptr;
    if (!values)
    {
      return fail(error);
    }
    this->UpdateProgress(0.05);
    const RSPResult r = featuremesh::RSPEdgeEnhancement(
      values, geometry, objectVoxels, backgroundVoxels, p, SMPParallelFor(), AlgorithmProgress(this, 0.05, 0.95));
    if (r.Aborted)
    {
      return 1;
    }
    if (!r.Error.empty())
    {
      return fail(r.Error);
    }

    SetImageFrame(output, geometry);
    // Each copy of a BraTS-sized array takes ~0.05 s: progress between them.
    AddPointArray<vtkFloatArray>(output, names::EdgeConfidence, r.EdgeConfidence);
    output->GetPointData()->SetActiveScalars(names::EdgeConfidence);
    this->UpdateProgress(0.96);
    AddPointArray<vtkUnsignedCharArray>(output, names::EdgeMap, r.EdgeMap);
    AddPointArray<vtkFloatArray>(output, names::ObjectDistance, r.ObjectDistance);
    this->UpdateProgress(0.97);
    AddPointArray<vtkFloatArray>(output, names::BackgroundDistance, r.BackgroundDistance);
    this->UpdateProgress(0.98);
    if (geometry.Is2D())
    {
      AddPointArray<vtkUnsignedCharArray>(output, names::ContourRegion, r.Region.empty() ? std::vector<std::uint8_t>(geometry.Size(), 0) : r.Region);
    }
    const auto world = [&](std::int64_t v) {
      const std::array<int, 3> c = geometry.Coordinates(v);
      return geometry.IndexToWorld({ { static_cast<double>(c[0]), static_cast<double>(c[1]), static_cast<double>(c[2]) } });
    };
    if (!r.Contour.empty())
    {
      vtkNew<vtkPoints> points;
      points->SetDataTypeToDouble();
      vtkNew<vtkCellArray> lines;
      lines->InsertNextCell(static_cast<vtkIdType>(r.Contour.size() + 1));
      for (std::size_t i = 0; i < r.Contour.size(); ++i)
      {
        const auto x = world(r.Contour[i]);
        lines->InsertCellPoint(points->InsertNextPoint(x.data()));
      }
      lines->InsertCellPoint(0);
      contourOutput->SetPoints(points);
      contourOutput->SetLines(lines);
    }
    else if (geometry.Is2D())
    {
      vtkWarningMacro("RSP Edge Enhancement: the edge confidence draws no closed contour around the object seeds.");
    }
    {
      vtkNew<vtkPoints> points;
      points->SetDataTypeToDouble();
      vtkNew<vtkCellArray> verts;
      vtkNew<vtkUnsignedCharArray> role;
      role->SetName(names::SampleRole);
      for (int kind = 0; kind < 2; ++kind)
      {
        for (std::int64_t v : kind == 0 ? r.SourceVoxels : r.SinkVoxels)
        {
          const auto x = world(v);
          const vtkIdType id = points->InsertNextPoint(x.data());
          verts->InsertNextCell(1, &id);
          role->InsertNextValue(static_cast<unsigned char>(kind));
        }
      }
      samplesOutput->SetPoints(points);
      samplesOutput->SetVerts(verts);
      samplesOutput->GetPointData()->AddArray(role);
    }
    AddFieldValue(output, names::Paths, static_cast<double>(r.Paths));
    AddFieldValue(output, names::PathVoxels, static_cast<double>(r.PathVoxels));
    AddFieldValue(output, names::PathGridFactor, r.PathGridFactor);
    AddFieldValue(output, names::ObjectThreshold, r.ObjectThreshold);
    AddFieldValue(output, names::BackgroundThreshold, r.BackgroundThreshold);
    AddFieldValue(output, names::GradientRange, r.GradientRange);
    for (const auto& step : r.StepSeconds)
    {
      if (step.first == "marching")
      {
        AddFieldValue(output, names::MarchingSeconds, step.second);
      }
      else if (step.first == "paths")
      {
        AddFieldValue(output, names::PathSeconds, step.second);
      }
    }
    AddFieldValue(output, names::TotalSeconds, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    this->UpdateProgress(1.0);
    return 1;
  });
}

std::string vtkRSPEdgeEnhancement::ValidateProperties()
{
  return featuremesh::ValidateParameters(static_cast<const featuremesh::RSPParameters&>(*this));
}

void vtkRSPEdgeEnhancement::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "GradientScale: " << this->GradientScale << "\n"
     << indent << "GradientSigma: " << this->GradientSigma << "\n"
     << indent << "NumberOfSources: " << this->Sources << "\n"
     << indent << "NumberOfSinks: " << this->Sinks << "\n"
     << indent << "SamplingThreshold: " << this->SamplingThreshold << "\n"
     << indent << "RandomSeed: " << this->GetRandomSeed() << "\n"
     << indent << "PathMargin: " << this->PathMargin << "\n"
     << indent << "MaximumPathVoxels: " << this->GetMaximumPathVoxels() << "\n"
     << indent << "EdgeThreshold: " << this->EdgeThreshold << "\n"
     << indent << "GapCost: " << this->GapCost << "\n";
}
