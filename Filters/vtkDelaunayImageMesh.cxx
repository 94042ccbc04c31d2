#include "vtkDelaunayImageMesh.h"

#include "Contract.h"
#include "DelaunayImageMesh.h"
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
#include <cmath>

vtkStandardNewMacro(vtkDelaunayImageMesh);

vtkDelaunayImageMesh::vtkDelaunayImageMesh()
  : featuremesh::FilterBase(this, "Delaunay Image Mesh")
{
  this->SetNumberOfInputPorts(2);
  this->SetInputArrayToProcess(
    0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

void vtkDelaunayImageMesh::SetBackend(int backend)
{
  featuremesh::SetClampedParameter(this, this->featuremesh::DelaunayImageMeshParameters::Backend, backend, TETGEN, CGAL);
}

int vtkDelaunayImageMesh::GetBackend()
{
  return static_cast<int>(this->featuremesh::DelaunayImageMeshParameters::Backend);
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
  return this->Run(outputVector, [&]() -> int {
    using namespace featuremesh;
    vtkPointSet* nodes = vtkPointSet::GetData(inputVector[0], 0);
    vtkSmartPointer<vtkImageData> image =
      VoxelValuedImage(vtkImageData::GetData(inputVector[1], 0), this->GetInputArrayInformation(0));
    vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector, 0);
    DropVoxelOwners(output); // the last run's map, which the executive's reset leaves on the object
    if (const int done = this->Start(outputVector, { nodes, image }); done >= 0)
    {
      return done;
    }
    if (!nodes || !image)
    {
      return this->Fail("both the Nodes (point set) and the Image inputs are required.");
    }
    ImageGeometry geometry;
    // The image is read in its own type (checked as ToDouble would, without the copy).
    vtkDataArray* values = this->Frame(image, geometry) ? this->ChosenImageArray(image, this->GetInputArrayInformation(0)) : nullptr;
    std::string error;
    if (!values || !CheckDouble(values, error))
    {
      return values ? this->Fail(error) : 0;
    }
    const bool is2D = geometry.Is2D();
    const vtkIdType nIn = nodes->GetNumberOfPoints();
    std::vector<std::array<double, 3>> index = PointsOf(nodes);
    error = ImageMeshNodes(geometry, index);
    if (!error.empty() || !(error = ValidateParameters(*this, is2D)).empty())
    {
      return this->Fail(error);
    }
    const vtkIdType firstSteiner = static_cast<vtkIdType>(index.size());
    this->UpdateProgress(0.1);

    double delaunaySeconds = this->Seconds();
    DelaunayResult delaunay;
    if (!this->Triangulate(geometry, index, delaunay))
    {
      return delaunay.Error.empty() ? 1 : this->Fail(delaunay.Error); // aborted, or TetGen's error
    }
    delaunaySeconds = this->Seconds() - delaunaySeconds;
    this->UpdateProgress(0.5);

    double statisticsSeconds = this->Seconds();
    const ParallelFor parallel = SMPParallelFor();
    SimplexMesh mesh(geometry, std::move(index), std::move(delaunay.Cells), delaunay.VerticesPerCell);
    mesh.SortElementsSpatially();
    const vtkSmartPointer<vtkIntArray> owner = NewVoxelOwnerArray(outputVector, geometry.Size());
    const ElementStatistics stats = ImageElementStatistics(ElementRasterizer(mesh), values, parallel,
      AlgorithmProgress(this, 0.5, 0.9), owner ? owner->GetPointer(0) : nullptr);
    if (stats.Aborted)
    {
      return 1;
    }
    std::vector<double> minAngle, radiusRatio;
    ElementQuality(mesh, minAngle, radiusRatio, parallel);
    statisticsSeconds = this->Seconds() - statisticsSeconds;
    this->UpdateProgress(0.9);
    WriteImageMesh(mesh, stats, minAngle, radiusRatio, output);
    AttachVoxelOwners(output, owner);
    // Node arrays pass through; added nodes get NodeType Added and Fixed 1 (corners) or 0 (refinement).
    const vtkIdType nPts = mesh.NumberOfPoints();
    PassNodeArrays(nodes->GetPointData(), nIn, output->GetPointData(), nPts, firstSteiner);
    AddFieldValues(output, { { names::AddedNodes, static_cast<double>(nPts - nIn) },
                             { names::DelaunayBackend, is2D || this->GetBackend() == CGAL ? 1.0 : 0.0 },
                             { names::DelaunaySeconds, delaunaySeconds }, { names::StatisticsSeconds, statisticsSeconds },
                             { names::TotalSeconds, this->Seconds() } });
    this->UpdateProgress(1.0);
    return 1;
  });
}

bool vtkDelaunayImageMesh::Triangulate(
  const featuremesh::ImageGeometry& geometry, std::vector<std::array<double, 3>>& index, featuremesh::DelaunayResult& delaunay)
{
  using namespace featuremesh;
  // Delaunay in frame coordinates: the right metric for anisotropic voxels, and the same mesh
  // whatever the image's origin, direction or mirror.
  std::vector<std::array<double, 3>> frame(index.size());
  std::transform(index.begin(), index.end(), frame.begin(), [&](const std::array<double, 3>& p) { return geometry.IndexToFrame(p); });
  const DelaunayImageMeshParameters o = *this;
  // TetGen has no progress or abort of its own: it runs on its own thread, owning its input.
  if (geometry.Is2D())
  {
    delaunay = Triangulate2D(frame);
  }
  else if (!RunWithHeartbeat<DelaunayResult>([frame, o]() { return Tetrahedralize(frame, o); },
             AlgorithmProgress(this, 0.1, 0.5), delaunay))
  {
    return false;
  }
  if (!delaunay.Error.empty())
  {
    return false;
  }
  // Points the mesher added (TetGen refinement).
  for (size_t i = index.size(); i < delaunay.Points.size(); ++i)
  {
    index.push_back(geometry.FrameToIndex(delaunay.Points[i]));
  }
  return true;
}

std::string vtkDelaunayImageMesh::ValidateProperties()
{
  return featuremesh::ValidateParameters(static_cast<const featuremesh::DelaunayImageMeshParameters&>(*this), false);
}

void vtkDelaunayImageMesh::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Backend: " << (this->GetBackend() == CGAL ? "CGAL" : "TetGen") << "\n";
  os << indent << "QualityRefinement: " << this->QualityRefinement << "\n";
  os << indent << "RadiusEdgeRatio: " << this->RadiusEdgeRatio << "\n";
  os << indent << "MinDihedralAngle: " << this->MinDihedralAngle << "\n";
}
