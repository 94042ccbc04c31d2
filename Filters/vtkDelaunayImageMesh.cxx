#include "vtkDelaunayImageMesh.h"

#include "DelaunayMesh.h"
#include "ElementRasterizer.h"
#include "FeatureNodes.h"
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
#include "vtkStringArray.h"
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

int vtkDelaunayImageMesh::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), port == 0 ? "vtkPointSet" : "vtkImageData");
  return 1;
}

int vtkDelaunayImageMesh::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  featuremesh::RequestWholeImage(inputVector[1]);
  return 1;
}

int vtkDelaunayImageMesh::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  using namespace featuremesh;
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  EnsureThreadedBackend();
  vtkPointSet* nodes = vtkPointSet::GetData(inputVector[0], 0);
  vtkImageData* image = vtkImageData::GetData(inputVector[1], 0);
  vtkUnstructuredGrid* output = vtkUnstructuredGrid::GetData(outputVector, 0);
  std::string error;
  Grid grid;
  if (!nodes || !image)
  {
    vtkErrorMacro("Delaunay Image Mesh: both the Nodes (point set) and the Image inputs are required.");
    return 0;
  }
  if (!ImageGrid(image, grid, error))
  {
    vtkErrorMacro("Delaunay Image Mesh: " << error);
    return 0;
  }
  const bool is2D = grid.Is2D();
  const vtkIdType nIn = nodes->GetNumberOfPoints();
  if (nIn < (is2D ? 3 : 4))
  {
    vtkErrorMacro("Delaunay Image Mesh: " << nIn << " nodes are too few; a " << (is2D ? "triangle" : "tetrahedral")
                                          << " mesh needs at least " << (is2D ? 3 : 4) << ".");
    return 0;
  }
  std::vector<double> values;
  std::string warning;
  vtkDataArray* array = ChosenArray(image, this->GetInputArrayInformation(0), error, warning);
  if (!warning.empty())
  {
    vtkWarningMacro("Delaunay Image Mesh: " << warning);
  }
  if (!array || !ToDouble(array, values, error))
  {
    vtkErrorMacro("Delaunay Image Mesh: " << error);
    return 0;
  }

  // Nodes in index space, snapped to voxel centres when within round-off of one.
  std::vector<std::array<double, 3>> world(nIn), index(nIn);
  vtkIdType outside = 0, offPlane = 0;
  for (vtkIdType i = 0; i < nIn; ++i)
  {
    nodes->GetPoint(i, world[i].data());
    WorldToIndex(image, world[i].data(), index[i].data());
    for (int a = 0; a < 3; ++a)
    {
      const double r = std::round(index[i][a]);
      if (std::fabs(index[i][a] - r) < 1e-6)
      {
        index[i][a] = r;
      }
    }
    bool in = true;
    for (int a = 0; a < 3; ++a)
    {
      in = in && index[i][a] >= 0.0 && index[i][a] <= grid.Dims[a] - 1.0;
    }
    outside += in ? 0 : 1;
    offPlane += (is2D && index[i][2] != 0.0) ? 1 : 0;
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
      const std::array<double, 3> corner = { { (c & 1) ? grid.Dims[0] - 1.0 : 0.0, (c & 2) ? grid.Dims[1] - 1.0 : 0.0,
        (c & 4) ? grid.Dims[2] - 1.0 : 0.0 } };
      if (!std::binary_search(sorted.begin(), sorted.end(), corner))
      {
        index.push_back(corner);
        world.emplace_back();
        IndexToWorld(image, corner.data(), world.back().data());
      }
    }
  }
  this->UpdateProgress(0.1);

  // Delaunay in world coordinates (the right metric for anisotropic voxels).
  auto t0 = Clock::now();
  DelaunayResult mesh;
  std::string backendName;
  if (is2D)
  {
    mesh = Triangulate2D(world);
    backendName = "CGAL Delaunay_triangulation_2";
  }
  else
  {
    DelaunayOptions o;
    o.Backend = this->Backend == CGAL ? DelaunayBackend::CGAL : DelaunayBackend::TetGen;
    o.QualityRefinement = this->QualityRefinement;
    o.RadiusEdgeRatio = this->RadiusEdgeRatio;
    o.MinDihedralAngle = this->MinDihedralAngle;
    if (o.QualityRefinement && (!(o.RadiusEdgeRatio >= 1.0) || !(o.MinDihedralAngle >= 0.0 && o.MinDihedralAngle < 30.0)))
    {
      vtkErrorMacro("Delaunay Image Mesh: quality refinement needs a radius-edge ratio of at least 1 and a minimum "
                    "dihedral angle in [0, 30) degrees.");
      return 0;
    }
    mesh = Tetrahedralize(world, o);
    backendName = this->Backend == CGAL ? "CGAL Delaunay_triangulation_3" : "TetGen";
  }
  if (!mesh.Error.empty())
  {
    vtkErrorMacro("Delaunay Image Mesh: " << mesh.Error);
    return 0;
  }
  const double delaunaySeconds = std::chrono::duration<double>(Clock::now() - t0).count();
  if (this->GetAbortExecute())
  {
    return 1;
  }
  this->UpdateProgress(0.5);

  // Points the mesher added (TetGen refinement) need index coordinates too.
  for (size_t i = index.size(); i < mesh.Points.size(); ++i)
  {
    std::array<double, 3> idx;
    WorldToIndex(image, mesh.Points[i].data(), idx.data());
    index.push_back(idx);
  }
  if (is2D)
  {
    for (auto& p : index)
    {
      p[2] = 0.0;
    }
  }

  t0 = Clock::now();
  const ParallelFor parallel = SMPParallelFor();
  ElementRasterizer raster(index, mesh.Cells, mesh.VerticesPerCell, grid);
  const ElementStatistics stats =
    ComputeElementStatistics(raster, index, mesh.Cells, mesh.VerticesPerCell, values.data(), grid, parallel);
  std::vector<double> quality, radiusRatio;
  ElementQuality(mesh.Points, mesh.Cells, mesh.VerticesPerCell, quality, radiusRatio, parallel);
  const double statisticsSeconds = std::chrono::duration<double>(Clock::now() - t0).count();
  this->UpdateProgress(0.9);

  // Output.
  const vtkIdType nPts = static_cast<vtkIdType>(mesh.Points.size());
  const vtkIdType nCells = static_cast<vtkIdType>(mesh.Cells.size() / mesh.VerticesPerCell);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(nPts);
  for (vtkIdType i = 0; i < nPts; ++i)
  {
    points->SetPoint(i, mesh.Points[i].data());
  }
  output->SetPoints(points);
  vtkNew<vtkIdTypeArray> connectivity, offsets;
  connectivity->SetNumberOfTuples(static_cast<vtkIdType>(mesh.Cells.size()));
  std::copy(mesh.Cells.begin(), mesh.Cells.end(), connectivity->GetPointer(0));
  offsets->SetNumberOfTuples(nCells + 1);
  for (vtkIdType c = 0; c <= nCells; ++c)
  {
    offsets->SetValue(c, c * mesh.VerticesPerCell);
  }
  vtkNew<vtkCellArray> cells;
  cells->SetData(offsets, connectivity);
  output->SetCells(is2D ? VTK_TRIANGLE : VTK_TETRA, cells);

  // Node arrays pass through; added nodes get NodeType 4 and Fixed 1 (corners) or 0 (refinement).
  vtkPointData* inPD = nodes->GetPointData();
  vtkPointData* outPD = output->GetPointData();
  outPD->CopyAllocate(inPD, nPts);
  for (vtkIdType i = 0; i < nIn; ++i)
  {
    outPD->CopyData(inPD, i, i);
  }
  for (vtkIdType i = nIn; i < nPts; ++i)
  {
    outPD->NullData(i);
  }
  auto setAdded = [&](const char* name, int value) {
    vtkDataArray* a = outPD->GetArray(name);
    if (!a)
    {
      vtkNew<vtkUnsignedCharArray> created;
      created->SetName(name);
      created->SetNumberOfTuples(nPts);
      created->Fill(0);
      outPD->AddArray(created);
      a = created;
    }
    for (vtkIdType i = nIn; i < nPts; ++i)
    {
      a->SetComponent(i, 0, value);
    }
  };
  setAdded("NodeType", NodeAdded);
  const vtkIdType firstSteiner = static_cast<vtkIdType>(world.size());
  setAdded("Fixed", 1);
  if (vtkDataArray* fixed = outPD->GetArray("Fixed"))
  {
    for (vtkIdType i = firstSteiner; i < nPts; ++i)
    {
      fixed->SetComponent(i, 0, 0);
    }
  }

  auto addCellArray = [&](const char* name, auto* arr, const auto& data) {
    arr->SetName(name);
    arr->SetNumberOfTuples(nCells);
    for (vtkIdType c = 0; c < nCells; ++c)
    {
      arr->SetValue(c, data[c]);
    }
    output->GetCellData()->AddArray(arr);
  };
  vtkNew<vtkIdTypeArray> pixelCount;
  vtkNew<vtkDoubleArray> mean, stddev, qualityArray, ratioArray;
  vtkNew<vtkUnsignedCharArray> interpolated;
  addCellArray("PixelCount", pixelCount.GetPointer(), stats.PixelCount);
  addCellArray("MeanIntensity", mean.GetPointer(), stats.Mean);
  addCellArray("IntensityStdDev", stddev.GetPointer(), stats.StdDev);
  addCellArray("Interpolated", interpolated.GetPointer(), stats.Interpolated);
  addCellArray("Quality", qualityArray.GetPointer(), quality);
  addCellArray("RadiusRatio", ratioArray.GetPointer(), radiusRatio);
  output->GetCellData()->SetActiveScalars("MeanIntensity");

  // Field data: a summary a user (or a report) can read without recomputing.
  AddFieldValue(output, "NumberOfNodes", static_cast<double>(nPts));
  AddFieldValue(output, "NumberOfElements", static_cast<double>(nCells));
  AddFieldValue(output, "AddedNodes", static_cast<double>(nPts - nIn));
  const auto mm = std::minmax_element(quality.begin(), quality.end());
  AddFieldValue(output, is2D ? "MinAngle" : "MinDihedralAngle", nCells ? *mm.first : 0.0);
  AddFieldValue(output, is2D ? "MaxAngleOfMinAngles" : "MaxOfMinDihedralAngles", nCells ? *mm.second : 0.0);
  AddFieldValue(output, "DelaunaySeconds", delaunaySeconds);
  AddFieldValue(output, "StatisticsSeconds", statisticsSeconds);
  AddFieldValue(output, "TotalSeconds", std::chrono::duration<double>(Clock::now() - start).count());
  // The image grid, so that later stages can rasterise onto it without the image itself.
  auto addTuple = [&](const char* name, const double* v) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->SetNumberOfComponents(3);
    a->InsertNextTuple(v);
    output->GetFieldData()->AddArray(a);
  };
  const double dimsD[3] = { double(grid.Dims[0]), double(grid.Dims[1]), double(grid.Dims[2]) };
  double originD[3];
  const double zero[3] = { 0, 0, 0 };
  IndexToWorld(image, zero, originD);
  addTuple("ImageOrigin", originD);
  addTuple("ImageSpacing", image->GetSpacing());
  addTuple("ImageDimensions", dimsD);
  vtkNew<vtkStringArray> backend;
  backend->SetName("Backend");
  backend->InsertNextValue(backendName);
  output->GetFieldData()->AddArray(backend);
  this->UpdateProgress(1.0);
  return 1;
}

void vtkDelaunayImageMesh::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Backend: " << (this->Backend == CGAL ? "CGAL" : "TetGen") << "\n";
  os << indent << "QualityRefinement: " << this->QualityRefinement << "\n";
  os << indent << "RadiusEdgeRatio: " << this->RadiusEdgeRatio << "\n";
  os << indent << "MinDihedralAngle: " << this->MinDihedralAngle << "\n";
}
