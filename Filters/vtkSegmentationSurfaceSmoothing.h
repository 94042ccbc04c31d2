/**
 * @class   vtkSegmentationSurfaceSmoothing
 * @brief   Smooths a segmentation's boundary and moves its labelled mesh with it (FeatureMesh stage 6).
 *
 * Input "Labelled Mesh": the Super-Voxel Cut's first output (triangles or tetrahedra with the cell
 * array Label, 0 background / 1..k objects, and the image frame in field data). Output 0: the boundary
 * between the labels (2D polylines, 3D triangles; one closed outward surface for one object) at its smoothed
 * positions: Taubin (default, 10 iterations: no shrinkage) or Laplacian (the thesis: 3 iterations
 * of relaxation 0.5).
 * Output 1: the labelled mesh whose nodes followed the boundary, every element positively oriented
 * and above its quality floor, labels unchanged, quality arrays recomputed and the stale image
 * statistics dropped; its boundary nodes are output 0's points. Point array Shortfall: how far a
 * boundary node stopped from its smoothed position. Nodes on the image box stay
 * on it. With several objects, junction curves (three labels) move along themselves and junction
 * points stay. See Filters/Core/Smoothing/SegmentationSurfaceSmoothing.h.
 */
#ifndef vtkSegmentationSurfaceSmoothing_h
#define vtkSegmentationSurfaceSmoothing_h

#include "FeatureMeshFiltersModule.h"
#include "vtkFeatureMeshFilter.h" // the shared run and start-up
#include "SegmentationSurfaceSmoothing.h" // the parameters, declared once
#include "vtkPolyDataAlgorithm.h"

// The filter is its Core parameters (TTK's shape): each property's value and default live in
// featuremesh::SegmentationSurfaceSmoothingParameters, which the setters write.
class FEATUREMESHFILTERS_EXPORT vtkSegmentationSurfaceSmoothing
  : public vtkPolyDataAlgorithm
  , protected featuremesh::SegmentationSurfaceSmoothingParameters
  , protected featuremesh::FilterBase
{
public:
  static vtkSegmentationSurfaceSmoothing* New();
  vtkTypeMacro(vtkSegmentationSurfaceSmoothing, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;
  /// Empty when the properties are usable, else the sentence Apply would fail with.
  std::string ValidateProperties() override;

  enum Methods
  {
    LAPLACIAN = 0,
    TAUBIN = 1
  };
  /// Taubin (default; lambda|mu: does not shrink) or Laplacian (the thesis).
  virtual void SetMethod(int method);
  virtual int GetMethod();
  /// Iterations (default 10; the thesis's Laplacian takes 3); Taubin's iteration is one lambda and
  /// one mu step.
  vtkSetMacro(Iterations, int);
  vtkGetMacro(Iterations, int);
  /// Relaxation factor lambda (default 0.5, the thesis).
  vtkSetMacro(Relaxation, double);
  vtkGetMacro(Relaxation, double);
  /// Taubin's pass-band frequency (default 0.1): mu = 1 / (PassBand - 1 / Relaxation).
  vtkSetMacro(PassBand, double);
  vtkGetMacro(PassBand, double);
  /// Move the labelled mesh with the boundary (default on); off leaves output 1 as the input.
  vtkSetMacro(VolumeMesh, bool);
  vtkGetMacro(VolumeMesh, bool);
  vtkBooleanMacro(VolumeMesh, bool);
  /// Quality floors of output 1 (degrees; 2D default 15, 3D default 8); an element already below
  /// its floor does not get worse.
  vtkSetMacro(MinAngle, double);
  vtkGetMacro(MinAngle, double);
  vtkSetMacro(MinDihedralAngle, double);
  vtkGetMacro(MinDihedralAngle, double);
  /// Rings of nodes around the boundary that move with it (default 2).
  vtkSetMacro(RelaxationRings, int);
  vtkGetMacro(RelaxationRings, int);

protected:
  vtkSegmentationSurfaceSmoothing();
  ~vtkSegmentationSurfaceSmoothing() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkSegmentationSurfaceSmoothing(const vtkSegmentationSurfaceSmoothing&) = delete;
  void operator=(const vtkSegmentationSurfaceSmoothing&) = delete;
};

#endif
