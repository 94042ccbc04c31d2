#include "vtkVoxelCut.h"

#include "BoykovJolly.h"
#include "vtkFeatureMeshSeeds.h"
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
  this->SetNumberOfInputPorts(3);
  this->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

int vtkVoxelCut::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), port == 0 ? "vtkImageData" : "vtkPointSet");
  return 1;
}

int vtkVoxelCut::RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkDataObject::SetPointDataActiveScalarInfo(outputVector->GetInformationObject(0), VTK_UNSIGNED_CHAR, 1);
  return 1;
}

int vtkVoxelCut::RequestUpdateExtent(vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  featuremesh::RequestWholeImage(inputVector[0]);
  return 1;
}

int vtkVoxelCut::RequestData(vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  using namespace featuremesh;
  const auto start = std::chrono::steady_clock::now();
  vtkImageData* image = vtkImageData::GetData(inputVector[0], 0);
  vtkPointSet* objectSeeds = vtkPointSet::GetData(inputVector[1], 0);
  vtkPointSet* backgroundSeeds = vtkPointSet::GetData(inputVector[2], 0);
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  std::string error;
  GridGeometry geo;
  if (!ImageGrid(image, geo.G, error))
  {
    vtkErrorMacro("Voxel Cut: " << error);
    return 0;
  }
  BoykovJollyParameters par;
  par.Bins = this->Bins;
  par.Sigma = this->Sigma;
  par.Lambda = this->Lambda;
  error = ValidateParameters(par);
  if (error.empty() && !(this->SeedRadius >= 0.0 && this->SeedRadius <= 50.0))
  {
    error = "the seed radius must lie in [0, 50] voxels.";
  }
  if (!error.empty())
  {
    vtkErrorMacro("Voxel Cut: " << error);
    return 0;
  }
  const double zero[3] = { 0, 0, 0 };
  IndexToWorld(image, zero, geo.Origin);
  std::copy(image->GetSpacing(), image->GetSpacing() + 3, geo.Spacing);
  std::vector<std::int64_t> objectVoxels, backgroundVoxels;
  if (!SeedVoxels(objectSeeds, geo, "object", objectVoxels, error) ||
    !SeedVoxels(backgroundSeeds, geo, "background", backgroundVoxels, error))
  {
    vtkErrorMacro("Voxel Cut: " << error);
    return 0;
  }
  CutProblem pr;
  std::string warning;
  vtkDataArray* array = ChosenArray(image, this->GetInputArrayInformation(0), error, warning);
  if (!warning.empty())
  {
    vtkWarningMacro("Voxel Cut: " << warning);
  }
  if (!array || !ToDouble(array, pr.Value, error))
  {
    vtkErrorMacro("Voxel Cut: " << error);
    return 0;
  }
  const Grid& g = geo.G;
  const std::int64_t n = g.Size();
  pr.Hard.assign(n, 0);
  for (std::int64_t v : objectVoxels)
  {
    pr.Hard[v] = 1;
  }
  for (std::int64_t v : backgroundVoxels)
  {
    if (pr.Hard[v] == 1)
    {
      vtkErrorMacro("Voxel Cut: a voxel is seeded both as object and as background; move one of the seeds.");
      return 0;
    }
    pr.Hard[v] = 2;
  }
  // Seed neighbourhoods: voxels within SeedRadius of each seed voxel.
  const int r = static_cast<int>(std::floor(this->SeedRadius));
  auto gather = [&](const std::vector<std::int64_t>& voxels, std::vector<double>& samples) {
    for (std::int64_t v : voxels)
    {
      const int k = static_cast<int>(v / g.SliceStride());
      const int j = static_cast<int>((v % g.SliceStride()) / g.Dims[0]);
      const int i = static_cast<int>(v % g.Dims[0]);
      const int rk = g.Is2D() ? 0 : r;
      for (int dk = -rk; dk <= rk; ++dk)
        for (int dj = -r; dj <= r; ++dj)
          for (int di = -r; di <= r; ++di)
          {
            if (di * di + dj * dj + dk * dk <= this->SeedRadius * this->SeedRadius && g.Contains(i + di, j + dj, k + dk))
            {
              samples.push_back(pr.Value[g.Index(i + di, j + dj, k + dk)]);
            }
          }
    }
  };
  gather(objectVoxels, pr.ObjectSamples);
  gather(backgroundVoxels, pr.BackgroundSamples);
  pr.Size.assign(n, 1.0);
  // 4-/6-connected grid, each pair one voxel face.
  const std::int64_t sx = 1, sy = g.Dims[0], sz = g.SliceStride();
  const std::int64_t edges = (g.Dims[0] - 1) * std::int64_t(g.Dims[1]) * g.Dims[2] +
    std::int64_t(g.Dims[0]) * (g.Dims[1] - 1) * g.Dims[2] + (g.Is2D() ? 0 : sz * (g.Dims[2] - 1));
  pr.A.reserve(edges);
  pr.B.reserve(edges);
  for (int k = 0; k < g.Dims[2]; ++k)
    for (int j = 0; j < g.Dims[1]; ++j)
      for (int i = 0; i < g.Dims[0]; ++i)
      {
        const std::int64_t v = g.Index(i, j, k);
        if (i + 1 < g.Dims[0])
        {
          pr.A.push_back(v);
          pr.B.push_back(v + sx);
        }
        if (j + 1 < g.Dims[1])
        {
          pr.A.push_back(v);
          pr.B.push_back(v + sy);
        }
        if (k + 1 < g.Dims[2])
        {
          pr.A.push_back(v);
          pr.B.push_back(v + sz);
        }
      }
  pr.Contact.assign(pr.A.size(), 1.0);
  this->UpdateProgress(0.2);
  const CutResult cut = BoykovJollyCut(pr, par);
  if (!cut.Error.empty())
  {
    vtkErrorMacro("Voxel Cut: " << cut.Error);
    return 0;
  }
  output->SetExtent(image->GetExtent());
  output->SetSpacing(image->GetSpacing());
  output->SetOrigin(image->GetOrigin());
  output->SetDirectionMatrix(image->GetDirectionMatrix());
  vtkNew<vtkUnsignedCharArray> labels;
  labels->SetName("Label");
  labels->SetNumberOfTuples(n);
  std::copy(cut.Label.begin(), cut.Label.end(), labels->GetPointer(0));
  output->GetPointData()->SetScalars(labels);
  AddFieldValue(output, "Sigma", cut.Sigma);
  AddFieldValue(output, "Bins", cut.Bins);
  AddFieldValue(output, "Flow", cut.Flow);
  AddFieldValue(output, "GraphSeconds", cut.GraphSeconds);
  AddFieldValue(output, "FlowSeconds", cut.FlowSeconds);
  AddFieldValue(output, "TotalSeconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  this->UpdateProgress(1.0);
  return 1;
}

void vtkVoxelCut::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Bins: " << this->Bins << "\n"
     << indent << "Sigma: " << this->Sigma << "\n"
     << indent << "Lambda: " << this->Lambda << "\n"
     << indent << "SeedRadius: " << this->SeedRadius << "\n";
}
