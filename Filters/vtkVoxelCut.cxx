#include "vtkVoxelCut.h"

#include "Contract.h"
#include "MultiLabelCut.h"
#include "SuperVoxelCut.h"
#include "vtkFeatureMeshUtilities.h"

#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <chrono>
#include <cmath>

vtkStandardNewMacro(vtkVoxelCut);

vtkVoxelCut::vtkVoxelCut()
{
  this->SetNumberOfInputPorts(4);
  this->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

FEATUREMESH_SEEDED_CUT_ACCESSORS(vtkVoxelCut)

int vtkVoxelCut::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), port == 0 ? "vtkImageData" : "vtkDataObject");
  if (port > 0)
  {
    info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  }
  return 1;
}

int vtkVoxelCut::RequestInformation(vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // The label image's extent starts at 0; its frame comes with the data.
  vtkInformation* info = outputVector->GetInformationObject(0);
  int ext[6];
  inputVector[0]->GetInformationObject(0)->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), ext);
  const int whole[6] = { 0, ext[1] - ext[0], 0, ext[3] - ext[2], 0, ext[5] - ext[4] };
  info->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole, 6);
  vtkDataObject::SetPointDataActiveScalarInfo(info, VTK_UNSIGNED_CHAR, 1);
  return 1;
}

int vtkVoxelCut::RequestUpdateExtent(vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  featuremesh::RequestWholeImage(inputVector[0]);
  return 1;
}

int vtkVoxelCut::RequestData(vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return featuremesh::RunFilter(this, "Voxel Cut", outputVector, this->FailedAt, this->FailedAtTime, [&]() -> int {
    using namespace featuremesh;
    const auto start = std::chrono::steady_clock::now();
    vtkSmartPointer<vtkImageData> image =
      VoxelValuedImage(vtkImageData::GetData(inputVector[0], 0), this->GetInputArrayInformation(0));
    vtkDataObject* objectSeeds = vtkDataObject::GetData(inputVector[1], 0);
    vtkDataObject* backgroundSeeds = vtkDataObject::GetData(inputVector[2], 0);
    vtkDataObject* labelledSeeds = vtkDataObject::GetData(inputVector[3], 0);
    vtkImageData* output = vtkImageData::GetData(outputVector, 0);
    std::string error, warning;
    auto fail = [&](const std::string& why) {
      vtkErrorMacro("Voxel Cut: " << why);
      return 0;
    };
    ImageGeometry geometry;
    if (IsEmptyPiece(outputVector, image))
    {
      return 1;
    }
    if (!ImageGeometryOf(image, geometry, error))
    {
      return fail(error);
    }
    const VoxelCutParameters& par = *this;
    error = this->ValidateProperties();
    if (!error.empty())
    {
      return fail(error);
    }
    std::vector<std::int64_t> objectVoxels, backgroundVoxels;
    if (labelledSeeds)
    {
      LabelledSeeds seeds;
      if (!LabelledSeedVoxels(labelledSeeds, this->SeedLabelArray.c_str(), geometry, seeds, error))
      {
        return fail(error);
      }
      vtkDataArray* array = ChosenArray(image, this->GetInputArrayInformation(0), error, warning);
      if (!array)
      {
        return fail(error);
      }
      if (*std::max_element(seeds.Label.begin(), seeds.Label.end()) > 1 || array->GetNumberOfComponents() > 1)
      {
        return this->RequestMultiLabel(seeds, array, geometry, par, outputVector);
      }
      // One object on one channel: alpha-expansion with two labels is the binary cut.
      for (std::size_t s = 0; s < seeds.Voxel.size(); ++s)
      {
        (seeds.Label[s] ? objectVoxels : backgroundVoxels).push_back(seeds.Voxel[s]);
      }
    }
    else if (!objectSeeds || !backgroundSeeds)
    {
      return fail("connect the Object Seeds and the Background Seeds, or labelled Seeds.");
    }
    else if (!ObjectAndBackgroundVoxels(objectSeeds, backgroundSeeds, geometry, objectVoxels, backgroundVoxels, error))
    {
      return fail(error);
    }
    std::vector<double> values;
    const bool valuesOk = ChosenValues(image, this->GetInputArrayInformation(0), values, error, warning);
    if (!warning.empty())
    {
      vtkWarningMacro("Voxel Cut: " << warning);
    }
    if (!valuesOk)
    {
      return fail(error);
    }
    this->UpdateProgress(0.2);
    const CutResult cut = featuremesh::VoxelCut(
      std::move(values), geometry, objectVoxels, backgroundVoxels, par, AlgorithmProgress(this, 0.2, 0.95));
    if (cut.Aborted)
    {
      return 1;
    }
    if (!cut.Error.empty())
    {
      return fail(cut.Error);
    }
    SetLabelImage(output, geometry, cut.Label);
    AddFieldValue(output, names::Sigma, cut.Sigma);
    AddFieldValue(output, names::Bins, cut.Bins);
    AddFieldValue(output, names::Flow, cut.Flow);
    AddFieldValue(output, names::GraphSeconds, cut.GraphSeconds);
    AddFieldValue(output, names::FlowSeconds, cut.FlowSeconds);
    AddFieldValue(output, names::GeodesicSeconds, cut.GeodesicSeconds);
    AddObjectComponents(output, cut.ObjectComponentVoxels, geometry.VoxelVolume(), cut.ConnectivityChanged);
    AddFieldValue(output, names::TotalSeconds, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    this->UpdateProgress(1.0);
    return 1;
  });
}

int vtkVoxelCut::RequestMultiLabel(const featuremesh::LabelledSeeds& seeds, vtkDataArray* array,
  const featuremesh::ImageGeometry& geometry, const featuremesh::VoxelCutParameters& par, vtkInformationVector* outputVector)
{
  using namespace featuremesh;
  const auto start = std::chrono::steady_clock::now();
  const int channels = array->GetNumberOfComponents();
  const std::int64_t n = geometry.Size();
  ChannelBins bins;
  std::vector<double> values;
  std::string error;
  bool binned = false;
  switch (array->GetDataType())
  {
    vtkTemplateMacro(const VTK_TT* v = static_cast<const VTK_TT*>(array->GetVoidPointer(0));
                     binned = BinChannels(v, channels, n,
                       SeedBinsPerChannel(v, channels, geometry, nullptr, nullptr, seeds, par.SeedRadius, par.Bins, par.Bandwidth),
                       bins, error, SMPParallelFor());
                     if (binned) { values.assign(v, v + n * channels); });
    default:
      error = "the array's value type is not supported.";
  }
  if (!binned)
  {
    vtkErrorMacro("Voxel Cut: " << error);
    return 0;
  }
  this->UpdateProgress(0.2);
  const MultiLabelParameters& multi = *this;
  const MultiLabelResult result =
    MultiLabelVoxelCut(values, bins, geometry, seeds, par, multi, AlgorithmProgress(this, 0.2, 0.95));
  if (result.Aborted)
  {
    return 1;
  }
  if (!result.Error.empty())
  {
    vtkErrorMacro("Voxel Cut: " << result.Error);
    return 0;
  }
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  SetLabelImage(output, geometry, result.Label);
  AddMultiLabelFields(output, result, this->LabelNames);
  AddFieldValue(output, names::TotalSeconds, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  this->UpdateProgress(1.0);
  return 1;
}

std::string vtkVoxelCut::ValidateProperties()
{
  return featuremesh::ValidateParameters(static_cast<const featuremesh::VoxelCutParameters&>(*this));
}

void vtkVoxelCut::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Bins: " << this->Bins << "\n"
     << indent << "Sigma: " << this->Sigma << "\n"
     << indent << "Lambda: " << this->Lambda << "\n"
     << indent << "Task: " << this->GetTask() << "\n"
     << indent << "Connectivity: " << this->GetConnectivity() << "\n"
     << indent << "GeodesicWeight: " << this->GetGeodesicWeight() << "\n"
     << indent << "GeodesicLength: " << this->GetGeodesicLength() << "\n"
     << indent << "Bandwidth: " << this->Bandwidth << "\n"
     << indent << "SeedRadius: " << this->SeedRadius << "\n"
     << indent << "SeedLabelArray: " << this->SeedLabelArray << "\n"
     << indent << "ChannelModel: " << this->GetChannelModel() << "\n"
     << indent << "LabelNames: " << this->LabelNames << "\n";
}
