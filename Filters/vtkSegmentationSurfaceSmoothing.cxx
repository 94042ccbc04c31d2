#include "vtkSegmentationSurfaceSmoothing.h"

#include "Contract.h"
#include "SurfaceSmoothing.h"
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
#include <chrono>

vtkStandardNewMacro(vtkSegmentationSurfaceSmoothing);

vtkSegmentationSurfaceSmoothing::vtkSegmentationSurfaceSmoothing()
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
  return featuremesh::RunFilter(this, "Segmentation Surface Smoothing", outputVector, this->FailedAt, this->FailedAtTime, [&]() -> int {
    using namespace featuremesh;
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    vtkUnstructuredGrid* input = vtkUnstructuredGrid::GetData(inputVector[0], 0);
    vtkPolyData* boundary = vtkPolyData::GetData(outputVector, 0);
    vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector, 1);
    std::string error;
    auto fail = [&](const std::string& why) {
      vtkErrorMacro("Segmentation Surface Smoothing: " << why);
      return 0;
    };

    const SurfaceSmoothingParameters& par = *this;
    error = this->ValidateProperties();
    if (!error.empty())
    {
      return fail(error);
    }
    if (IsEmptyPiece(outputVector, input))
    {
      return 1;
    }
    if (!input || input->GetNumberOfCells() == 0)
    {
      return fail("the labelled mesh is empty.");
    }
    vtkDataArray* labelArray = input->GetCellData()->GetArray(names::Label);
    if (!labelArray || labelArray->GetNumberOfComponents() != 1)
    {
      return fail("the mesh has no Label cell array; connect the Super-Voxel Cut's first output.");
    }
    ImageGeometry geometry;
    if (!ImageGeometryFromFieldData(input, geometry, error))
    {
      return fail(error);
    }
    SimplexMesh mesh;
    if (!ToSimplexMesh(input, geometry, mesh, error))
    {
      return fail(error);
    }
    const vtkIdType nCells = input->GetNumberOfCells();
    std::vector<std::uint8_t> label(nCells);
    for (vtkIdType c = 0; c < nCells; ++c)
    {
      const double l = labelArray->GetComponent(c, 0);
      if (!(l >= 0.0 && l <= 255.0 && l == std::floor(l)))
      {
        return fail("the Label cell array holds " + std::to_string(l) +
          "; it must be 0 (background) or a whole number 1..255 (objects), as the Super-Voxel Cut writes it.");
      }
      label[c] = static_cast<std::uint8_t>(l);
    }
    this->UpdateProgress(0.05);

    const ParallelFor parallel = SMPParallelFor();
    const SurfaceSmoothingResult result =
      SmoothSegmentationSurface(mesh, label, par, parallel, AlgorithmProgress(this, 0.05, 0.85));
    if (result.Aborted)
    {
      return 1;
    }
    if (!result.Error.empty())
    {
      return fail(result.Error);
    }

    // Output 1: the input with its points moved, the stale statistics dropped (the voxels an element
    // owns changed with it) and the quality recomputed; without VolumeMesh, the input.
    output->ShallowCopy(input);
    DropVoxelOwners(output);
    // The input's points, the moved ones replaced (unmoved points keep their world coordinates bit
    // for bit).
    auto movedPoints = [&](const std::vector<std::array<double, 3>>& index) {
      vtkNew<vtkPoints> points;
      points->SetDataTypeToDouble();
      points->SetNumberOfPoints(static_cast<vtkIdType>(index.size()));
      for (std::size_t i = 0; i < index.size(); ++i)
      {
        const vtkIdType id = static_cast<vtkIdType>(i);
        points->SetPoint(id, index[i] != mesh.Points()[i] ? geometry.IndexToWorld(index[i]).data() : input->GetPoint(id));
      }
      return points;
    };
    const bool is2D = geometry.Is2D();
    // The smallest angle before: the input's quality array (stages 2 and 3 write it), else computed.
    const char* qualityName = is2D ? names::MinAngle : names::MinDihedralAngle;
    std::vector<double> minAngle, radiusRatio;
    double before = 180.0;
    if (vtkDataArray* quality = input->GetCellData()->GetArray(qualityName))
    {
      before = quality->GetRange(0)[0];
    }
    else
    {
      ElementQuality(mesh, minAngle, radiusRatio, parallel);
      before = *std::min_element(minAngle.begin(), minAngle.end());
    }
    double after = before;
    vtkSmartPointer<vtkPoints> points = input->GetPoints();
    if (par.VolumeMesh)
    {
      points = movedPoints(result.Points);
      output->SetPoints(points);
      for (const char* stale : { names::PixelCount, names::MeanIntensity, names::IntensityStdDev, names::Interpolated })
      {
        output->GetCellData()->RemoveArray(stale);
      }
      SimplexMesh moved = mesh;
      moved.SetPoints(result.Points);
      ElementQuality(moved, minAngle, radiusRatio, parallel);
      after = *std::min_element(minAngle.begin(), minAngle.end());
      for (const auto& array : { std::make_pair(qualityName, &minAngle), std::make_pair(names::RadiusRatio, &radiusRatio) })
      {
        vtkNew<vtkDoubleArray> values;
        values->SetName(array.first);
        values->SetNumberOfTuples(nCells);
        std::copy(array.second->begin(), array.second->end(), values->GetPointer(0));
        output->GetCellData()->AddArray(values);
      }
    }
    output->GetCellData()->SetActiveScalars(names::Label);
    vtkNew<vtkFloatArray> shortfall;
    shortfall->SetName(names::Shortfall);
    shortfall->SetNumberOfTuples(static_cast<vtkIdType>(result.Shortfall.size()));
    std::copy(result.Shortfall.begin(), result.Shortfall.end(), shortfall->GetPointer(0));
    output->GetPointData()->AddArray(shortfall);

    // Output 0: the boundary, on output 1's points (or at its smoothed positions without VolumeMesh).
    BoundaryPolyData(par.VolumeMesh ? points.Get() : movedPoints(result.BoundaryPoints).Get(), result.Faces,
      mesh.VerticesPerCell() - 1, boundary);
    boundary->GetPointData()->AddArray(shortfall);

    const double change = result.ObjectMeasureBefore > 0 ? result.ObjectMeasureAfter / result.ObjectMeasureBefore - 1.0 : 0.0;
    for (vtkDataObject* d : { static_cast<vtkDataObject*>(boundary), static_cast<vtkDataObject*>(output) })
    {
      AddFieldValue(d, names::BoundaryNodes, static_cast<double>(result.BoundaryNodes));
      AddFieldValue(d, names::PinchedNodes, static_cast<double>(result.PinchedNodes));
      AddFieldValue(d, names::NonManifoldEdges, static_cast<double>(result.NonManifoldEdges));
      AddFieldValue(d, names::ShortNodes, static_cast<double>(result.ShortNodes));
      AddFieldValue(d, names::MaxShortfall, result.MaxShortfall);
      AddFieldValue(d, names::ReachedFraction, result.ReachedFraction);
      AddFieldValue(d, names::RelaxedNodes, static_cast<double>(result.RelaxedNodes));
      AddFieldValue(d, names::ObjectMeasureBefore, result.ObjectMeasureBefore);
      AddFieldValue(d, names::ObjectMeasureAfter, result.ObjectMeasureAfter);
      AddFieldValue(d, names::MeasureChange, change);
      AddFieldValue(d, is2D ? names::MinAngleBefore : names::MinDihedralAngleBefore, before);
      AddFieldValue(d, qualityName, after);
      AddFieldValue(d, names::SurfaceSeconds, result.SurfaceSeconds);
      AddFieldValue(d, names::VolumeSeconds, result.VolumeSeconds);
      AddFieldValue(d, names::TotalSeconds, std::chrono::duration<double>(Clock::now() - start).count());
    }
    AddImageGeometry(geometry, boundary);
    this->UpdateProgress(1.0);
    return 1;
  });
}

std::string vtkSegmentationSurfaceSmoothing::ValidateProperties()
{
  return featuremesh::ValidateParameters(static_cast<const featuremesh::SurfaceSmoothingParameters&>(*this));
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
