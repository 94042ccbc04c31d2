#include "vtkDelaunayImageMesh.h"

#include "Contract.h"
#include "DelaunayMesh.h"
#include "vtkFeatureMeshUtilities.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
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
#include "vtkPoints.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <chrono>
#include <cmath>

vtkStandardNewMacro(vtkDelaunayImageMesh);

vtkDelaunayImageMesh::vtkDelaunayImageMesh()
{
  this->SetNumberOfInputPorts(2);
  this->SetInputArrayToProcess(
    0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

void vtkDelaunayImageMesh::SetBackend(int backend)
{
  featuremesh::SetClampedParameter(this, this->featuremesh::DelaunayOptions::Backend, backend, TETGEN, CGAL);
}

int vtkDelaunayImageMesh::GetBackend()
{
  return static_cast<int>(this->featuremesh::DelaunayOptions::Backend);
}

int vtkDelaunayImageMesh::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), port == 0 ? "vtkPointSet" : "vtkImageData");
  return 1;
}

int vtkDelaunayImageMesh::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  featuremesh::RequestWholeImage(inputVector[1]);
  featuremesh::StopVoxelOwnersRequest(inputVector[0]);
  featuremesh::StopVoxelOwnersRequest(inputVector[1]);
  return 1;
}

int vtkDelaunayImageMesh::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return featuremesh::RunFilter(this, "Delaunay Image Mesh", outputVector, this->FailedAt, this->FailedAtTime, [&]() -> int {
    using namespace featuremesh;
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    vtkPointSet* nodes = vtkPointSet::GetData(inputVector[0], 0);
    vtkSmartPointer<vtkImageData> image =
      VoxelValuedImage(vtkImageData::GetData(inputVector[1], 0), this->GetInputArrayInformation(0));
    vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector, 0);
    DropVoxelOwners(output); // the last run's map, which the executive's reset leaves on the object
    std::string error, warning;
    ImageGeometry geometry;
    if (IsEmptyPiece(outputVector, nodes) || IsEmptyPiece(outputVector, image))
    {
      return 1;
    }
    if (!nodes || !image)
    {
      vtkErrorMacro("Delaunay Image Mesh: both the Nodes (point set) and the Image inputs are required.");
      return 0;
    }
    if (!ImageGeometryOf(image, geometry, error))
    {
      vtkErrorMacro("Delaunay Image Mesh: " << error);
      return 0;
    }
    const bool is2D = geometry.Is2D();
    const vtkIdType nIn = nodes->GetNumberOfPoints();
    // The image is read in its own type (checked as ToDouble would, without the copy).
    vtkDataArray* values = ChosenArray(image, this->GetInputArrayInformation(0), error, warning);
    const bool valuesOk = values && CheckDouble(values, error);
    if (!warning.empty())
    {
      vtkWarningMacro("Delaunay Image Mesh: " << warning);
    }
    if (!valuesOk)
    {
      vtkErrorMacro("Delaunay Image Mesh: " << error);
      return 0;
    }

    std::vector<std::array<double, 3>> index = PointsOf(nodes);
    error = ImageMeshNodes(geometry, index);
    if (error.empty())
    {
      error = ValidateParameters(*this, is2D);
    }
    if (!error.empty())
    {
      vtkErrorMacro("Delaunay Image Mesh: " << error);
      return 0;
    }
    const vtkIdType firstSteiner = static_cast<vtkIdType>(index.size());
    this->UpdateProgress(0.1);

    // Delaunay in frame coordinates: the right metric for anisotropic voxels, and the same mesh
    // whatever the image's origin, direction or mirror.
    auto t0 = Clock::now();
    std::vector<std::array<double, 3>> frame(index.size());
    std::transform(index.begin(), index.end(), frame.begin(), [&](const std::array<double, 3>& p) { return geometry.IndexToFrame(p); });
    const DelaunayOptions o = *this;
    // TetGen has no progress or abort of its own: it runs on its own thread, owning its input.
    DelaunayResult delaunay;
    if (is2D)
    {
      delaunay = Triangulate2D(frame);
    }
    else if (!RunWithHeartbeat<DelaunayResult>([frame, o]() { return Tetrahedralize(frame, o); },
               AlgorithmProgress(this, 0.1, 0.5), delaunay))
    {
      return 1;
    }
    if (!delaunay.Error.empty())
    {
      vtkErrorMacro("Delaunay Image Mesh: " << delaunay.Error);
      return 0;
    }
    const double delaunaySeconds = std::chrono::duration<double>(Clock::now() - t0).count();
    this->UpdateProgress(0.5);
    // Points the mesher added (TetGen refinement).
    for (size_t i = index.size(); i < delaunay.Points.size(); ++i)
    {
      index.push_back(geometry.FrameToIndex(delaunay.Points[i]));
    }

    t0 = Clock::now();
    const ParallelFor parallel = SMPParallelFor();
    const SimplexMesh mesh(geometry, std::move(index), std::move(delaunay.Cells), delaunay.VerticesPerCell);
    const vtkSmartPointer<vtkIntArray> owner = NewVoxelOwnerArray(outputVector, geometry.Size());
    const ElementStatistics stats = ImageElementStatistics(ElementRasterizer(mesh), values, parallel,
      AlgorithmProgress(this, 0.5, 0.9), owner ? owner->GetPointer(0) : nullptr);
    if (stats.Aborted)
    {
      return 1;
    }
    std::vector<double> minAngle, radiusRatio;
    ElementQuality(mesh, minAngle, radiusRatio, parallel);
    const double statisticsSeconds = std::chrono::duration<double>(Clock::now() - t0).count();
    this->UpdateProgress(0.9);
    WriteImageMesh(mesh, stats, minAngle, radiusRatio, output);
    AttachVoxelOwners(output, owner);

    // Node arrays pass through; added nodes get NodeType Added and Fixed 1 (corners) or 0 (refinement).
    const vtkIdType nPts = mesh.NumberOfPoints();
    PassNodeArrays(nodes->GetPointData(), nIn, output->GetPointData(), nPts, firstSteiner);

    AddFieldValue(output, names::AddedNodes, static_cast<double>(nPts - nIn));
    AddFieldValue(output, names::DelaunayBackend, is2D || this->GetBackend() == CGAL ? 1.0 : 0.0);
    AddFieldValue(output, names::DelaunaySeconds, delaunaySeconds);
    AddFieldValue(output, names::StatisticsSeconds, statisticsSeconds);
    AddFieldValue(output, names::TotalSeconds, std::chrono::duration<double>(Clock::now() - start).count());
    this->UpdateProgress(1.0);
    return 1;
  });
}

std::string vtkDelaunayImageMesh::ValidateProperties()
{
  return featuremesh::ValidateParameters(static_cast<const featuremesh::DelaunayOptions&>(*this), false);
}

void vtkDelaunayImageMesh::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Backend: " << (this->GetBackend() == CGAL ? "CGAL" : "TetGen") << "\n";
  os << indent << "QualityRefinement: " << this->QualityRefinement << "\n";
  os << indent << "RadiusEdgeRatio: " << this->RadiusEdgeRatio << "\n";
  os << indent << "MinDihedralAngle: " << this->MinDihedralAngle << "\n";
}
