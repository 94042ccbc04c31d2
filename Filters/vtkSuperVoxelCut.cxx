#include "vtkSuperVoxelCut.h"

#include "BoykovJolly.h"
#include "ElementRasterizer.h"
#include "MeshAdjacency.h"
#include "vtkFeatureMeshSeeds.h"
#include "vtkFeatureMeshUtilities.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCellTypes.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStripper.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <chrono>
#include <cmath>

vtkStandardNewMacro(vtkSuperVoxelCut);

vtkSuperVoxelCut::vtkSuperVoxelCut()
{
  this->SetNumberOfInputPorts(4);
  this->SetNumberOfOutputPorts(3);
  this->SetInputArrayToProcess(0, 3, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

int vtkSuperVoxelCut::FillInputPortInformation(int port, vtkInformation* info)
{
  const char* types[4] = { "vtkUnstructuredGrid", "vtkPointSet", "vtkPointSet", "vtkImageData" };
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), types[port]);
  if (port == 3)
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
  // With the image connected the label image's grid is known up front; otherwise it is taken
  // from the mesh's ImageOrigin/ImageSpacing/ImageDimensions field data at execution.
  vtkInformation* labelInfo = outputVector->GetInformationObject(2);
  if (inputVector[3]->GetNumberOfInformationObjects() > 0)
  {
    vtkInformation* imageInfo = inputVector[3]->GetInformationObject(0);
    int ext[6];
    double spacing[3], origin[3];
    imageInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), ext);
    imageInfo->Get(vtkDataObject::SPACING(), spacing);
    imageInfo->Get(vtkDataObject::ORIGIN(), origin);
    labelInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), ext, 6);
    labelInfo->Set(vtkDataObject::SPACING(), spacing, 3);
    labelInfo->Set(vtkDataObject::ORIGIN(), origin, 3);
  }
  vtkDataObject::SetPointDataActiveScalarInfo(labelInfo, VTK_UNSIGNED_CHAR, 1);
  return 1;
}

int vtkSuperVoxelCut::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  featuremesh::RequestWholeImage(inputVector[3]);
  return 1;
}

int vtkSuperVoxelCut::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  using namespace featuremesh;
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  EnsureThreadedBackend();
  vtkUnstructuredGrid* mesh = vtkUnstructuredGrid::GetData(inputVector[0], 0);
  vtkPointSet* objectSeeds = vtkPointSet::GetData(inputVector[1], 0);
  vtkPointSet* backgroundSeeds = vtkPointSet::GetData(inputVector[2], 0);
  vtkImageData* image = vtkImageData::GetData(inputVector[3], 0);
  vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector, 0);
  vtkPolyData* boundary = vtkPolyData::GetData(outputVector, 1);
  vtkImageData* labelImage = vtkImageData::GetData(outputVector, 2);
  std::string error;

  BoykovJollyParameters par;
  par.Bins = this->Bins;
  par.Sigma = this->Sigma;
  par.Lambda = this->Lambda;
  error = ValidateParameters(par);
  if (!error.empty())
  {
    vtkErrorMacro("Super-Voxel Cut: " << error);
    return 0;
  }
  if (!mesh || mesh->GetNumberOfCells() == 0)
  {
    vtkErrorMacro("Super-Voxel Cut: the mesh is empty.");
    return 0;
  }
  vtkDataArray* meanArray = mesh->GetCellData()->GetArray("MeanIntensity");
  vtkDataArray* countArray = mesh->GetCellData()->GetArray("PixelCount");
  if (!meanArray || !countArray)
  {
    vtkErrorMacro("Super-Voxel Cut: the mesh has no MeanIntensity and PixelCount cell arrays; "
                  "make it with Delaunay Image Mesh.");
    return 0;
  }
  const vtkIdType nCells = mesh->GetNumberOfCells();
  const int cellType = mesh->GetCellType(0);
  if (cellType != VTK_TRIANGLE && cellType != VTK_TETRA)
  {
    vtkErrorMacro("Super-Voxel Cut: the mesh must consist of triangles (2D) or tetrahedra (3D).");
    return 0;
  }
  const int vpc = cellType == VTK_TRIANGLE ? 3 : 4;
  std::vector<std::int64_t> cells(static_cast<size_t>(nCells) * vpc);
  {
    vtkIdType npts;
    const vtkIdType* ids;
    for (vtkIdType c = 0; c < nCells; ++c)
    {
      mesh->GetCellPoints(c, npts, ids);
      if (mesh->GetCellType(c) != cellType || npts != vpc)
      {
        vtkErrorMacro("Super-Voxel Cut: the mesh mixes cell types; it must be all triangles or all tetrahedra.");
        return 0;
      }
      std::copy(ids, ids + vpc, cells.begin() + c * vpc);
    }
  }

  // The image grid: the Image input when connected, else the mesh's field data.
  GridGeometry geo;
  if (image)
  {
    if (!ImageGrid(image, geo.G, error))
    {
      vtkErrorMacro("Super-Voxel Cut: " << error);
      return 0;
    }
    const double zero[3] = { 0, 0, 0 };
    IndexToWorld(image, zero, geo.Origin);
    std::copy(image->GetSpacing(), image->GetSpacing() + 3, geo.Spacing);
  }
  else
  {
    vtkDataArray* o = mesh->GetFieldData()->GetArray("ImageOrigin");
    vtkDataArray* s = mesh->GetFieldData()->GetArray("ImageSpacing");
    vtkDataArray* d = mesh->GetFieldData()->GetArray("ImageDimensions");
    if (!o || !s || !d)
    {
      vtkErrorMacro("Super-Voxel Cut: connect the Image input, or give a mesh made by Delaunay Image Mesh "
                    "(its field data hold the image grid).");
      return 0;
    }
    for (int a = 0; a < 3; ++a)
    {
      geo.Origin[a] = o->GetComponent(0, a);
      geo.Spacing[a] = s->GetComponent(0, a);
      geo.G.Dims[a] = static_cast<int>(d->GetComponent(0, a));
    }
  }
  if ((vpc == 3) != geo.G.Is2D())
  {
    vtkErrorMacro("Super-Voxel Cut: a " << (vpc == 3 ? "triangle" : "tetrahedral") << " mesh needs a "
                                        << (vpc == 3 ? "2D" : "3D") << " image.");
    return 0;
  }

  // Points in world and index space.
  const vtkIdType nPts = mesh->GetNumberOfPoints();
  std::vector<std::array<double, 3>> world(nPts), index(nPts);
  for (vtkIdType i = 0; i < nPts; ++i)
  {
    mesh->GetPoint(i, world[i].data());
    for (int a = 0; a < 3; ++a)
    {
      double c = geo.G.Dims[a] == 1 ? 0.0 : (world[i][a] - geo.Origin[a]) / geo.Spacing[a];
      const double r = std::round(c);
      index[i][a] = std::fabs(c - r) < 1e-6 ? r : c;
    }
  }
  const ParallelFor parallel = SMPParallelFor();
  const auto t0 = Clock::now();
  ElementRasterizer raster(index, cells, vpc, geo.G);
  const std::vector<std::int64_t> owner = VoxelOwners(raster, geo.G, parallel);
  this->UpdateProgress(0.2);

  // Seeds to elements.
  std::vector<std::int64_t> objectVoxels, backgroundVoxels;
  if (!SeedVoxels(objectSeeds, geo, "object", objectVoxels, error) ||
    !SeedVoxels(backgroundSeeds, geo, "background", backgroundVoxels, error))
  {
    vtkErrorMacro("Super-Voxel Cut: " << error);
    return 0;
  }
  CutProblem pr;
  pr.Hard.assign(nCells, 0);
  for (std::int64_t v : objectVoxels)
  {
    if (owner[v] < 0)
    {
      vtkErrorMacro("Super-Voxel Cut: an object seed lies outside the mesh.");
      return 0;
    }
    pr.Hard[owner[v]] = 1;
  }
  for (std::int64_t v : backgroundVoxels)
  {
    if (owner[v] < 0)
    {
      vtkErrorMacro("Super-Voxel Cut: a background seed lies outside the mesh.");
      return 0;
    }
    if (pr.Hard[owner[v]] == 1)
    {
      vtkErrorMacro("Super-Voxel Cut: element " << owner[v]
                                                << " holds both an object and a background seed; move one of them.");
      return 0;
    }
    pr.Hard[owner[v]] = 2;
  }

  // Graph.
  pr.Value.resize(nCells);
  pr.Size.resize(nCells);
  for (vtkIdType c = 0; c < nCells; ++c)
  {
    pr.Value[c] = meanArray->GetComponent(c, 0);
    pr.Size[c] = std::max(0.0, countArray->GetComponent(c, 0));
  }
  const MeshAdjacency adj = BuildAdjacency(world, cells, vpc);
  pr.A = adj.A;
  pr.B = adj.B;
  // Contact in voxel faces: a 2D edge in pixel lengths, a 3D face in voxel-face areas.
  const double unit = vpc == 3 ? 0.5 * (geo.Spacing[0] + geo.Spacing[1])
                               : std::pow(geo.Spacing[0] * geo.Spacing[1] * geo.Spacing[2], 2.0 / 3.0);
  pr.Contact.resize(adj.Measure.size());
  for (size_t e = 0; e < adj.Measure.size(); ++e)
  {
    pr.Contact[e] = this->ScaleByContact ? adj.Measure[e] / unit : 1.0;
  }
  // Seed histograms: the voxels of the seed elements when the image is there, else their means
  // weighted by their voxel counts.
  std::vector<double> values;
  if (image)
  {
    std::string warning;
    vtkDataArray* array = ChosenArray(image, this->GetInputArrayInformation(0), error, warning);
    if (!warning.empty())
    {
      vtkWarningMacro("Super-Voxel Cut: " << warning);
    }
    if (!array || !ToDouble(array, values, error))
    {
      vtkErrorMacro("Super-Voxel Cut: " << error);
      return 0;
    }
    for (std::int64_t v = 0; v < geo.G.Size(); ++v)
    {
      const std::int64_t e = owner[v];
      if (e >= 0 && pr.Hard[e])
      {
        (pr.Hard[e] == 1 ? pr.ObjectSamples : pr.BackgroundSamples).push_back(values[v]);
      }
    }
  }
  else
  {
    for (vtkIdType c = 0; c < nCells; ++c)
    {
      if (pr.Hard[c])
      {
        auto& s = pr.Hard[c] == 1 ? pr.ObjectSamples : pr.BackgroundSamples;
        auto& w = pr.Hard[c] == 1 ? pr.ObjectWeights : pr.BackgroundWeights;
        s.push_back(pr.Value[c]);
        w.push_back(std::max(1.0, pr.Size[c]));
      }
    }
  }
  if (image && this->VoxelRegionTerm)
  {
    pr.PixelValue = values.data();
    pr.PixelOwner = owner.data();
    pr.PixelTotal = geo.G.Size();
  }
  const double setupSeconds = std::chrono::duration<double>(Clock::now() - t0).count();
  this->UpdateProgress(0.4);
  const CutResult cut = BoykovJollyCut(pr, par);
  if (!cut.Error.empty())
  {
    vtkErrorMacro("Super-Voxel Cut: " << cut.Error);
    return 0;
  }
  if (this->GetAbortExecute())
  {
    return 1;
  }
  this->UpdateProgress(0.7);

  // Output 0: the mesh with labels.
  output->ShallowCopy(mesh);
  vtkNew<vtkUnsignedCharArray> label;
  label->SetName("Label");
  label->SetNumberOfTuples(nCells);
  std::copy(cut.Label.begin(), cut.Label.end(), label->GetPointer(0));
  output->GetCellData()->AddArray(label);
  output->GetCellData()->SetActiveScalars("Label");

  // Output 1: boundary faces of the object, oriented out of it, on the mesh's points.
  vtkNew<vtkCellArray> faces;
  auto addFace = [&](std::int64_t element, int local) {
    std::int64_t f[3];
    OutwardFace(world, cells.data() + element * vpc, vpc, local, f);
    const vtkIdType ids[3] = { f[0], f[1], f[2] };
    faces->InsertNextCell(vpc - 1, ids);
  };
  for (size_t e = 0; e < adj.A.size(); ++e)
  {
    const std::uint8_t la = cut.Label[adj.A[e]], lb = cut.Label[adj.B[e]];
    if (la != lb)
    {
      la ? addFace(adj.A[e], adj.LocalA[e]) : addFace(adj.B[e], adj.LocalB[e]);
    }
  }
  for (size_t h = 0; h < adj.HullElement.size(); ++h)
  {
    if (cut.Label[adj.HullElement[h]])
    {
      addFace(adj.HullElement[h], adj.HullFace[h]);
    }
  }
  vtkNew<vtkPolyData> surface;
  surface->SetPoints(mesh->GetPoints());
  if (vpc == 3)
  {
    surface->SetLines(faces);
    vtkNew<vtkStripper> stripper;
    stripper->SetInputData(surface);
    stripper->JoinContiguousSegmentsOn();
    stripper->Update();
    boundary->ShallowCopy(stripper->GetOutput());
  }
  else
  {
    surface->SetPolys(faces);
    boundary->ShallowCopy(surface);
  }

  // Output 2: labels on the image grid.
  const Grid& g = geo.G;
  labelImage->SetExtent(0, g.Dims[0] - 1, 0, g.Dims[1] - 1, 0, g.Dims[2] - 1);
  labelImage->SetSpacing(geo.Spacing);
  labelImage->SetOrigin(geo.Origin);
  if (image)
  {
    labelImage->SetExtent(image->GetExtent());
    labelImage->SetOrigin(image->GetOrigin());
    labelImage->SetDirectionMatrix(image->GetDirectionMatrix());
  }
  vtkNew<vtkUnsignedCharArray> voxels;
  voxels->SetName("Label");
  voxels->SetNumberOfTuples(g.Size());
  unsigned char* out = voxels->GetPointer(0);
  parallel(g.Size(), 65536, [&](std::int64_t b, std::int64_t e) {
    for (std::int64_t v = b; v < e; ++v)
    {
      out[v] = owner[v] >= 0 ? cut.Label[owner[v]] : 0;
    }
  });
  labelImage->GetPointData()->SetScalars(voxels);

  std::int64_t objectElements = std::count(cut.Label.begin(), cut.Label.end(), 1);
  for (vtkDataObject* d : { static_cast<vtkDataObject*>(output), static_cast<vtkDataObject*>(labelImage) })
  {
    AddFieldValue(d, "Sigma", cut.Sigma);
    AddFieldValue(d, "Bins", cut.Bins);
    AddFieldValue(d, "Flow", cut.Flow);
    AddFieldValue(d, "ObjectElements", static_cast<double>(objectElements));
    AddFieldValue(d, "SetupSeconds", setupSeconds);
    AddFieldValue(d, "GraphSeconds", cut.GraphSeconds);
    AddFieldValue(d, "FlowSeconds", cut.FlowSeconds);
    AddFieldValue(d, "CutTotalSeconds", std::chrono::duration<double>(Clock::now() - start).count());
  }
  this->UpdateProgress(1.0);
  return 1;
}

void vtkSuperVoxelCut::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Bins: " << this->Bins << "\n"
     << indent << "Sigma: " << this->Sigma << "\n"
     << indent << "Lambda: " << this->Lambda << "\n"
     << indent << "ScaleByContact: " << this->ScaleByContact << "\n"
     << indent << "VoxelRegionTerm: " << this->VoxelRegionTerm << "\n";
}
