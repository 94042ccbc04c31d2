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

namespace
{
std::array<double, 3> VoxelCentre(const featuremesh::ImageGeometry& geometry, std::int64_t v)
{
  const std::array<int, 3> c = geometry.Coordinates(v);
  return geometry.IndexToWorld({ { static_cast<double>(c[0]), static_cast<double>(c[1]), static_cast<double>(c[2]) } });
}

// Output 1: the closed contour through the voxels of `contour` (2D); false when there is none.
bool WriteContour(const std::vector<std::int64_t>& contour, const featuremesh::ImageGeometry& geometry, vtkPolyData* output)
{
  if (contour.empty())
  {
    return false;
  }
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkCellArray> lines;
  lines->InsertNextCell(static_cast<vtkIdType>(contour.size() + 1));
  for (std::int64_t v : contour)
  {
    lines->InsertCellPoint(points->InsertNextPoint(VoxelCentre(geometry, v).data()));
  }
  lines->InsertCellPoint(0);
  output->SetPoints(points);
  output->SetLines(lines);
  return true;
}

// Output 2: the paths' source and sink voxels as vertices, SampleRole 0 (source) or 1 (sink).
void WriteSamples(const featuremesh::RSPResult& r, const featuremesh::ImageGeometry& geometry, vtkPolyData* output)
{
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkCellArray> verts;
  vtkNew<vtkUnsignedCharArray> role;
  role->SetName(featuremesh::names::SampleRole);
  for (int kind = 0; kind < 2; ++kind)
  {
    for (std::int64_t v : kind == 0 ? r.SourceVoxels : r.SinkVoxels)
    {
      const vtkIdType id = points->InsertNextPoint(VoxelCentre(geometry, v).data());
      verts->InsertNextCell(1, &id);
      role->InsertNextValue(static_cast<unsigned char>(kind));
    }
  }
  output->SetPoints(points);
  output->SetVerts(verts);
  output->GetPointData()->AddArray(role);
}
} // namespace

vtkStandardNewMacro(vtkRSPEdgeEnhancement);

vtkRSPEdgeEnhancement::vtkRSPEdgeEnhancement()
  : featuremesh::FilterBase(this, "RSP Edge Enhancement")
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
  return this->Run(outputVector, [&]() -> int {
    using namespace featuremesh;
    vtkSmartPointer<vtkImageData> image =
      VoxelValuedImage(vtkImageData::GetData(inputVector[0], 0), this->GetInputArrayInformation(0));
    vtkDataObject* objectSeeds = vtkDataObject::GetData(inputVector[1], 0);
    vtkDataObject* backgroundSeeds = vtkDataObject::GetData(inputVector[2], 0);
    vtkImageData* output = vtkImageData::GetData(outputVector, 0);
    if (const int done = this->Start(outputVector, { image }); done >= 0)
    {
      return done;
    }
    ImageGeometry geometry;
    std::string error;
    std::vector<std::int64_t> objectVoxels, backgroundVoxels;
    if (!this->Frame(image, geometry))
    {
      return 0;
    }
    if (!ObjectAndBackgroundVoxels(objectSeeds, backgroundSeeds, geometry, objectVoxels, backgroundVoxels, error))
    {
      return this->Fail(error);
    }
    std::vector<float> storage;
    vtkDataArray* array = this->ChosenImageArray(image, this->GetInputArrayInformation(0));
    const float* values = array ? FloatValues(array, storage, error) : nullptr;
    if (!values)
    {
      return array ? this->Fail(error) : 0;
    }
    this->UpdateProgress(0.05);
    const RSPParameters& p = *this;
    const RSPResult r = featuremesh::RSPEdgeEnhancement(
      values, geometry, objectVoxels, backgroundVoxels, p, SMPParallelFor(), AlgorithmProgress(this, 0.05, 0.95));
    if (r.Aborted || !r.Error.empty())
    {
      return r.Aborted ? 1 : this->Fail(r.Error);
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
    if (!WriteContour(r.Contour, geometry, vtkPolyData::GetData(outputVector, 1)) && geometry.Is2D())
    {
      this->Warn("the edge confidence draws no closed contour around the object seeds.");
    }
    WriteSamples(r, geometry, vtkPolyData::GetData(outputVector, 2));
    AddFieldValues(output, { { names::Paths, static_cast<double>(r.Paths) },
                             { names::PathVoxels, static_cast<double>(r.PathVoxels) },
                             { names::PathGridFactor, r.PathGridFactor }, { names::ObjectThreshold, r.ObjectThreshold },
                             { names::BackgroundThreshold, r.BackgroundThreshold }, { names::GradientRange, r.GradientRange } });
    for (const auto& step : r.StepSeconds)
    {
      if (step.first == "marching" || step.first == "paths")
      {
        AddFieldValue(output, step.first == "marching" ? names::MarchingSeconds : names::PathSeconds, step.second);
      }
    }
    AddFieldValue(output, names::TotalSeconds, this->Seconds());
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
