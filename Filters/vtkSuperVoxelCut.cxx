#include "vtkSuperVoxelCut.h"

#include "Contract.h"
#include "Memory.h"
#include "MultiLabelCut.h"
#include "SuperVoxelCut.h"
#include "VoxelRefinement.h"
#include "vtkFeatureMeshUtilities.h"

#include "vtkCellData.h"
#include "vtkCellTypes.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"
#include "vtkTable.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>

vtkStandardNewMacro(vtkSuperVoxelCut);

namespace
{
// The binary cut's cost of each label for voxel v of element e, lambda times its region and
// spatial terms, reading the image in its own type.
template <typename T>
std::function<void(std::int64_t, std::int64_t, double*)> BinaryVoxelCost(
  const T* x, const featuremesh::CutResult& cut, double lambda)
{
  const bool spatial = !cut.SpatialObject.empty();
  return [x, &cut, lambda, spatial](std::int64_t v, std::int64_t e, double* costs) {
    const int b = cut.ValueBin(static_cast<double>(x[v]));
    costs[0] = lambda * (cut.BinCostBackground[b] + (spatial ? cut.SpatialScale * cut.SpatialBackground[e] : 0.0));
    costs[1] = lambda * (cut.BinCostObject[b] + (spatial ? cut.SpatialScale * cut.SpatialObject[e] : 0.0) +
                          (cut.Reach.empty() ? 0.0 : cut.Reach[e]));
  };
}
// The squared distance of two voxels' channel vectors, of an image in its own type.
template <typename T>
std::function<double(std::int64_t, std::int64_t)> ChannelDistance2(const T* x, int channels)
{
  return [x, channels](std::int64_t a, std::int64_t b) {
    double s = 0.0;
    for (int c = 0; c < channels; ++c)
    {
      const double d = static_cast<double>(x[a * channels + c]) - static_cast<double>(x[b * channels + c]);
      s += d * d;
    }
    return s;
  };
}
} // namespace

struct vtkSuperVoxelCut::MeshData
{
  // The inputs they came from: the same objects, unmodified since (the data objects' own MTime
  // moves with every pipeline pass, so the arrays are compared).
  std::vector<std::pair<vtkObject*, vtkMTimeType>> Sources;
  featuremesh::ImageGeometry Frame;
  featuremesh::SimplexMesh Mesh;
  featuremesh::SharedArray<double> Mean, Count; // shared with the cut's problem and its caches
  featuremesh::SuperVoxelCutData Cut;
  featuremesh::MaxFlowCache Flow;
  // For labelled seeds, made when first asked for: the voxels' channel bins, each element's runs of
  // them and its channel means, and what the last multi-label cut keeps.
  featuremesh::ChannelBins Bins;
  featuremesh::NodeBinRuns Runs;
  std::vector<double> ChannelMean, ChannelCount;
  featuremesh::MultiLabelCache Multi;
  // Whether the voxel owners came from the mesh's own map (stage 2 or 3) instead of a rasterisation.
  bool OwnerMapReused = false;
  // The label images of the last two cuts and the element labels each holds: a re-cut rewrites the
  // one no one else holds (output 2 holds the last) where labels changed, not every voxel.
  struct LabelImage
  {
    vtkSmartPointer<vtkUnsignedCharArray> Voxels;
    std::vector<std::uint8_t> Labels;
    // The voxels whose label the refinement set apart from their element's.
    std::vector<std::int64_t> Refined;
  };
  std::array<LabelImage, 2> LabelImages;
  int LastLabelImage = 0;
  // The voxel grid's automatic sigma of the values the cut reads (VoxelGridSigma; 0 until asked
  // for), and what the voxel refinement keeps.
  double VoxelSigma = 0.0;
  featuremesh::VoxelRefinementCache Refinement;

  MeshData(std::initializer_list<vtkObject*> sources, const featuremesh::ImageGeometry& frame)
    : Frame(frame)
  {
    for (vtkObject* o : sources)
    {
      this->Sources.emplace_back(o, o ? o->GetMTime() : 0);
    }
  }
  bool SameInputs(const MeshData& other) const
  {
    return this->Sources == other.Sources && featuremesh::SameFrame(this->Frame, other.Frame);
  }
};

vtkSuperVoxelCut::~vtkSuperVoxelCut() = default;

vtkSuperVoxelCut::vtkSuperVoxelCut()
  : featuremesh::FilterBase(this, "Super-Voxel Cut")
{
  this->SetNumberOfInputPorts(5);
  this->SetNumberOfOutputPorts(3);
  this->SetInputArrayToProcess(0, 3, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

FEATUREMESH_SEEDED_CUT_ACCESSORS(vtkSuperVoxelCut)

int vtkSuperVoxelCut::FillInputPortInformation(int port, vtkInformation* info)
{
  const char* types[5] = { "vtkUnstructuredGrid", "vtkDataObject", "vtkDataObject", "vtkImageData", "vtkDataObject" };
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), types[port]);
  if (port > 0)
  {
    info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  }
  return 1;
}

int vtkSuperVoxelCut::FillOutputPortInformation(int port, vtkInformation* info)
{
  const char* types[3] = { "vtkUnstructuredGrid", "vtkPolyData", "vtkImageData" };
  info->Set(vtkDataObject::DATA_TYPE_NAME(), types[port]);
  return 1;
}

int vtkSuperVoxelCut::RequestInformation(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // With the image connected the label image's size is known up front (its extent starts at 0,
  // the frame comes with the data); otherwise it is taken from the mesh's field data at execution.
  vtkInformation* labelInfo = outputVector->GetInformationObject(2);
  if (inputVector[3]->GetNumberOfInformationObjects() > 0)
  {
    int ext[6];
    inputVector[3]->GetInformationObject(0)->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), ext);
    const int whole[6] = { 0, ext[1] - ext[0], 0, ext[3] - ext[2], 0, ext[5] - ext[4] };
    labelInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole, 6);
  }
  vtkDataObject::SetPointDataActiveScalarInfo(labelInfo, VTK_UNSIGNED_CHAR, 1);
  return 1;
}

int vtkSuperVoxelCut::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  featuremesh::RequestWholeImage(inputVector[3]);
  for (int port = 0; port < this->GetNumberOfInputPorts(); ++port)
  {
    featuremesh::StopVoxelOwnersRequest(inputVector[port]);
  }
  return 1;
}

int vtkSuperVoxelCut::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return this->Run(outputVector, [&]() -> int {
    using namespace featuremesh;
    vtkUnstructuredGrid* input = vtkUnstructuredGrid::GetData(inputVector[0], 0);
    vtkDataObject* objectSeeds = vtkDataObject::GetData(inputVector[1], 0);
    vtkDataObject* backgroundSeeds = vtkDataObject::GetData(inputVector[2], 0);
    vtkSmartPointer<vtkImageData> image =
      VoxelValuedImage(vtkImageData::GetData(inputVector[3], 0), this->GetInputArrayInformation(0));
    vtkDataObject* labelledSeeds = vtkDataObject::GetData(inputVector[4], 0);
    if (const int done = this->Start(outputVector, { input }); done >= 0)
    {
      return done;
    }
    ImageGeometry geometry;
    vtkDataArray* valuesArray = nullptr;
    vtkDataArray* binaryValues = nullptr;
    bool contrast = false;
    if (const int done = this->ReadImage(input, image, labelledSeeds != nullptr, geometry, valuesArray, binaryValues, contrast);
        done >= 0)
    {
      return done;
    }
    if (!labelledSeeds && (!objectSeeds || !backgroundSeeds))
    {
      return this->Fail("connect the Object Seeds and the Background Seeds, or labelled Seeds.");
    }
    if (const int done = this->Prepare(input, geometry, valuesArray, binaryValues, contrast && binaryValues); done >= 0)
    {
      return done;
    }
    std::string error;
    std::vector<std::int64_t> objectVoxels, backgroundVoxels;
    if (labelledSeeds)
    {
      LabelledSeeds seeds;
      if (!LabelledSeedVoxels(labelledSeeds, this->SeedLabelArray.c_str(), geometry, seeds, error))
      {
        return this->Fail(error);
      }
      // One object on one channel: alpha-expansion with two labels is the binary cut.
      if (binaryValues != valuesArray || !BinarySeedVoxels(seeds, objectVoxels, backgroundVoxels))
      {
        return this->RequestMultiLabel(input, seeds, valuesArray, *this, outputVector);
      }
    }
    else if (!ObjectAndBackgroundVoxels(objectSeeds, backgroundSeeds, geometry, objectVoxels, backgroundVoxels, error))
    {
      return this->Fail(error);
    }
    this->UpdateProgress(0.45);
    VoxelValueFunction voxelValue;
    if (binaryValues)
    {
      voxelValue = [binaryValues](std::int64_t v) { return binaryValues->GetComponent(v, 0); };
    }
    MeshData& data = *this->Prepared;
    // A binary cut does not use the labelled seeds' move graphs (hundreds of MB on a brain volume).
    data.Multi.Moves.Clear();
    SuperVoxelCutResult result = featuremesh::SuperVoxelCut(data.Mesh, data.Cut, data.Mean, data.Count,
      objectVoxels, backgroundVoxels, voxelValue, *this, SMPParallelFor(), AlgorithmProgress(this, 0.45, 0.9), &data.Flow);
    if (result.Aborted || !result.Error.empty())
    {
      return result.Aborted ? 1 : this->Fail(result.Error);
    }
    this->UpdateProgress(0.9);
    const VoxelRefinementResult refinement = this->RefineBinary(result, binaryValues, objectVoxels, backgroundVoxels);
    if (refinement.Aborted || !refinement.Error.empty())
    {
      return refinement.Aborted ? 1 : this->Fail(refinement.Error);
    }
    this->WriteLabels(input, result.Cut.Label, result.BoundaryFaces, refinement, outputVector);
    this->WriteCutFields(result, geometry.VoxelVolume(), outputVector);
    this->WriteRefinementFields(refinement, outputVector);
    this->UpdateProgress(1.0);
    return 1;
  });
}

void vtkSuperVoxelCut::WriteCutFields(
  const featuremesh::SuperVoxelCutResult& result, double voxelVolume, vtkInformationVector* outputVector)
{
  using namespace featuremesh;
  const CutResult& cut = result.Cut;
  const auto objectElements = std::count(cut.Label.begin(), cut.Label.end(), LabelObject);
  for (vtkDataObject* d : { vtkDataObject::GetData(outputVector, 0), vtkDataObject::GetData(outputVector, 2) })
  {
    AddFieldValues(d, { { names::Sigma, cut.Sigma }, { names::Bins, cut.Bins }, { names::SeedOverlap, cut.SeedOverlap },
                        { names::SpatialWeight, cut.SpatialWeight }, { names::SeedReachDistance, cut.ReachDistance },
                        { names::Flow, cut.Flow }, { names::ObjectElements, static_cast<double>(objectElements) } });
    AddObjectComponents(d, cut.ObjectComponentVoxels, voxelVolume, cut.ConnectivityChanged);
    AddFieldValues(d, { { names::SetupSeconds, result.SetupSeconds },
                        { names::OwnerMapReused, this->Prepared->OwnerMapReused ? 1.0 : 0.0 },
                        { names::GraphSeconds, cut.GraphSeconds }, { names::FlowSeconds, cut.FlowSeconds },
                        { names::GeodesicSeconds, cut.GeodesicSeconds }, { names::CutTotalSeconds, this->Seconds() } });
  }
}

int vtkSuperVoxelCut::ReadImage(vtkUnstructuredGrid* input, vtkImageData* image, bool labelled,
  featuremesh::ImageGeometry& geometry, vtkDataArray*& valuesArray, vtkDataArray*& binaryValues, bool& contrast)
{
  using namespace featuremesh;
  // The image frame: the Image input when connected, else the mesh's field data.
  std::string error = ImageMeshProblem(input);
  if (!error.empty())
  {
    return this->Fail(error);
  }
  if (image ? !ImageGeometryOf(image, geometry, error) || !MeshMatchesImage(input, geometry, error)
            : !ImageGeometryFromFieldData(input, geometry, error))
  {
    return this->Fail(image ? error : error + " Or connect the Image input.");
  }
  valuesArray = image ? this->ChosenImageArray(image, this->GetInputArrayInformation(0)) : nullptr;
  if (image && !valuesArray)
  {
    return 0;
  }
  contrast = UsesLocalContrast(*this);
  if (contrast && !valuesArray && this->featuremesh::SeededCutParameters::Intensity == CutIntensity::LocalContrast)
  {
    return this->Fail("the local contrast is read from the image: connect the Image input.");
  }
  if (contrast && !valuesArray)
  {
    this->Warn("Task Class reads the image's local contrast; without the Image input the cut reads the elements' MeanIntensity.");
  }
  valuesArray = CutValues(valuesArray, contrast, geometry, this->ContrastScale, this->Contrast, error);
  if (image && !valuesArray)
  {
    return this->Fail(error);
  }
  // A multi-channel image serves labelled seeds only; the binary preparation leaves it out.
  binaryValues = valuesArray && valuesArray->GetNumberOfComponents() == 1 ? valuesArray : nullptr;
  if (valuesArray && !binaryValues && !labelled)
  {
    return this->Fail("the image array has " + std::to_string(valuesArray->GetNumberOfComponents()) +
      " components; a binary cut takes one (choose a one-component array), labelled Seeds take several.");
  }
  return -1;
}

int vtkSuperVoxelCut::Prepare(vtkUnstructuredGrid* input, const featuremesh::ImageGeometry& geometry,
  vtkDataArray* valuesArray, vtkDataArray* binaryValues, bool voxelMeans)
{
  using namespace featuremesh;
  vtkDataArray* meanArray = input->GetCellData()->GetArray(names::MeanIntensity);
  vtkDataArray* countArray = input->GetCellData()->GetArray(names::PixelCount);
  // Kept from the last run when the mesh, the image and its array are the same objects, unmodified (a seed edit).
  MeshData key({ input->GetPoints(), input->GetCells(), meanArray, countArray, valuesArray }, geometry);
  if (this->Prepared && this->Prepared->SameInputs(key))
  {
    return -1;
  }
  this->Prepared.reset();
  auto prepared = std::make_unique<MeshData>(std::move(key));
  std::string error;
  if (!ToSimplexMesh(input, geometry, prepared->Mesh, error))
  {
    return this->Fail(error);
  }
  const vtkIdType nCells = input->GetNumberOfCells();
  std::vector<double>& means = prepared->Mean.Mutable();
  std::vector<double>& counts = prepared->Count.Mutable();
  means.resize(nCells);
  counts.resize(nCells);
  vtkIdType badMean = 0, badCount = 0;
  for (vtkIdType c = 0; c < nCells; ++c)
  {
    const double mean = means[c] = meanArray->GetComponent(c, 0);
    const double count = counts[c] = countArray->GetComponent(c, 0);
    badMean += std::isfinite(mean) ? 0 : 1;
    badCount += std::isfinite(count) && count >= 0 ? 0 : 1;
  }
  if (badMean || badCount)
  {
    return this->Fail("the mesh's " + std::string(badMean ? "MeanIntensity" : "PixelCount") + " cell array holds " +
      std::to_string(badMean ? badMean : badCount) +
      (badMean ? " NaN or infinite values" : " negative or non-finite values") + "; recompute the mesh with Delaunay Image Mesh.");
  }
  // The image is read in its own type (checked as ToDouble would, without the copy).
  if (binaryValues && !CheckDouble(binaryValues, error))
  {
    return this->Fail(error);
  }
  this->UpdateProgress(0.1);
  // Stage 2's or 3's owner map, when it was made for this mesh in this frame.
  ImageGeometry meshFrame;
  std::string ignored;
  if (ImageGeometryFromFieldData(input, meshFrame, ignored) && SameFrame(meshFrame, geometry))
  {
    prepared->OwnerMapReused = AttachedVoxelOwners(input, geometry.Size(), prepared->Cut.Owner);
  }
  const ProgressFunction progress = AlgorithmProgress(this, 0.1, 0.4);
  bool ready = false;
  if (!binaryValues)
  {
    ready = PrepareSuperVoxelCut(prepared->Mesh, static_cast<const double*>(nullptr), prepared->Cut, error, SMPParallelFor(), progress);
  }
  else
  {
    switch (binaryValues->GetDataType())
    {
      vtkTemplateMacro(ready = PrepareSuperVoxelCut(prepared->Mesh, static_cast<const VTK_TT*>(binaryValues->GetVoidPointer(0)),
                         prepared->Cut, error, SMPParallelFor(), progress,
                         std::make_shared<vtkSmartPointer<vtkDataArray>>(binaryValues)));
      default:
        error = "the array's value type is not supported.";
    }
  }
  if (!ready)
  {
    return error.empty() ? 1 : this->Fail(error); // aborted, or a bad value
  }
  if (voxelMeans)
  {
    prepared->Mean = NodeMeans(prepared->Cut.Voxels);
  }
  this->Prepared = std::move(prepared);
  return -1;
}

featuremesh::VoxelRefinementResult vtkSuperVoxelCut::RefineBinary(featuremesh::SuperVoxelCutResult& result,
  vtkDataArray* values, const std::vector<std::int64_t>& objectVoxels, const std::vector<std::int64_t>& backgroundVoxels)
{
  using namespace featuremesh;
  const CutResult& cut = result.Cut;
  if (!(this->VoxelRefinement > 0) || !values)
  {
    return VoxelRefinementResult();
  }
  std::vector<std::int64_t> seedVoxels = objectVoxels;
  seedVoxels.insert(seedVoxels.end(), backgroundVoxels.begin(), backgroundVoxels.end());
  std::function<void(std::int64_t, std::int64_t, double*)> cost;
  switch (values->GetDataType())
  {
    vtkTemplateMacro(cost = BinaryVoxelCost(static_cast<const VTK_TT*>(values->GetVoidPointer(0)), cut, this->Lambda));
  }
  VoxelRefinementResult refinement = this->Refine(cut.Label, 2, values, seedVoxels, cost, &result.ObjectComponent, 0.9);
  // The components' volumes hold the refined voxels too.
  std::vector<double>& volumes = result.Cut.ObjectComponentVoxels;
  for (std::size_t c = 0; c < refinement.ComponentChange.size() && c < volumes.size(); ++c)
  {
    volumes[c] += refinement.ComponentChange[c];
  }
  std::stable_sort(volumes.begin(), volumes.end(), std::greater<double>());
  return refinement;
}

featuremesh::VoxelRefinementResult vtkSuperVoxelCut::RefineLabels(
  const featuremesh::MultiLabelResult& result, vtkDataArray* values, const featuremesh::LabelledSeeds& seeds)
{
  using namespace featuremesh;
  if (!(this->VoxelRefinement > 0))
  {
    return VoxelRefinementResult();
  }
  const MeshData& data = *this->Prepared;
  const int L = result.Labels;
  const double lambda = this->Lambda;
  const std::vector<std::vector<double>>& binCosts = result.BinCosts;
  const std::vector<std::uint16_t>& bin = data.Bins.Bin;
  const std::vector<double>& size = data.ChannelCount;
  const SharedArray<double>& spatial = result.Spatial;
  const SharedArray<double>& reach = result.Reach;
  return this->Refine(result.Label, L, values, seeds.Voxel,
    [&](std::int64_t v, std::int64_t e, double* costs) {
      for (int l = 0; l < L; ++l)
      {
        costs[l] = lambda * binCosts[l][bin[v]] + (spatial.empty() || !(size[e] > 0.0) ? 0.0 : spatial[e * L + l] / size[e]) +
          (l == 0 || reach.empty() ? 0.0 : lambda * reach[e * (L - 1) + l - 1]);
      }
    },
    nullptr, 0.9);
}

featuremesh::VoxelRefinementResult vtkSuperVoxelCut::Refine(const std::vector<std::uint8_t>& labels, int labelCount,
  vtkDataArray* values, const std::vector<std::int64_t>& seedVoxels,
  const std::function<void(std::int64_t, std::int64_t, double*)>& cost, const std::vector<std::int64_t>* component,
  double progressFrom)
{
  using namespace featuremesh;
  MeshData& data = *this->Prepared;
  const int channels = values->GetNumberOfComponents();
  VoxelRefinementProblem p;
  p.Mesh = &data.Mesh;
  p.Owner = &data.Cut.Owner;
  p.Label = &labels;
  p.Labels = labelCount;
  const SuperVoxelCutParameters& par = *this;
  p.Rings = par.VoxelRefinement;
  p.Connectivity = ConnectivityFor(par.Connectivity, par.Task);
  p.Fixed.assign(labels.size(), 0);
  for (std::int64_t v : seedVoxels)
  {
    if (data.Cut.Owner[v] >= 0)
    {
      p.Fixed[data.Cut.Owner[v]] = 1;
    }
  }
  p.Cost = cost;
  p.Component = component;
  p.Parallel = SMPParallelFor();
  switch (values->GetDataType())
  {
    vtkTemplateMacro(p.Distance2 = ChannelDistance2(static_cast<const VTK_TT*>(values->GetVoidPointer(0)), channels);
                     if (!(data.VoxelSigma > 0.0)) {
                       data.VoxelSigma = VoxelGridSigma(
                         static_cast<const VTK_TT*>(values->GetVoidPointer(0)), channels, data.Mesh.Geometry(), p.Parallel);
                     });
  }
  p.Sigma = this->Sigma > 0.0 ? this->Sigma : data.VoxelSigma;
  return RefineOnVoxels(p, AlgorithmProgress(this, progressFrom, 1.0), &data.Refinement);
}

void vtkSuperVoxelCut::WriteRefinementFields(const featuremesh::VoxelRefinementResult& refinement, vtkInformationVector* outputVector)
{
  using namespace featuremesh;
  for (vtkDataObject* d : { vtkDataObject::GetData(outputVector, 0), vtkDataObject::GetData(outputVector, 2) })
  {
    AddFieldValues(d, { { names::RefinedVoxels, static_cast<double>(refinement.BandVoxels) },
                        { names::RelabelledVoxels, static_cast<double>(refinement.Voxel.size()) },
                        { names::VoxelRefinementSeconds, refinement.Seconds } });
  }
}

void vtkSuperVoxelCut::WriteLabels(vtkUnstructuredGrid* input, const std::vector<std::uint8_t>& labels,
  const std::vector<std::int64_t>& boundaryFaces, const featuremesh::VoxelRefinementResult& refinement,
  vtkInformationVector* outputVector)
{
  using namespace featuremesh;
  MeshData& data = *this->Prepared;
  const ImageGeometry& geometry = data.Mesh.Geometry();
  // Output 0: the mesh with labels.
  vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector, 0);
  output->ShallowCopy(input);
  DropVoxelOwners(output);
  vtkNew<vtkUnsignedCharArray> label;
  label->SetName(names::Label);
  label->SetNumberOfTuples(static_cast<vtkIdType>(labels.size()));
  std::copy(labels.begin(), labels.end(), label->GetPointer(0));
  output->GetCellData()->AddArray(label);
  output->GetCellData()->SetActiveScalars(names::Label);
  output->GetPointData()->SetActiveAttribute(-1, vtkDataSetAttributes::SCALARS); // coloured by Label
  // Output 1: the boundary, on the mesh's points (2D polylines, 3D triangles outward).
  BoundaryPolyData(input->GetPoints(), boundaryFaces, data.Mesh.VerticesPerCell() - 1, vtkPolyData::GetData(outputVector, 1));
  // Output 2: the labels on the image grid.
  vtkImageData* labelImage = vtkImageData::GetData(outputVector, 2);
  // Not the mesh's field data the pipeline passed on (its per-voxel owner map would make a saved
  // label image as large as the mesh's): the image carries its own frame and the cut's summaries.
  labelImage->GetFieldData()->Initialize();
  vtkPolyData::GetData(outputVector, 1)->GetFieldData()->Initialize();
  SetImageFrame(labelImage, geometry);
  labelImage->GetPointData()->SetScalars(this->LabelVoxels(labels, refinement));
  if (this->SuperVoxelIds)
  {
    vtkNew<vtkIdTypeArray> ids;
    ids->SetName(names::ElementId);
    ids->SetNumberOfTuples(geometry.Size());
    std::copy(data.Cut.Owner.begin(), data.Cut.Owner.end(), ids->GetPointer(0));
    labelImage->GetPointData()->AddArray(ids);
  }
}

vtkUnsignedCharArray* vtkSuperVoxelCut::LabelVoxels(
  const std::vector<std::uint8_t>& labels, const featuremesh::VoxelRefinementResult& refinement)
{
  using namespace featuremesh;
  MeshData& data = *this->Prepared;
  const std::int64_t size = data.Mesh.Geometry().Size();
  auto unheld = [&](int slot) {
    const auto& voxels = data.LabelImages[slot].Voxels;
    return voxels && voxels->GetReferenceCount() == 1 && voxels->GetNumberOfTuples() == size;
  };
  // The last cut's image when no one holds it (the fewest changes), else the one before.
  const int last = data.LastLabelImage;
  int slot = unheld(last) ? last : unheld(1 - last) ? 1 - last : -1;
  if (slot < 0)
  {
    slot = 1 - last; // both held elsewhere, or none yet: a new array
    MeshData::LabelImage& fresh = data.LabelImages[slot];
    fresh.Voxels = vtkSmartPointer<vtkUnsignedCharArray>::New();
    fresh.Voxels->SetName(names::Label);
    fresh.Voxels->SetNumberOfTuples(size);
    AdviseHugePages(fresh.Voxels->GetPointer(0), static_cast<std::size_t>(size));
    fresh.Labels.clear();
    // A copy of the last image (held, e.g. by a view) is patched like a kept one: a copy streams
    // 1 byte per voxel, the full labelling reads the 4-byte owner map as well.
    const MeshData::LabelImage& held = data.LabelImages[last];
    if (held.Voxels && held.Voxels->GetNumberOfTuples() == size && !held.Labels.empty())
    {
      std::copy_n(held.Voxels->GetPointer(0), size, fresh.Voxels->GetPointer(0));
      fresh.Labels = held.Labels;
      fresh.Refined = held.Refined;
    }
  }
  MeshData::LabelImage& image = data.LabelImages[slot];
  // The last refinement undone first: the image then holds its elements' labels, as a patch needs.
  std::uint8_t* voxels = image.Voxels->GetPointer(0);
  if (!image.Labels.empty())
  {
    for (std::int64_t v : image.Refined)
    {
      const std::int32_t e = data.Cut.Owner[v];
      voxels[v] = e >= 0 && e < static_cast<std::int64_t>(image.Labels.size()) ? image.Labels[e] : 0;
    }
  }
  image.Refined.clear();
  if (!PatchVoxelLabels(data.Mesh, data.Cut.Owner, image.Labels, labels, image.Voxels->GetPointer(0), SMPParallelFor()))
  {
    VoxelLabels(data.Cut.Owner, labels, image.Voxels->GetPointer(0), SMPParallelFor());
  }
  ApplyRefinement(refinement, voxels);
  image.Refined = refinement.Voxel;
  // Written through its pointer: without Modified a kept image's cached value range (VTK's, which
  // ParaView shows) would stay the cut's before last.
  image.Voxels->Modified();
  image.Labels = labels;
  data.LastLabelImage = slot;
  return image.Voxels;
}

int vtkSuperVoxelCut::RequestMultiLabel(vtkUnstructuredGrid* input, const featuremesh::LabelledSeeds& seeds,
  vtkDataArray* values, const featuremesh::SuperVoxelCutParameters& par, vtkInformationVector* outputVector)
{
  using namespace featuremesh;
  if (!values)
  {
    return this->Fail("labelled seeds with more than one object need the Image input.");
  }
  MeshData& data = *this->Prepared;
  const SimplexMesh& mesh = data.Mesh;
  const ImageGeometry& geometry = mesh.Geometry();
  const ParallelFor parallel = SMPParallelFor();
  const int channels = values->GetNumberOfComponents();
  std::string error;
  int perChannel = 0;
  switch (values->GetDataType())
  {
    vtkTemplateMacro(perChannel = SeedBinsPerChannel(static_cast<const VTK_TT*>(values->GetVoidPointer(0)), channels,
                       geometry, seeds, par.SeedRadius, par.Bins, par.Bandwidth, &data.Bins));
  }
  if (data.Bins.Channels != channels || data.Bins.PerChannel != perChannel)
  {
    data.Bins = ChannelBins();
    bool binned = false;
    switch (values->GetDataType())
    {
      vtkTemplateMacro(const VTK_TT* v = static_cast<const VTK_TT*>(values->GetVoidPointer(0));
                       binned = BinChannels(v, channels, geometry.Size(), perChannel, data.Bins, error, parallel);
                       if (binned) {
                         NodeChannelMeans(data.Cut.Owner.data(), v, channels, geometry.Size(), mesh.NumberOfElements(),
                           data.ChannelMean, data.ChannelCount);
                       });
      default:
        error = "the array's value type is not supported.";
    }
    if (!binned)
    {
      data.Bins = ChannelBins();
      return this->Fail(error);
    }
    data.Runs = GroupNodeBins(data.Cut.Owner.data(), data.Bins, mesh.NumberOfElements());
    data.Multi.Clear();
  }
  this->UpdateProgress(0.45);
  const MultiLabelParameters& multi = *this;
  const MultiLabelResult result = MultiLabelSuperVoxelCut(mesh, data.Cut, data.Bins, data.Runs, data.ChannelMean,
    data.ChannelCount, seeds, par, multi, parallel, AlgorithmProgress(this, 0.45, 0.9), &data.Multi);
  if (result.Aborted || !result.Error.empty())
  {
    return result.Aborted ? 1 : this->Fail(result.Error);
  }
  const VoxelRefinementResult refinement = this->RefineLabels(result, values, seeds);
  if (refinement.Aborted || !refinement.Error.empty())
  {
    return refinement.Aborted ? 1 : this->Fail(refinement.Error);
  }
  this->WriteLabels(input, result.Label, result.BoundaryFaces, refinement, outputVector);
  this->WriteRefinementFields(refinement, outputVector);
  for (vtkDataObject* d : { vtkDataObject::GetData(outputVector, 0), vtkDataObject::GetData(outputVector, 2) })
  {
    AddMultiLabelFields(d, result, this->LabelNames);
    AddFieldValues(d, { { names::SetupSeconds, result.SetupSeconds },
                        { names::OwnerMapReused, data.OwnerMapReused ? 1.0 : 0.0 }, { names::CutTotalSeconds, this->Seconds() } });
  }
  this->UpdateProgress(1.0);
  return 1;
}

std::string vtkSuperVoxelCut::ValidateProperties()
{
  return featuremesh::ValidateParameters(static_cast<const featuremesh::SuperVoxelCutParameters&>(*this));
}

void vtkSuperVoxelCut::PrintSelf(ostream& os, vtkIndent indent)
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
     << indent << "SuperVoxelIds: " << this->SuperVoxelIds << "\n"
     << indent << "ScaleByContact: " << this->ScaleByContact << "\n"
     << indent << "VoxelRegionTerm: " << this->VoxelRegionTerm << "\n"
     << indent << "SampleSeedElements: " << this->SampleSeedElements << "\n"
     << indent << "SeedElementRadius: " << this->SeedElementRadius << "\n"
     << indent << "VoxelRefinement: " << this->VoxelRefinement << "\n"
     << indent << "SeedRadius: " << this->SeedRadius << "\n"
     << indent << "SeedLabelArray: " << this->SeedLabelArray << "\n"
     << indent << "ChannelModel: " << this->GetChannelModel() << "\n"
     << indent << "LabelNames: " << this->LabelNames << "\n";
}
