/**
 * @class   vtkSuperVoxelCut
 * @brief   Boykov-Jolly graph cut on the elements of an image mesh (FeatureMesh stage 4).
 *
 * Every element of the Delaunay Image Mesh output is a graph node (intensity = MeanIntensity,
 * region weight = PixelCount); elements sharing an edge (2D) or face (3D) are joined by an edge
 * whose boundary weight exp(-dI^2 / 2 sigma^2) is scaled by the shared edge length / face area in
 * voxel units. That scaling is the default because it makes the element energy a discretisation of
 * the same energy as the voxel cut (each voxel face counts 1), so lambda and sigma mean the same in
 * both. Inputs: 0 "Mesh", 1 "Object Seeds", 2 "Background Seeds", optional 3 "Image" (then the
 * seed histograms use the voxels of the seed elements rather than their means), optional 4 "Seeds"
 * (labelled seeds instead of ports 1 and 2: k objects by alpha-expansion, featuremesh::MultiLabelCut). A seed belongs to
 * the element that owns the voxel containing it. Outputs: 0 the mesh with cell array `Label`
 * (1 object, 0 background); 1 the boundary between labels (2D polylines, 3D a closed outward
 * triangle surface on the mesh's points); 2 the labels rasterised on the image grid (uint8), the
 * voxels of the elements along the cut labelled again by the voxel cut's energy (VoxelRefinement).
 */
#ifndef vtkSuperVoxelCut_h
#define vtkSuperVoxelCut_h

#include "Contract.h"
#include "FeatureMeshFiltersModule.h"
#include "vtkFeatureMeshFilter.h" // the shared run and start-up
#include "MultiLabelCut.h" // the parameters, declared once
#include "SuperVoxelCut.h"
#include "VoxelRefinement.h"
#include "vtkUnstructuredGridAlgorithm.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

class vtkDataArray;
class vtkImageData;
namespace featuremesh
{
class LocalContrastArray;
}
class vtkUnstructuredGrid;
class vtkUnsignedCharArray;
// The filter is its Core parameters (TTK's shape): each energy property's value and default live in
// featuremesh::SuperVoxelCutParameters and MultiLabelParameters, which the setters write.
class FEATUREMESHFILTERS_EXPORT vtkSuperVoxelCut
  : public vtkUnstructuredGridAlgorithm
  , protected featuremesh::SuperVoxelCutParameters
  , protected featuremesh::MultiLabelParameters
  , protected featuremesh::FilterBase
{
public:
  static vtkSuperVoxelCut* New();
  vtkTypeMacro(vtkSuperVoxelCut, vtkUnstructuredGridAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;
  /// Empty when the properties are usable, else the sentence Apply would fail with.
  std::string ValidateProperties() override;

  /// Histogram bins; 0 = automatic (64).
  vtkSetMacro(Bins, int);
  vtkGetMacro(Bins, int);
  /// Boundary sigma; 0 = automatic (RMS of the mean-intensity differences over adjacent elements).
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
  /// Scale boundary weights by the shared edge length / face area (default on).
  vtkSetMacro(ScaleByContact, bool);
  vtkGetMacro(ScaleByContact, bool);
  vtkBooleanMacro(ScaleByContact, bool);
  /// With the Image connected: an element's region cost is the sum of its voxels' costs (default on)
  /// rather than its voxel count times the cost of its mean.
  vtkSetMacro(VoxelRegionTerm, bool);
  vtkGetMacro(VoxelRegionTerm, bool);
  vtkBooleanMacro(VoxelRegionTerm, bool);
  /// With the Image connected: the histograms sample the voxels of the seed elements within
  /// SeedElementRadius of their seeds (on), or the voxels within SeedRadius of each seed, as the
  /// Voxel Cut does (off, default). Labelled seeds of several objects, or several channels, always
  /// take the latter.
  vtkSetMacro(SampleSeedElements, bool);
  vtkGetMacro(SampleSeedElements, bool);
  vtkBooleanMacro(SampleSeedElements, bool);
  /// With SampleSeedElements: only the seed elements' voxels within this distance (voxels) of a
  /// seed of their kind (default 5); 0 every voxel of the seed elements. Beyond [0, 50]: an error
  /// at execution.
  vtkSetMacro(SeedElementRadius, double);
  vtkGetMacro(SeedElementRadius, double);
  /// Adds ElementId (the element owning each voxel, -1 none) to the label image: the mesh as a
  /// super-voxel label image (default off).
  vtkSetMacro(SuperVoxelIds, bool);
  vtkGetMacro(SuperVoxelIds, bool);
  vtkBooleanMacro(SuperVoxelIds, bool);
  /// With the Image connected: rings of elements along the cut whose voxels are labelled again by
  /// the voxel cut's energy (1: the elements with a neighbour of another label; default 2: their
  /// neighbours too; 0 off). The label image then follows the voxels where an element straddles
  /// the boundary; the mesh's elements keep their labels. Beyond [0, 8]: an error at execution.
  vtkSetMacro(VoxelRefinement, int);
  vtkGetMacro(VoxelRefinement, int);
  /// Radius (voxels) of each seed's neighbourhood when SampleSeedElements is off, and with labelled
  /// seeds of several objects or channels.
  vtkSetMacro(SeedRadius, double);
  vtkGetMacro(SeedRadius, double);
  /// With the Seeds input (port 4): the name of its label array or column (default Label, matched
  /// without case; 0 background, 1..k objects).
  vtkSetStdStringFromCharMacro(SeedLabelArray);
  vtkGetCharFromStdStringMacro(SeedLabelArray);
  /// With labelled seeds, each label's density over the channels (featuremesh::ChannelModel): 0 one
  /// joint kernel density, 1 the product of one per channel (default), 2 a Gaussian mixture.
  virtual void SetChannelModel(int value);
  virtual int GetChannelModel();
  /// Names of labels 0..k, separated by ';' (optional): the outputs' LabelNames field data.
  vtkSetStdStringFromCharMacro(LabelNames);
  vtkGetCharFromStdStringMacro(LabelNames);

protected:
  vtkSuperVoxelCut();
  ~vtkSuperVoxelCut() override;
  int FillInputPortInformation(int port, vtkInformation* info) override;
  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  // Output and input options, not the energy's.
  bool SuperVoxelIds = false;
  std::string SeedLabelArray = featuremesh::names::Label;
  std::string LabelNames;

private:
  // The three outputs from the elements' labels and the boundary faces between them.
  void WriteLabels(vtkUnstructuredGrid* input, const std::vector<std::uint8_t>& labels,
    const std::vector<std::int64_t>& boundaryFaces, const featuremesh::VoxelRefinementResult& refinement,
    vtkInformationVector* outputVector);
  // Output 2's voxel labels with the refinement's, in an array the filter keeps for the next cut.
  vtkUnsignedCharArray* LabelVoxels(const std::vector<std::uint8_t>& labels, const featuremesh::VoxelRefinementResult& refinement);
  // The binary cut's voxel refinement (none when VoxelRefinement is 0 or without the image's
  // values), its object components' volumes updated; the labelled seeds' cut's.
  featuremesh::VoxelRefinementResult RefineBinary(featuremesh::SuperVoxelCutResult& result, vtkDataArray* values,
    const std::vector<std::int64_t>& objectVoxels, const std::vector<std::int64_t>& backgroundVoxels);
  featuremesh::VoxelRefinementResult RefineLabels(
    const featuremesh::MultiLabelResult& result, vtkDataArray* values, const featuremesh::LabelledSeeds& seeds);
  // The voxels along the cut labelled again (VoxelRefinement.h) from the cut's terms per voxel:
  // `cost(v, e, costs)` before the Potts weights of `values`; the seeds' elements keep their labels.
  // With `component` (binary) the result gives each object component's change in voxels.
  featuremesh::VoxelRefinementResult Refine(const std::vector<std::uint8_t>& labels, int labelCount, vtkDataArray* values,
    const std::vector<std::int64_t>& seedVoxels, const std::function<void(std::int64_t, std::int64_t, double*)>& cost,
    const std::vector<std::int64_t>* component, double progressFrom);
  // The refinement's field data on the labelled mesh and the label image.
  void WriteRefinementFields(const featuremesh::VoxelRefinementResult& refinement, vtkInformationVector* outputVector);
  // The image frame (the Image input, else the mesh's field data) and the values the cut reads:
  // -1 to go on, else RequestData's result. `binaryValues` is `valuesArray` when it has one
  // component; several serve labelled seeds only.
  int ReadImage(vtkUnstructuredGrid* input, vtkImageData* image, bool labelled, featuremesh::ImageGeometry& geometry,
    vtkDataArray*& valuesArray, vtkDataArray*& binaryValues, bool& contrast);
  // Makes (or keeps, for a seed edit) the mesh-dependent data: -1 to go on, else RequestData's result.
  // With `voxelMeans` the elements' intensities are the means of `binaryValues` over their voxels
  // (the local contrast), not the mesh's MeanIntensity.
  int Prepare(vtkUnstructuredGrid* input, const featuremesh::ImageGeometry& geometry, vtkDataArray* valuesArray,
    vtkDataArray* binaryValues, bool voxelMeans);
  // The binary cut's field data on the labelled mesh and the label image.
  void WriteCutFields(const featuremesh::SuperVoxelCutResult& result, double voxelVolume, vtkInformationVector* outputVector);
  // The cut with labelled seeds on the Seeds input.
  int RequestMultiLabel(vtkUnstructuredGrid* input, const featuremesh::LabelledSeeds& seeds, vtkDataArray* values,
    const featuremesh::SuperVoxelCutParameters& parameters, vtkInformationVector* outputVector);
  // What depends on the mesh and the image alone (the simplex mesh with its adjacency, the voxel
  // owners, the element statistics and voxel values), kept while they do not change: a seed edit
  // re-runs only the cut.
  struct MeshData;
  std::unique_ptr<MeshData> Prepared;
  // The image's local contrast, when the cut reads it, kept for the next cut of the same image.
  std::unique_ptr<featuremesh::LocalContrastArray> Contrast;
  vtkSuperVoxelCut(const vtkSuperVoxelCut&) = delete;
  void operator=(const vtkSuperVoxelCut&) = delete;
};

#endif
