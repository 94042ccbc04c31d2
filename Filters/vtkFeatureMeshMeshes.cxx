#include "vtkFeatureMeshMeshes.h"
#include "vtkFeatureMeshArrays.h"
#include "vtkFeatureMeshFrame.h"

#include "Contract.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkIdTypeArray.h"
#include "vtkTypeInt32Array.h"
#include "vtkTypeInt64Array.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStripper.h"
#include "vtkType.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <string>
namespace featuremesh
{
std::string ImageMeshProblem(vtkUnstructuredGrid* grid)
{
  if (!grid || grid->GetNumberOfCells() == 0)
  {
    return "the mesh is empty.";
  }
  if (!grid->GetCellData()->GetArray(names::MeanIntensity) || !grid->GetCellData()->GetArray(names::PixelCount))
  {
    return "the mesh has no MeanIntensity and PixelCount cell arrays; make it with Delaunay Image Mesh.";
  }
  return std::string();
}

bool ToSimplexMesh(vtkUnstructuredGrid* grid, const ImageGeometry& geometry, SimplexMesh& mesh, std::string& error)
{
  const vtkIdType nCells = grid ? grid->GetNumberOfCells() : 0;
  if (nCells == 0)
  {
    error = "the mesh is empty.";
    return false;
  }
  const int cellType = grid->GetCellType(0);
  if (cellType != VTK_TRIANGLE && cellType != VTK_TETRA)
  {
    error = "the mesh must consist of triangles (2D) or tetrahedra (3D).";
    return false;
  }
  const int vpc = cellType == VTK_TRIANGLE ? 3 : 4;
  std::vector<std::int64_t> cells(static_cast<size_t>(nCells) * vpc);
  vtkIdType npts;
  const vtkIdType* ids;
  for (vtkIdType c = 0; c < nCells; ++c)
  {
    grid->GetCellPoints(c, npts, ids);
    if (grid->GetCellType(c) != cellType || npts != vpc)
    {
      error = "the mesh mixes cell types; it must be all triangles or all tetrahedra.";
      return false;
    }
    std::copy(ids, ids + vpc, cells.begin() + c * vpc);
  }
  const vtkIdType nPts = grid->GetNumberOfPoints();
  std::vector<std::array<double, 3>> index(nPts);
  for (vtkIdType i = 0; i < nPts; ++i)
  {
    std::array<double, 3> world;
    grid->GetPoint(i, world.data());
    index[i] = geometry.WorldToIndex(world);
    if (geometry.Is2D())
    {
      index[i][2] = 0.0;
    }
  }
  SimplexMesh result(geometry, std::move(index), std::move(cells), vpc);
  error = result.Validate();
  if (!error.empty())
  {
    return false;
  }
  // Whatever the writer's convention or the frame's mirror.
  result.OrientPositively();
  mesh = std::move(result);
  return true;
}

void WriteImageMesh(const SimplexMesh& mesh, const ElementStatistics& stats, const std::vector<double>& minAngle,
  const std::vector<double>& radiusRatio, vtkUnstructuredGrid* output)
{
  const int vpc = mesh.VerticesPerCell();
  const bool is2D = vpc == 3;
  const vtkIdType nPts = mesh.NumberOfPoints();
  const vtkIdType nCells = mesh.NumberOfElements();
  const std::vector<std::array<double, 3>> world = mesh.WorldPoints();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(nPts);
  for (vtkIdType i = 0; i < nPts; ++i)
  {
    points->SetPoint(i, world[i].data());
  }
  output->SetPoints(points);
  // 32-bit ids when they fit: half of vtkIdType's memory (0.15 GB over stages 2 and 3 at 512^3).
  vtkNew<vtkCellArray> cells;
  auto fill = [&](auto* connectivity, auto* offsets) {
    connectivity->SetNumberOfTuples(static_cast<vtkIdType>(mesh.Cells().size()));
    auto* conn = connectivity->GetPointer(0);
    std::copy(mesh.Cells().begin(), mesh.Cells().end(), conn);
    if (mesh.Geometry().IsMirrored())
    {
      for (vtkIdType c = 0; c < nCells; ++c)
      {
        std::swap(conn[c * vpc + vpc - 2], conn[c * vpc + vpc - 1]);
      }
    }
    offsets->SetNumberOfTuples(nCells + 1);
    for (vtkIdType c = 0; c <= nCells; ++c)
    {
      offsets->SetValue(c, c * vpc);
    }
    cells->SetData(offsets, connectivity);
  };
  if (nPts <= VTK_TYPE_INT32_MAX && static_cast<vtkIdType>(mesh.Cells().size()) <= VTK_TYPE_INT32_MAX)
  {
    vtkNew<vtkTypeInt32Array> connectivity, offsets;
    fill(connectivity.GetPointer(), offsets.GetPointer());
  }
  else
  {
    vtkNew<vtkTypeInt64Array> connectivity, offsets;
    fill(connectivity.GetPointer(), offsets.GetPointer());
  }
  output->SetCells(is2D ? VTK_TRIANGLE : VTK_TETRA, cells);

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
  vtkNew<vtkDoubleArray> mean, stddev, angle, ratio;
  vtkNew<vtkUnsignedCharArray> interpolated;
  addCellArray(names::PixelCount, pixelCount.GetPointer(), stats.PixelCount);
  addCellArray(names::MeanIntensity, mean.GetPointer(), stats.Mean);
  addCellArray(names::IntensityStdDev, stddev.GetPointer(), stats.StdDev);
  addCellArray(names::Interpolated, interpolated.GetPointer(), stats.Interpolated);
  addCellArray(is2D ? names::MinAngle : names::MinDihedralAngle, angle.GetPointer(), minAngle);
  addCellArray(names::RadiusRatio, ratio.GetPointer(), radiusRatio);
  // ParaView colours a mesh by its active scalars: the elements' quality, not the nodes' types.
  output->GetCellData()->SetActiveScalars(is2D ? names::MinAngle : names::MinDihedralAngle);

  // Field data: a summary a user (or a report) can read without recomputing, and the frame.
  AddFieldValue(output, names::NumberOfNodes, static_cast<double>(nPts));
  AddFieldValue(output, names::NumberOfElements, static_cast<double>(nCells));
  const auto mm = std::minmax_element(minAngle.begin(), minAngle.end());
  AddFieldValue(output, is2D ? names::MinAngle : names::MinDihedralAngle, nCells ? *mm.first : 0.0);
  AddFieldValue(output, is2D ? names::MaxOfMinAngles : names::MaxOfMinDihedralAngles, nCells ? *mm.second : 0.0);
  AddImageGeometry(mesh.Geometry(), output);
}

void PassNodeArrays(vtkPointData* in, vtkIdType nIn, vtkPointData* out, vtkIdType nOut, vtkIdType firstSteiner)
{
  out->CopyAllocate(in, nOut);
  for (vtkIdType i = 0; i < nIn; ++i)
  {
    out->CopyData(in, i, i);
  }
  for (vtkIdType i = nIn; i < nOut; ++i)
  {
    out->NullData(i);
  }
  auto setAdded = [&](const char* name, int corner, int steiner) {
    vtkDataArray* a = out->GetArray(name);
    if (!a)
    {
      vtkNew<vtkUnsignedCharArray> created;
      created->SetName(name);
      created->SetNumberOfTuples(nOut);
      created->Fill(0);
      out->AddArray(created);
      a = created;
    }
    for (vtkIdType i = nIn; i < nOut; ++i)
    {
      a->SetComponent(i, 0, i < firstSteiner ? corner : steiner);
    }
  };
  const int added = static_cast<int>(NodeType::Added);
  setAdded(names::NodeType, added, added);
  setAdded(names::Fixed, 1, 0);
  // A mesh is coloured by its elements' quality (WriteImageMesh), not by the nodes' types.
  out->SetActiveAttribute(-1, vtkDataSetAttributes::SCALARS);
}

ElementStatistics ImageElementStatistics(const ElementRasterizer& raster, vtkDataArray* values,
  const ParallelFor& parallel, const ProgressFunction& progress, std::int32_t* owner)
{
  switch (values->GetDataType())
  {
    vtkTemplateMacro(
      return ComputeElementStatistics(raster, static_cast<const VTK_TT*>(values->GetVoidPointer(0)), parallel, progress, owner));
  }
  // CheckDouble rejected every other type.
  ElementStatistics none;
  none.Aborted = true;
  return none;
}

void BoundaryPolyData(vtkPoints* points, const std::vector<std::int64_t>& faces, int faceSize, vtkPolyData* output)
{
  vtkNew<vtkCellArray> cells;
  for (std::size_t f = 0; f < faces.size(); f += faceSize)
  {
    const vtkIdType ids[3] = { faces[f], faces[f + 1], faceSize == 3 ? faces[f + 2] : 0 };
    cells->InsertNextCell(faceSize, ids);
  }
  vtkNew<vtkPolyData> surface;
  surface->SetPoints(points);
  if (faceSize == 2)
  {
    surface->SetLines(cells);
    vtkNew<vtkStripper> stripper;
    stripper->SetInputData(surface);
    stripper->JoinContiguousSegmentsOn();
    stripper->Update();
    output->ShallowCopy(stripper->GetOutput());
  }
  else
  {
    surface->SetPolys(cells);
    output->ShallowCopy(surface);
  }
}
} // namespace featuremesh
