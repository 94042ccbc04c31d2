#include "vtkSegmentationSurfaceSmoothing.h"

#include "Contract.h"
#include "SegmentationSurfaceSmoothing.h"
#include "vtkFeatureMeshUtilities.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkPointData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <cmath>

namespace
{
// The Label cell array as 0 (background) or 1..255 (objects); false with `error` otherwise.
bool CellLabels(vtkUnstructuredGrid* input, std::vector<std::uint8_t>& label, std::string& error)
{
  vtkDataArray* labelArray = input->GetCellData()->GetArray(featuremesh::names::Label);
  if (!labelArray || labelArray->GetNumberOfComponents() != 1)
  {
    error = "the mesh has no Label cell array; connect the Super-Voxel Cut's first output.";
    return false;
  }
  const vtkIdType nCells = input->GetNumberOfCells();
  label.resize(nCells);
  for (vtkIdType c = 0; c < nCells; ++c)
  {
    const double l = labelArray->GetComponent(c, 0);
    if (!(l >= 0.0 && l <= 255.0 && l == std::floor(l)))
    {
      error = "the Label cell array holds " + std::to_string(l) +
        "; it must be 0 (background) or a whole number 1..255 (objects), as the Super-Voxel Cut writes it.";
      return false;
    }
    label[c] = static_cast<std::uint8_t>(l);
  }
  return true;
}

// The input's points, the moved ones replaced (unmoved points keep their world coordinates bit for bit).
vtkSmartPointer<vtkPoints> MovedPoints(const featuremesh::SimplexMesh& mesh, const featuremesh::ImageGeometry& geometry,
  vtkUnstructuredGrid* input, const std::vector<std::array<double, 3>>& index)
{
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(index.size()));
  for (std::size_t i = 0; i < index.size(); ++i)
  {
    const vtkIdType id = static_cast<vtkIdType>(i);
    points->SetPoint(id, index[i] != mesh.Points()[i] ? geometry.IndexToWorld(index[i]).data() : input->GetPoint(id));
  }
  return points;
}

// Output 1 with the smoothed volume mesh's points: the stale image statistics dropped, the quality
// recomputed; returns its smallest angle.
double MoveVolumeMesh(const featuremesh::SimplexMesh& mesh, const featuremesh::ImageGeometry& geometry,
  vtkUnstructuredGrid* input, const std::vector<std::array<double, 3>>& moved, const char* qualityName,
  const featuremesh::ParallelFor& parallel, vtkUnstructuredGrid* output)
{
  namespace names = featuremesh::names;
  output->SetPoints(MovedPoints(mesh, geometry, input, moved));
  for (const char* stale : { names::PixelCount, names::MeanIntensity, names::IntensityStdDev, names::Interpolated })
  {
    output->GetCellData()->RemoveArray(stale);
  }
  featuremesh::SimplexMesh movedMesh = mesh;
  movedMesh.SetPoints(moved);
  std::vector<double> minAngle, radiusRatio;
  featuremesh::ElementQuality(movedMesh, minAngle, radiusRatio, parallel);
  for (const auto& array : { std::make_pair(qualityName, &minAngle), std::make_pair(names::RadiusRatio, &radiusRatio) })
  {
    vtkNew<vtkDoubleArray> values;
    values->SetName(array.first);
    values->SetNumberOfTuples(static_cast<vtkIdType>(array.second->size()));
    std::copy(array.second->begin(), array.second->end(), values->GetPointer(0));
    output->GetCellData()->AddArray(values);
  }
  return *std::min_element(minAngle.begin(), minAngle.end());
}
} // namespace

vtkStandardNewMacro(vtkSegmentationSurfaceSmoothing);

vtkSegmentationSurfaceSmoothing::vtkSegmentationSurfaceSmoothing()
  : featuremesh::FilterBase(this, "Segmentation Surface Smoothing")
{
  this->SetNumberOfOutputPorts(2);
}

void vtkSegmentationSurfaceSmoothing::SetMethod(int method)
{
  featuremesh::SetClampedParameter(this, this->Method, method, LAPLACIAN, TAUBIN);
}

int vtkSegmentationSurfaceSmoothing::GetMethod()
{
  return static_cast<int>(this->Method);
}

int vtkSegmentationSurfaceSmoothing::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkUnstructuredGrid");
  return 1;
}

int vtkSegmentationSurfaceSmoothing::FillOutputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkDataObject::DATA_TYPE_NAME(), port == 0 ? "vtkPolyData" : "vtkUnstructuredGrid");
  return 1;
}

int vtkSegmentationSurfaceSmoothing::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return this->Run(outputVector, [&]() -> int {
    using namespace featuremesh;
    vtkUnstructuredGrid* input = vtkUnstructuredGrid::GetData(inputVector[0], 0);
    vtkPolyData* boundary = vtkPolyData::GetData(outputVector, 0);
    vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector, 1);
    if (const int done = this->Start(outputVector, { input }); done >= 0)
    {
      return done;
    }
    if (!input || input->GetNumberOfCells() == 0)
    {
      return this->Fail("the labelled mesh is empty.");
    }
    std::string error;
    ImageGeometry geometry;
    SimplexMesh mesh;
    std::vector<std::uint8_t> label;
    if (!CellLabels(input, label, error) || !ImageGeometryFromFieldData(input, geometry, error) ||
      !ToSimplexMesh(input, geometry, mesh, error))
    {
      return this->Fail(error);
    }
    this->UpdateProgress(0.05);

    const SegmentationSurfaceSmoothingParameters& par = *this;
    const ParallelFor parallel = SMPParallelFor();
    const SegmentationSurfaceSmoothingResult result =
      SmoothSegmentationSurface(mesh, label, par, parallel, AlgorithmProgress(this, 0.05, 0.85));
    if (result.Aborted || !result.Error.empty())
    {
      return result.Aborted ? 1 : this->Fail(result.Error);
    }

    // Output 1: the input with its points moved, the stale statistics dropped (the voxels an element
    // owns changed with it) and the quality recomputed; without VolumeMesh, the input.
    output->ShallowCopy(input);
    DropVoxelOwners(output);
    const bool is2D = geometry.Is2D();
    const char* qualityName = is2D ? names::MinAngle : names::MinDihedralAngle;
    // The smallest angle before: the input's quality array (stages 2 and 3 write it), else computed.
    std::vector<double> minAngle, radiusRatio;
    vtkDataArray* quality = input->GetCellData()->GetArray(qualityName);
    if (!quality)
    {
      ElementQuality(mesh, minAngle, radiusRatio, parallel);
    }
    const double before = quality ? quality->GetRange(0)[0] : *std::min_element(minAngle.begin(), minAngle.end());
    const double after = par.VolumeMesh ? MoveVolumeMesh(mesh, geometry, input, result.Points, qualityName, parallel, output) : before;
    output->GetCellData()->SetActiveScalars(names::Label);
    vtkNew<vtkFloatArray> shortfall;
    shortfall->SetName(names::Shortfall);
    shortfall->SetNumberOfTuples(static_cast<vtkIdType>(result.Shortfall.size()));
    std::copy(result.Shortfall.begin(), result.Shortfall.end(), shortfall->GetPointer(0));
    output->GetPointData()->AddArray(shortfall);

    // Output 0: the boundary, on output 1's points (or at its smoothed positions without VolumeMesh).
    BoundaryPolyData(par.VolumeMesh ? output->GetPoints() : MovedPoints(mesh, geometry, input, result.BoundaryPoints).Get(),
      result.Faces, mesh.VerticesPerCell() - 1, boundary);
    boundary->GetPointData()->AddArray(shortfall);
    const double change = result.ObjectMeasureBefore > 0 ? result.ObjectMeasureAfter / result.ObjectMeasureBefore - 1.0 : 0.0;
    for (vtkDataObject* d : { static_cast<vtkDataObject*>(boundary), static_cast<vtkDataObject*>(output) })
    {
      AddFieldValues(d, { { names::BoundaryNodes, static_cast<double>(result.BoundaryNodes) },
                          { names::PinchedNodes, static_cast<double>(result.PinchedNodes) },
                          { names::NonManifoldEdges, static_cast<double>(result.NonManifoldEdges) },
                          { names::ShortNodes, static_cast<double>(result.ShortNodes) },
                          { names::MaxShortfall, result.MaxShortfall }, { names::ReachedFraction, result.ReachedFraction },
                          { names::RelaxedNodes, static_cast<double>(result.RelaxedNodes) },
                          { names::ObjectMeasureBefore, result.ObjectMeasureBefore },
                          { names::ObjectMeasureAfter, result.ObjectMeasureAfter }, { names::MeasureChange, change },
                          { is2D ? names::MinAngleBefore : names::MinDihedralAngleBefore, before }, { qualityName, after },
                          { names::SurfaceSeconds, result.SurfaceSeconds }, { names::VolumeSeconds, result.VolumeSeconds },
                          { names::TotalSeconds, this->Seconds() } });
    }
    AddImageGeometry(geometry, boundary);
    this->UpdateProgress(1.0);
    return 1;
  });
}

std::string vtkSegmentationSurfaceSmoothing::ValidateProperties()
{
  return featuremesh::ValidateParameters(static_cast<const featuremesh::SegmentationSurfaceSmoothingParameters&>(*this));
}

void vtkSegmentationSurfaceSmoothing::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Method: " << (this->Method == featuremesh::SurfaceSmoothingMethod::Laplacian ? "Laplacian" : "Taubin") << "\n";
  os << indent << "Iterations: " << this->Iterations << "\n";
  os << indent << "Relaxation: " << this->Relaxation << "\n";
  os << indent << "PassBand: " << this->PassBand << "\n";
  os << indent << "VolumeMesh: " << this->VolumeMesh << "\n";
  os << indent << "MinAngle: " << this->MinAngle << "\n";
  os << indent << "MinDihedralAngle: " << this->MinDihedralAngle << "\n";
  os << indent << "RelaxationRings: " << this->RelaxationRings << "\n";
}
