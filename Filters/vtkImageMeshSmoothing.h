/**
 * @class   vtkImageMeshSmoothing
 * @brief   Image-weighted CVT / ODT smoothing of an image mesh with edge flips and sliver removal
 *          (FeatureMesh stage 3).
 *
 * Input 0 "Mesh": a Delaunay Image Mesh output (triangles or tetrahedra with its cell arrays and
 * image frame); input 1 "Image": the image it was made from. Each iteration moves every free node
 * (multicolour Gauss-Seidel) to its CVT or ODT position under a density that grows with the image
 * gradient, then restores the Delaunay property (2D edge flips, 3D re-tetrahedralisation);
 * Delaunay refinement then adds nodes where the angle bounds are missed (2D CGAL, 3D TetGen with
 * the box faces kept), and 3D meshes finish with sliver perturbation. Fixed nodes (point array
 * Fixed = 1) never move (3D: within 1.5 voxels of the box they move onto it before refinement);
 * free nodes on the image box slide in their face or edge; box corners stay. The output has the same
 * points (moved) and point arrays, new elements, and stage 2's cell arrays recomputed exactly, with
 * its own voxel owner map; it asks its input for none (docs/CONTRACT.md).
 * See Filters/Core/Smoothing/ImageMeshSmoothing.h.
 */
#ifndef vtkImageMeshSmoothing_h
#define vtkImageMeshSmoothing_h

#include "FeatureMeshFiltersModule.h"
#include "vtkFeatureMeshFilter.h" // the shared run and start-up
#include "ImageMeshSmoothing.h" // the parameters, declared once
#include "vtkUnstructuredGridAlgorithm.h"

// The filter is its Core parameters (TTK's shape): each property's value and default live in
// featuremesh::ImageMeshSmoothingParameters, which the setters write.
class FEATUREMESHFILTERS_EXPORT vtkImageMeshSmoothing
  : public vtkUnstructuredGridAlgorithm
  , protected featuremesh::ImageMeshSmoothingParameters
  , protected featuremesh::FilterBase
{
public:
  static vtkImageMeshSmoothing* New();
  vtkTypeMacro(vtkImageMeshSmoothing, vtkUnstructuredGridAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;
  /// Empty when the properties are usable, else the sentence Apply would fail with.
  std::string ValidateProperties() override;

  enum Methods
  {
    CVT = 0,
    ODT = 1
  };
  /// CVT (thesis eq. 10) or ODT (eq. 12, default).
  virtual void SetMethod(int method);
  virtual int GetMethod();
  /// Smoothing sweeps (default 5, the thesis's); 0 passes the mesh through.
  vtkSetMacro(Iterations, int);
  vtkGetMacro(Iterations, int);
  /// Gaussian sigma (voxels) before the gradient magnitude of the density (default 1).
  vtkSetMacro(Sigma, double);
  vtkGetMacro(Sigma, double);
  /// Weight of the image gradient in the density (default 1; 0 = unweighted CVT / ODT).
  vtkSetMacro(FeatureWeight, double);
  vtkGetMacro(FeatureWeight, double);
  /// Voxels a fixed (Canny) node may slide along its edge; 0 keeps fixed nodes in place.
  vtkSetMacro(FixedNodeSlack, double);
  vtkGetMacro(FixedNodeSlack, double);
  /// Restore the Delaunay property after each sweep (default on).
  vtkSetMacro(Flips, bool);
  vtkGetMacro(Flips, bool);
  vtkBooleanMacro(Flips, bool);
  /// Add nodes (Delaunay refinement) where elements stay below MinAngle (2D, default 20 degrees)
  /// or MinDihedralAngle (3D, default 9 degrees) after the sweeps; in 3D TetGen's optimisation
  /// then flips tetrahedra with a dihedral angle above MaxDihedralAngle (default 150). On by default.
  vtkSetMacro(QualityRefinement, bool);
  vtkGetMacro(QualityRefinement, bool);
  vtkBooleanMacro(QualityRefinement, bool);
  vtkSetMacro(MinAngle, double);
  vtkGetMacro(MinAngle, double);
  vtkSetMacro(MinDihedralAngle, double);
  vtkGetMacro(MinDihedralAngle, double);
  vtkSetMacro(MaxDihedralAngle, double);
  vtkGetMacro(MaxDihedralAngle, double);
  /// 3D: tetrahedra whose minimum dihedral angle is below SliverAngle: flips where no vertex may
  /// move, else perturbation of their free vertices.
  vtkSetMacro(SliverRemoval, bool);
  vtkGetMacro(SliverRemoval, bool);
  vtkBooleanMacro(SliverRemoval, bool);
  vtkSetMacro(SliverAngle, double);
  vtkGetMacro(SliverAngle, double);
  /// 3D: the smallest dihedral angle the mesh keeps after refinement and sliver removal (default
  /// 10 degrees): a few tetrahedra under it get their vertices moved, fixed ones included; more,
  /// and refinement and sliver removal run again.
  vtkSetMacro(DihedralFloor, double);
  vtkGetMacro(DihedralFloor, double);

  void SetImageConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(1, output); }

protected:
  vtkImageMeshSmoothing();
  ~vtkImageMeshSmoothing() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkImageMeshSmoothing(const vtkImageMeshSmoothing&) = delete;
  void operator=(const vtkImageMeshSmoothing&) = delete;
};

#endif
