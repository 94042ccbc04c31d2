// VTK plumbing shared by the FeatureMesh filters: thread backend, parallel-for and progress
// adapters for the VTK-free core, and the image checks every stage makes the same way.
#ifndef vtkFeatureMeshUtilities_h
#define vtkFeatureMeshUtilities_h

#include "Grid.h"
#include "Parallel.h"

#include <string>
#include <vector>

class vtkAlgorithm;
class vtkDataObject;
class vtkDataArray;
class vtkImageData;
class vtkInformation;
class vtkInformationVector;
class vtkPointSet;

namespace featuremesh
{
// Selects the STDThread SMP backend when VTK runs the Sequential default and the user did not
// choose one with VTK_SMP_BACKEND_IN_USE.
void EnsureThreadedBackend();

// A parallel-for on vtkSMPTools.
ParallelFor SMPParallelFor();

// Maps core progress [0,1] to [begin,end] of the algorithm's progress; false once abort is asked.
ProgressFunction AlgorithmProgress(vtkAlgorithm* algorithm, double begin, double end);

// Grid of an image, or an error sentence: the image must have at least 2 voxels along x and y,
// and be a single xy slice (2D) or a volume with at least 2 voxels along z (3D).
bool ImageGrid(vtkImageData* image, Grid& grid, std::string& error);

// Sets the update extent of every image connected to `port` to its whole extent.
void RequestWholeImage(vtkInformationVector* portVector);

// Copies a one-component array to double, rejecting NaN/Inf.
bool ToDouble(vtkDataArray* array, std::vector<double>& values, std::string& error);

// Copies a one-component array to float, rejecting NaN/Inf (error names how many).
bool ToFloat(vtkDataArray* array, std::vector<float>& values, std::string& error);

// The values of a one-component array as floats: the array's own memory when it is a float array
// (no copy: copying BraTS costs ~50 ms, most of it page faults), else converted into `storage`.
// Null with `error` set when the array is unusable (components, type, NaN/Inf).
const float* FloatValues(vtkDataArray* array, std::vector<float>& storage, std::string& error);

// The image point array named by SetInputArrayToProcess (looked up on `image`, whatever port the
// selection names), or the active point scalars when no name was given (ParaView sends an empty
// name when the input had not run yet). A missing named array falls back to the active scalars with
// a warning sentence; null with an error sentence when there are none.
vtkDataArray* ChosenArray(vtkImageData* image, vtkInformation* arrayInfo, std::string& error, std::string& warning);

// Adds a one-value double array `name` to the object's field data (summaries, timings).
void AddFieldValue(vtkDataObject* object, const char* name, double value);

// Index-space coordinates (relative to the extent's start) of a world point.
void WorldToIndex(vtkImageData* image, const double world[3], double index[3]);
void IndexToWorld(vtkImageData* image, const double index[3], double world[3]);
} // namespace featuremesh

#endif
