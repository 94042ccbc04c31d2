/**
 * @class   vtkRSPEdgeEnhancement
 * @brief   Seeded randomized shortest paths -> edge-confidence map (FeatureMesh stage 5).
 *
 * Thesis chapter 5. Input 0 the image, input 1 object seeds, input 2 background seeds (any
 * vtkPointSet, world coordinates). Fast-marching distance maps from both seed sets, random sources
 * and sinks drawn from them by rejection sampling, every source-sink shortest path on the 4-/6-
 * connected grid with edge weight (G_i + G_j) / 2, G = exp(-beta |grad I|); each voxel counts the
 * paths through it (EdgeConfidence). Outputs: 0 the image (EdgeConfidence, float, active; EdgeMap,
 * uint8, what Feature Nodes' Edge Map input reads; the two marching maps; in 2D ContourRegion);
 * 1 the closed final contour (2D; empty in 3D); 2 the sources and sinks (SampleRole 0 / 1).
 * The core is featuremesh::RSPEdgeEnhancement; defaults are featuremesh::RSPParameters.
 */
#ifndef vtkRSPEdgeEnhancement_h
#define vtkRSPEdgeEnhancement_h

#include "FeatureMeshFiltersModule.h"
#include "vtkFeatureMeshFilter.h" // the shared run and start-up
#include "RSPEdgeEnhancement.h" // the parameters, declared once
#include "vtkImageAlgorithm.h"

// The filter is its Core parameters (TTK's shape): each property's value and default live in
// featuremesh::RSPParameters, which the setters write.
class FEATUREMESHFILTERS_EXPORT vtkRSPEdgeEnhancement
  : public vtkImageAlgorithm
  , protected featuremesh::RSPParameters
  , protected featuremesh::FilterBase
{
public:
  static vtkRSPEdgeEnhancement* New();
  vtkTypeMacro(vtkRSPEdgeEnhancement, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;
  /// Empty when the properties are usable, else the sentence Apply would fail with.
  std::string ValidateProperties() override;

  /// beta of G = exp(-beta |grad I|), |grad I| in 8-bit grey levels per voxel (the image's 1st-99th
  /// percentile range mapped to 255). Default 0.1, the thesis's.
  vtkSetMacro(GradientScale, double);
  vtkGetMacro(GradientScale, double);
  /// Gaussian standard deviation (voxels) before the gradient; 0 = raw image. Default 1.
  vtkSetMacro(GradientSigma, double);
  vtkGetMacro(GradientSigma, double);
  /// Random sources and sinks. Defaults 50 and 100, the thesis's.
  virtual void SetNumberOfSources(int value);
  virtual int GetNumberOfSources();
  virtual void SetNumberOfSinks(int value);
  virtual int GetNumberOfSinks();
  /// T of the rejection sampler in marching-map units; 0 (default) = automatic.
  vtkSetMacro(SamplingThreshold, double);
  vtkGetMacro(SamplingThreshold, double);
  virtual void SetRandomSeed(int value);
  virtual int GetRandomSeed();
  /// Larger images run the paths on a coarser grid first (see featuremesh::RSPParameters); 0 = never.
  virtual void SetMaximumPathVoxels(int value);
  virtual int GetMaximumPathVoxels();
  /// Voxels the paths may use beyond the box the marching maps reach. Default 8.
  vtkSetMacro(PathMargin, int);
  vtkGetMacro(PathMargin, int);
  /// Binary edge map: EC >= this fraction of the paths. Default 0.01.
  vtkSetMacro(EdgeThreshold, double);
  vtkGetMacro(EdgeThreshold, double);
  /// 2D contour: cost of an EC = 0 voxel against one a single path crossed. Default 1e4.
  vtkSetMacro(GapCost, double);
  vtkGetMacro(GapCost, double);

  void SetObjectSeedsConnection(vtkAlgorithmOutput* o) { this->SetInputConnection(1, o); }
  void SetBackgroundSeedsConnection(vtkAlgorithmOutput* o) { this->SetInputConnection(2, o); }

protected:
  vtkRSPEdgeEnhancement();
  ~vtkRSPEdgeEnhancement() override = default;
  int FillInputPortInformation(int port, vtkInformation* info) override;
  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;


private:
  vtkRSPEdgeEnhancement(const vtkRSPEdgeEnhancement&) = delete;
  void operator=(const vtkRSPEdgeEnhancement&) = delete;
};

#endif
