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

namespace
{
// Beyond this TetGen needs tens of GB and minutes; Feature Nodes places ~0.5 % of the voxels.
constexpr vtkIdType MaximumNodes = 20000000;
}

vtkDelaunayImageMesh::vtkDelaunayImageMesh()
{
  const featuremesh::DelaunayOptions defaults;
  this->Backend = static_cast<int>(defaults.Backend);
  this->QualityRefinement = defaults.QualityRefinement;
  this->RadiusEdgeRatio = defaults.RadiusEdgeRatio;
  this->MinDihedralAngle = defaults.MinDihedralAngle;
  this->SetNumberOfInputPorts(2);
  this->SetInputArrayToProcess(
    0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
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
    if (nIn < (is2D ? 3 : 4))
    {
      vtkErrorMacro("Delaunay Image Mesh: " << nIn << " nodes are too few; a " << (is2D ? "triangle" : "tetrahedral")
                                            << " mesh needs at least " << (is2D ? 3 : 4) << ".");
      return 0;
    }
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

    // Nodes in index space: on voxel centres when Feature Nodes placed them, anywhere else too (the
    // rasteriser owns each voxel centre exactly whatever the nodes, as after stage 3).
    std::vector<std::array<double, 3>> index = PointsOf(nodes);
    vtkIdType outside = 0, offPlane = 0;
    for (auto& p : index)
    {
      p = geometry.WorldToIndex(p);
      bool in = true;
      for (int a = 0; a < 3; ++a)
      {
        in = in && p[a] >= 0.0 && p[a] <= geometry.Dims[a] - 1.0;
      }
      outside += in ? 0 : 1;
      offPlane += (is2D && p[2] != 0.0) ? 1 : 0;
    }
    if (is2D && offPlane)
    {
      vtkErrorMacro("Delaunay Image Mesh: the image is 2D but " << offPlane
                      << " nodes lie off its slice plane; the nodes do not match the image's dimension.");
      return 0;
    }
    if (outside)
    {
      vtkErrorMacro("Delaunay Image Mesh: " << outside << " of " << nIn << " nodes lie outside the image bounds.");
      return 0;
    }
    if (nIn > MaximumNodes)
    {
      vtkErrorMacro("Delaunay Image Mesh: " << nIn << " nodes are more than the " << MaximumNodes
                                            << " this filter meshes; raise the node spacing in Feature Nodes.");
      return 0;
    }
    const std::int64_t duplicates = CountDuplicates(index);
    if (duplicates)
    {
      vtkErrorMacro("Delaunay Image Mesh: " << duplicates
                                            << " nodes duplicate other nodes; remove them (e.g. with Clean) first.");
      return 0;
    }
    if (!SpansDimension(index, is2D ? 2 : 3))
    {
      vtkErrorMacro("Delaunay Image Mesh: the nodes are " << (is2D ? "collinear" : "coplanar (or collinear)")
                                                          << "; a mesh needs nodes spanning the image's "
                                                          << (is2D ? "area." : "volume."));
      return 0;
    }
    // The mesh must tile the box: add the image corners that are not nodes yet.
    {
      std::vector<std::array<double, 3>> sorted(index);
      std::sort(sorted.begin(), sorted.end());
      for (int c = 0; c < (is2D ? 4 : 8); ++c)
      {
        const std::array<double, 3> corner = { { (c & 1) ? geometry.Dims[0] - 1.0 : 0.0,
          (c & 2) ? geometry.Dims[1] - 1.0 : 0.0, (c & 4) ? geometry.Dims[2] - 1.0 : 0.0 } };
        if (!std::binary_search(sorted.begin(), sorted.end(), corner))
        {
          index.push_back(corner);
        }
      }
    }
    const vtkIdType firstSteiner = static_cast<vtkIdType>(index.size());
    this->UpdateProgress(0.1);

    // Delaunay in frame coordinates: the right metric for anisotropic voxels, and the same mesh
    // whatever the image's origin, direction or mirror.
    auto t0 = Clock::now();
    std::vector<std::array<double, 3>> frame(index.size());
    std::transform(index.begin(), index.end(), frame.begin(), [&](const std::array<double, 3>& p) { return geometry.IndexToFrame(p); });
    DelaunayOptions o;
    o.Backend = this->Backend == CGAL ? DelaunayBackend::CGAL : DelaunayBackend::TetGen;
    o.QualityRefinement = this->QualityRefinement;
    o.RadiusEdgeRatio = this->RadiusEdgeRatio;
    o.MinDihedralAngle = this->MinDihedralAngle;
    // TetGen's refinement need not terminate beyond these bounds (its guarantee holds for a ratio of 2
    // and no angle bound): the liver's nodes never returned with a ratio of 1.0 or an angle of 25.
    if (!is2D && o.QualityRefinement &&
      (!(o.RadiusEdgeRatio >= 1.2) || !(o.MinDihedralAngle >= 0.0 && o.MinDihedralAngle <= 18.0)))
    {
      vtkErrorMacro("Delaunay Image Mesh: quality refinement needs a radius-edge ratio of at least 1.2 and a minimum "
                    "dihedral angle in [0, 18] degrees; TetGen may not terminate beyond them.");
      return 0;
    }
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
    AddFieldValue(output, names::DelaunayBackend, is2D || this->Backend == CGAL ? 1.0 : 0.0);
    AddFieldValue(output, names::DelaunaySeconds, delaunaySeconds);
    AddFieldValue(output, names::StatisticsSeconds, statisticsSeconds);
    AddFieldValue(output, names::TotalSeconds, std::chrono::duration<double>(Clock::now() - start).count());
    this->UpdateProgress(1.0);
    return 1;
  });
}

void vtkDelaunayImageMesh::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Backend: " << (this->Backend == CGAL ? "CGAL" : "TetGen") << "\n";
  os << indent << "QualityRefinement: " << this->QualityRefinement << "\n";
  os << indent << "RadiusEdgeRatio: " << this->RadiusEdgeRatio << "\n";
  os << indent << "MinDihedralAngle: " << this->MinDihedralAngle << "\n";
}
