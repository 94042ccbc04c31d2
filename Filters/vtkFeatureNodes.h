/**
 * @class   vtkFeatureNodes
 * @brief   Feature-sensitive mesh nodes of a 2D image or 3D volume (FeatureMesh stage 1).
 *
 * Canny edge points thinned adaptively by PCA of their neighbouring edge points (dense on curved
 * or tiny features, sparse on straight edges and flat surfaces), Floyd-Steinberg halftoning
 * points of a Hessian feature map, uniform fill points and boundary nodes (image corners, border
 * in 2D, box faces in 3D). Input 0 is the image (the array chosen with SetInputArrayToProcess);
 * optional input 1 an edge map on the same grid whose non-zero voxels replace Canny's edges.
 *
 * Output 0: vtkPolyData, one vertex per node on a voxel centre, point arrays `NodeType`
 * (0 Canny, 1 halftone, 2 uniform, 3 boundary), `Fixed` (1 = later smoothing must not move it)
 * and `SampleRadius` (voxels). Output 1: the edge map used (uint8 image, array `EdgeMap`).
 * Defaults are the thesis's, except the Canny maximum, taken as the 99th percentile of the
 * gradient magnitude: the plain maximum breaks on images with a few very bright spots.
 */
#ifndef vtkFeatureNodes_h
#define vtkFeatureNodes_h

#include "FeatureMeshFiltersModule.h"
#include "vtkFeatureMeshFilter.h" // the shared run and start-up
#include "FeatureNodes.h" // the parameters, declared once
#include "vtkPolyDataAlgorithm.h"

class vtkImageData;

// The filter is its Core parameters (TTK's shape): each property's value and default live in
// featuremesh::FeatureNodeParameters, which the setters write.
class FEATUREMESHFILTERS_EXPORT vtkFeatureNodes
  : public vtkPolyDataAlgorithm
  , protected featuremesh::FeatureNodeParameters
  , protected featuremesh::FilterBase
{
public:
  static vtkFeatureNodes* New();
  vtkTypeMacro(vtkFeatureNodes, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;
  /// Empty when the properties are usable, else the sentence Apply would fail with.
  std::string ValidateProperties() override;

  /// Standard deviation (voxels) of the Gaussian applied before Canny. Default 0.7.
  vtkSetMacro(GaussianSigma, double);
  vtkGetMacro(GaussianSigma, double);

  /// Standard deviation (voxels) of the Gaussian before the Hessian of the halftoning feature map.
  /// Default 2: second differences at the Canny scale measure mostly noise (measured on the
  /// nuclei image: 20 k halftone points, 8 % of pixels, spread over the flat background).
  vtkSetMacro(HessianSigma, double);
  vtkGetMacro(HessianSigma, double);

  /// Canny hysteresis thresholds as fractions of the gradient maximum. Defaults 0.1 and 0.6.
  vtkSetMacro(LowThreshold, double);
  vtkGetMacro(LowThreshold, double);
  vtkSetMacro(HighThreshold, double);
  vtkGetMacro(HighThreshold, double);

  /// Percentile of the gradient magnitude used as its maximum; 100 = the plain maximum. Default 99.
  vtkSetMacro(MaximumPercentile, double);
  vtkGetMacro(MaximumPercentile, double);

  /// Noise floor: Canny's thresholds and the feature map stay above the image's estimated noise
  /// (FeatureNodeParameters::NoiseFloor). Default on; the noise's deviation is field data NoiseSigma.
  vtkSetMacro(NoiseFloor, bool);
  vtkGetMacro(NoiseFloor, bool);
  vtkBooleanMacro(NoiseFloor, bool);

  /// Edge (voxels) of the neighbourhood for the PCA covariance; 0 = thesis default (11 in 2D, 5 in 3D).
  vtkSetMacro(CovarianceNeighbourhood, int);
  vtkGetMacro(CovarianceNeighbourhood, int);

  /// Halftoning points on/off, threshold q (default 0.3) and exponent gamma (default 1).
  vtkSetMacro(Halftoning, bool);
  vtkGetMacro(Halftoning, bool);
  vtkBooleanMacro(Halftoning, bool);
  vtkSetMacro(HalftoneThreshold, double);
  vtkGetMacro(HalftoneThreshold, double);
  vtkSetMacro(HalftoneGamma, double);
  vtkGetMacro(HalftoneGamma, double);

  /// Window (voxels) free of Canny points around a halftone point, and of any node around a
  /// uniform point. Default 7.
  vtkSetMacro(ExclusionWindow, int);
  vtkGetMacro(ExclusionWindow, int);

  /// Lattice spacing (voxels of the image's finest axis: even in world units on thick slices) of
  /// uniform points (default 7) and of boundary nodes (default 7).
  vtkSetMacro(UniformSpacing, int);
  vtkGetMacro(UniformSpacing, int);
  vtkSetMacro(BoundarySpacing, int);
  vtkGetMacro(BoundarySpacing, int);

  /// With an Edge Map connected: seed-aware recipe (default on; see featuremesh::FeatureNodeParameters)
  /// or, off, the map replaces Canny's edges. Gate radius (voxels) of the Canny edges
  /// kept near the map (default 20); coarsening levels (default 3) of the fill away from the edges.
  vtkSetMacro(SeedAware, bool);
  vtkGetMacro(SeedAware, bool);
  vtkBooleanMacro(SeedAware, bool);
  vtkSetMacro(EdgeGateRadius, int);
  vtkGetMacro(EdgeGateRadius, int);
  vtkSetMacro(CoarseningLevels, int);
  vtkGetMacro(CoarseningLevels, int);

  /// Optional edge map (port 1): its EdgeMap point array (else its scalars, else its first array),
  /// non-zero = edge.
  void SetEdgeMapConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(1, output); }

protected:
  vtkFeatureNodes();
  ~vtkFeatureNodes() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkFeatureNodes(const vtkFeatureNodes&) = delete;
  void operator=(const vtkFeatureNodes&) = delete;
};

#endif
