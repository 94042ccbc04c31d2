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
#include <cmath>

vtkStandardNewMacro(vtkVoxelCut);

vtkVoxelCut::vtkVoxelCut()
  : featuremesh::FilterBase(this, "Voxel Cut")
{
  this->SetNumberOfInputPorts(4);
  this->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

vtkVoxelCut::~vtkVoxelCut() = default;

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
  return this->Run(outputVector, [&]() -> int {
    using namespace featuremesh;
    vtkSmartPointer<vtkImageData> image =
      VoxelValuedImage(vtkImageData::GetData(inputVector[0], 0), this->GetInputArrayInformation(0));
    vtkDataObject* objectSeeds = vtkDataObject::GetData(inputVector[1], 0);
    vtkDataObject* backgroundSeeds = vtkDataObject::GetData(inputVector[2], 0);
    vtkDataObject* labelledSeeds = vtkDataObject::GetData(inputVector[3], 0);
    vtkImageData* output = vtkImageData::GetData(outputVector, 0);
    if (const int done = this->Start(outputVector, { image }); done >= 0)
    {
      return done;
    }
    ImageGeometry geometry;
    vtkDataArray* array = this->Frame(image, geometry) ? this->ChosenImageArray(image, this->GetInputArrayInformation(0)) : nullptr;
    if (!array)
    {
      return 0;
    }
    const VoxelCutParameters& par = *this;
    std::string error;
    if (!(array = CutValues(array, UsesLocalContrast(par), geometry, this->ContrastScale, this->Contrast, error)))
    {
      return this->Fail(error);
    }
    std::vector<std::int64_t> objectVoxels, backgroundVoxels;
    if (labelledSeeds)
    {
      LabelledSeeds seeds;
      if (!LabelledSeedVoxels(labelledSeeds, this->SeedLabelArray.c_str(), geometry, seeds, error))
      {
        return this->Fail(error);
      }
      // One object on one channel: alpha-expansion with two labels is the binary cut.
      if (array->GetNumberOfComponents() > 1 || !BinarySeedVoxels(seeds, objectVoxels, backgroundVoxels))
      {
        return this->RequestMultiLabel(seeds, array, geometry, par, outputVector);
      }
    }
    else if (!objectSeeds || !backgroundSeeds)
    {
      return this->Fail("connect the Object Seeds and the Background Seeds, or labelled Seeds.");
    }
    else if (!ObjectAndBackgroundVoxels(objectSeeds, backgroundSeeds, geometry, objectVoxels, backgroundVoxels, error))
    {
      return this->Fail(error);
    }
    std::vector<double> values;
    if (!ToDouble(array, values, error))
    {
      return this->Fail(error);
    }
    this->UpdateProgress(0.2);
    const CutResult cut = featuremesh::VoxelCut(
      std::move(values), geometry, objectVoxels, backgroundVoxels, par, AlgorithmProgress(this, 0.2, 0.95), SMPParallelFor());
    if (cut.Aborted || !cut.Error.empty())
    {
      return cut.Aborted ? 1 : this->Fail(cut.Error);
    }
    SetLabelImage(output, geometry, cut.Label);
    AddFieldValues(output, { { names::Sigma, cut.Sigma }, { names::Bins, cut.Bins }, { names::SeedOverlap, cut.SeedOverlap },
                             { names::SpatialWeight, cut.SpatialWeight },
                             { names::SeedReachDistance, cut.ReachDistance }, { names::Flow, cut.Flow },
                             { names::GraphSeconds, cut.GraphSeconds }, { names::FlowSeconds, cut.FlowSeconds },
                             { names::GeodesicSeconds, cut.GeodesicSeconds } });
    AddObjectComponents(output, cut.ObjectComponentVoxels, geometry.VoxelVolume(), cut.ConnectivityChanged);
    AddFieldValue(output, names::TotalSeconds, this->Seconds());
    this->UpdateProgress(1.0);
    return 1;
  });
}

int vtkVoxelCut::RequestMultiLabel(const featuremesh::LabelledSeeds& seeds, vtkDataArray* array,
  const featuremesh::ImageGeometry& geometry, const featuremesh::VoxelCutParameters& par, vtkInformationVector* outputVector)
{
  using namespace featuremesh;
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
                       SeedBinsPerChannel(v, channels, geometry, seeds, par.SeedRadius, par.Bins, par.Bandwidth),
                       bins, error, SMPParallelFor());
                     if (binned) { values.assign(v, v + n * channels); });
    default:
      error = "the array's value type is not supported.";
  }
  if (!binned)
  {
    return this->Fail(error);
  }
  this->UpdateProgress(0.2);
  const MultiLabelParameters& multi = *this;
  const MultiLabelResult result =
    MultiLabelVoxelCut(values, bins, geometry, seeds, par, multi, AlgorithmProgress(this, 0.2, 0.95), SMPParallelFor());
  if (result.Aborted || !result.Error.empty())
  {
    return result.Aborted ? 1 : this->Fail(result.Error);
  }
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  SetLabelImage(output, geometry, result.Label);
  AddMultiLabelFields(output, result, this->LabelNames);
  AddFieldValue(output, names::TotalSeconds, this->Seconds());
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
     << indent << "Intensity: " << this->GetIntensity() << "\n"
     << indent << "ContrastScale: " << this->ContrastScale << "\n"
     << indent << "GeodesicWeight: " << this->GetGeodesicWeight() << "\n"
     << indent << "GeodesicLength: " << this->GetGeodesicLength() << "\n"
     << indent << "AdaptiveGeodesicWeight: " << this->GetAdaptiveGeodesicWeight() << "\n"
     << indent << "SeedReach: " << this->GetSeedReach() << "\n"
     << indent << "SeedReachWeight: " << this->GetSeedReachWeight() << "\n"
     << indent << "Bandwidth: " << this->Bandwidth << "\n"
     << indent << "SeedRadius: " << this->SeedRadius << "\n"
     << indent << "SeedLabelArray: " << this->SeedLabelArray << "\n"
     << indent << "ChannelModel: " << this->GetChannelModel() << "\n"
     << indent << "LabelNames: " << this->LabelNames << "\n";
}
