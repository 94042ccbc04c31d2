/**
 * @class   vtkVoxelCut
 * @brief   Classical Boykov-Jolly graph cut on the pixel/voxel grid (FeatureMesh stage 4b).
 *
 * The baseline the Super-Voxel Cut is measured against: the same energy (BoykovJolly.h), the same
 * seeds, the same max-flow library, on the 4-/6-connected grid. Input 0 the image, input 1 object
 * seeds, input 2 background seeds (any vtkPointSet). A seed marks the voxel that contains it (hard
 * constraint); the seed histograms use the voxels within SeedRadius of each seed, the same
 * neighbourhood size a seed element has in the super-voxel cut. Output: uint8 label image
 * (`Label`, 1 object, 0 background); field data give the timing, sigma and flow.
 */
#ifndef vtkVoxelCut_h
#define vtkVoxelCut_h

#include "Contract.h"
#include "FeatureMeshFiltersModule.h"
#include "vtkFeatureMeshFilter.h" // the shared run and start-up
#include "MultiLabelCut.h" // the parameters, declared once
#include "SuperVoxelCut.h"
#include "vtkImageAlgorithm.h"

#include <memory>
#include <string>

class vtkDataArray;
namespace featuremesh
{
class LocalContrastArray;
}

// The filter is its Core parameters (TTK's shape): each energy property's value and default live in
// featuremesh::VoxelCutParameters and MultiLabelParameters, which the setters write.
class FEATUREMESHFILTERS_EXPORT vtkVoxelCut
  : public vtkImageAlgorithm
  , protected featuremesh::VoxelCutParameters
  , protected featuremesh::MultiLabelParameters
  , protected featuremesh::FilterBase
{
public:
  static vtkVoxelCut* New();
  vtkTypeMacro(vtkVoxelCut, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;
  /// Empty when the properties are usable, else the sentence Apply would fail with.
  std::string ValidateProperties() override;

  /// Histogram bins; 0 = automatic (64).
  vtkSetMacro(Bins, int);
  vtkGetMacro(Bins, int);
  /// Boundary sigma; 0 = automatic (RMS of neighbour differences).
  vtkSetMacro(Sigma, double);
  vtkGetMacro(Sigma, double);
  /// Region-term weight lambda.
  vtkSetMacro(Lambda, double);
  vtkGetMacro(Lambda, double);
  /// What the seeds ask for (featuremesh::Task): 0 the one object they lie in (default), 1 every
  /// object like the seeded ones. Out of range: an error at execution.
  virtual void SetTask(int value);
  virtual int GetTask();
  /// What the seeds reach (featuremesh::Connectivity): 0 off, 1 fill holes, 2 one seeded object,
  /// 3 from the task (default: 2 for Object, 1 for Class).
  virtual void SetConnectivity(int value);
  virtual int GetConnectivity();
  /// What the cut reads at each voxel (featuremesh::CutIntensity): 0 the image's values, 1 their
  /// local contrast, 2 from the task (default: 1 for Class, 0 for Object). Out of range: an error at execution.
  virtual void SetIntensity(int value);
  virtual int GetIntensity();
  /// Gaussian scale (voxels) of the local contrast's neighbourhood (default 8).
  vtkSetMacro(ContrastScale, double);
  vtkGetMacro(ContrastScale, double);
  /// Weight of the seeds' geodesic spatial term for Task Object (featuremesh::SeedGeodesicParameters); 0 = off.
  virtual void SetGeodesicWeight(double value);
  virtual double GetGeodesicWeight();
  /// Length of a voxel of travel in the geodesic, in units of the intensity range.
  virtual void SetGeodesicLength(double value);
  virtual double GetGeodesicLength();
  /// With one object: scale the geodesic weight by the overlap of the seeds' intensity densities over
  /// featuremesh::SeedOverlapReference (default on; SeedGeodesicParameters::Adaptive).
  virtual void SetAdaptiveGeodesicWeight(bool value);
  virtual bool GetAdaptiveGeodesicWeight();
  vtkBooleanMacro(AdaptiveGeodesicWeight, bool);
  /// Task Object: where the seeds' reach starts, in units of R, the largest distance from an object
  /// seed to the nearest background seed (featuremesh::SeedReachParameters; default 1).
  virtual void SetSeedReach(double value);
  virtual double GetSeedReach();
  /// Cost per voxel of the object one R beyond Seed Reach, growing linearly (default 4; 0 = off).
  virtual void SetSeedReachWeight(double value);
  virtual double GetSeedReachWeight();
  /// Kernel bandwidth of the seed histograms as a multiple of Silverman's rule (default 1).
  vtkSetMacro(Bandwidth, double);
  vtkGetMacro(Bandwidth, double);
  /// Radius (voxels) of the neighbourhood around each seed whose voxels build the histograms. Default 2.
  vtkSetMacro(SeedRadius, double);
  vtkGetMacro(SeedRadius, double);
  /// With the Seeds input (port 3), as vtkSuperVoxelCut: the label array's name, the channel model,
  /// the label names.
  vtkSetStdStringFromCharMacro(SeedLabelArray);
  vtkGetCharFromStdStringMacro(SeedLabelArray);
  virtual void SetChannelModel(int value);
  virtual int GetChannelModel();
  vtkSetStdStringFromCharMacro(LabelNames);
  vtkGetCharFromStdStringMacro(LabelNames);

  void SetObjectSeedsConnection(vtkAlgorithmOutput* o) { this->SetInputConnection(1, o); }
  void SetBackgroundSeedsConnection(vtkAlgorithmOutput* o) { this->SetInputConnection(2, o); }

protected:
  vtkVoxelCut();
  ~vtkVoxelCut() override;
  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  // Input and output options, not the energy's.
  std::string SeedLabelArray = featuremesh::names::Label;
  std::string LabelNames;

private:
  // The image's local contrast, when the cut reads it, kept for the next cut of the same image.
  std::unique_ptr<featuremesh::LocalContrastArray> Contrast;
  int RequestMultiLabel(const featuremesh::LabelledSeeds& seeds, vtkDataArray* array,
    const featuremesh::ImageGeometry& geometry, const featuremesh::VoxelCutParameters& parameters,
    vtkInformationVector* outputVector);
  vtkVoxelCut(const vtkVoxelCut&) = delete;
  void operator=(const vtkVoxelCut&) = delete;
};

#endif
