// Meshes between VTK and the core's SimplexMesh: the input grid as a simplex mesh, the image-mesh
// output of stages 2 and 3, node arrays, element statistics, label boundaries as poly data.
#ifndef vtkFeatureMeshMeshes_h
#define vtkFeatureMeshMeshes_h

#include "ElementQuality.h"
#include "ElementRasterizer.h"
#include "ImageGeometry.h"
#include "Parallel.h"
#include "SimplexMesh.h"

#include "vtkType.h"

#include <cstdint>
#include <string>
#include <vector>

class vtkDataArray;
class vtkPointData;
class vtkPoints;
class vtkPolyData;
class vtkUnstructuredGrid;

namespace featuremesh
{
// A triangle (2D) / tetrahedral (3D) unstructured grid as a SimplexMesh on `geometry`'s index
// space, every element positively oriented there; false with a sentence for mixed or other cell
// types, or a cell type that does not match the image's dimension.
bool ToSimplexMesh(vtkUnstructuredGrid* grid, const ImageGeometry& geometry, SimplexMesh& mesh, std::string& error);

// Why `grid` is not an image mesh (stage 2's or 3's output: cells with MeanIntensity and
// PixelCount), or "" when it is one.
std::string ImageMeshProblem(vtkUnstructuredGrid* grid);

// The image-mesh output of stages 2 and 3: world points, cells (positively oriented in world
// coordinates), the statistics and quality cell arrays, the image frame and summary field data.
void WriteImageMesh(const SimplexMesh& mesh, const ElementStatistics& statistics, const std::vector<double>& minAngle,
  const std::vector<double>& radiusRatio, vtkUnstructuredGrid* output);

// Point arrays of a mesh whose first nIn points are the nodes of `in`: copied for those, and for the
// nOut - nIn points added after them NodeType Added and Fixed 1 (ids below firstSteiner: box
// corners) or 0 (refinement), other arrays zero.
void PassNodeArrays(vtkPointData* in, vtkIdType nIn, vtkPointData* out, vtkIdType nOut, vtkIdType firstSteiner);

// ComputeElementStatistics on the array's own values (no double copy: 71 MB of fresh pages on BraTS);
// `values` passed CheckDouble.
ElementStatistics ImageElementStatistics(const ElementRasterizer& raster, vtkDataArray* values,
  const ParallelFor& parallel, const ProgressFunction& progress, std::int32_t* owner);

// A label boundary (faces of `faceSize` ids on `points`, as LabelBoundaryFaces gives them) as poly
// data: 2D segments joined into polylines, 3D triangles.
void BoundaryPolyData(vtkPoints* points, const std::vector<std::int64_t>& faces, int faceSize, vtkPolyData* output);
} // namespace featuremesh

#endif
