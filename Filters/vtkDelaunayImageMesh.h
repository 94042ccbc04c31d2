/**
 * @class   vtkDelaunayImageMesh
 * @brief   Delaunay triangle / tetrahedral mesh of image nodes with exact super-pixel statistics
 *          (FeatureMesh stage 2).
 *
 * Input 0 "Nodes": any vtkPointSet (e.g. Feature Nodes), its point arrays passed to the mesh
 * points; input 1 "Image": the image whose voxels the elements summarise. 2D images give
 * VTK_TRIANGLE cells (CGAL), 3D images VTK_TETRA cells (TetGen, or CGAL's
 * Delaunay_triangulation_3). Missing image corners are added (NodeType 4), so the mesh tiles the
 * image box. Every voxel centre belongs to exactly one element (see ElementRasterizer.h for the
 * tie rule); cell arrays: PixelCount, MeanIntensity, IntensityStdDev, Interpolated (1 = element
 * owns no centre, mean interpolated at its centroid), MinAngle (triangles) or MinDihedralAngle
 * (tetrahedra) in degrees, RadiusRatio (1 = equilateral). Field data record the image frame
 * (origin, spacing, dimensions, direction) so that later stages can work without the image.
 */
#ifndef vtkDelaunayImageMesh_h
#define vtkDelaunayImageMesh_h

#include "DelaunayImageMesh.h" // the parameters, declared once
#include "FeatureMeshFiltersModule.h"
#include "vtkFeatureMeshFilter.h" // the shared run and start-up
#include "vtkUnstructuredGridAlgorithm.h"

#include <array>
#include <vector>

// The filter is its Core parameters (TTK's shape): each property's value and default live in
// featuremesh::DelaunayImageMeshParameters, which the setters write.
class FEATUREMESHFILTERS_EXPORT vtkDelaunayImageMesh
  : public vtkUnstructuredGridAlgorithm
  , protected featuremesh::DelaunayImageMeshParameters
  , protected featuremesh::FilterBase
{
public:
  static vtkDelaunayImageMesh* New();
  vtkTypeMacro(vtkDelaunayImageMesh, vtkUnstructuredGridAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;
  /// Empty when the properties are usable, else the sentence Apply would fail with (3D bounds:
  /// a 2D image takes any refinement bound).
  std::string ValidateProperties() override;

  enum Backends
  {
    TETGEN = 0,
    CGAL = 1
  };
  /// 3D backend: TETGEN (default, as the thesis) or CGAL.
  virtual void SetBackend(int backend);
  virtual int GetBackend();

  /// TetGen quality refinement (3D, adds nodes with NodeType 4). Off by default.
  vtkSetMacro(QualityRefinement, bool);
  vtkGetMacro(QualityRefinement, bool);
  vtkBooleanMacro(QualityRefinement, bool);
  /// Radius-edge ratio bound (default 2) and minimum dihedral angle in degrees (default 10).
  vtkSetMacro(RadiusEdgeRatio, double);
  vtkGetMacro(RadiusEdgeRatio, double);
  vtkSetMacro(MinDihedralAngle, double);
  vtkGetMacro(MinDihedralAngle, double);

  void SetImageConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(1, output); }

protected:
  vtkDelaunayImageMesh();
  ~vtkDelaunayImageMesh() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  // The Delaunay mesh of the nodes (image index coordinates), the mesher's added nodes appended to
  // `index`; false when aborted or with delaunay.Error set.
  bool Triangulate(const featuremesh::ImageGeometry& geometry, std::vector<std::array<double, 3>>& index,
    featuremesh::DelaunayResult& delaunay);

private:
  vtkDelaunayImageMesh(const vtkDelaunayImageMesh&) = delete;
  void operator=(const vtkDelaunayImageMesh&) = delete;
};

#endif
