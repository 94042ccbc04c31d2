// Arrays in and out: the chosen image array and its values (checked), cell-valued images, field
// values, label tables and label images.
#ifndef vtkFeatureMeshArrays_h
#define vtkFeatureMeshArrays_h

#include "ImageGeometry.h"
#include "Parallel.h"

#include "vtkSmartPointer.h"

#include <cstdint>
#include <initializer_list>
#include <memory>
#include <string>
#include <utility>
#include <vector>

class vtkDataObject;
class vtkDataArray;
class vtkFloatArray;
class vtkImageData;
class vtkInformation;

namespace featuremesh
{
struct MultiLabelResult;

// Copies a one-component array to double, rejecting NaN/Inf.
bool ToDouble(vtkDataArray* array, std::vector<double>& values, std::string& error);
// What ToDouble checks, without the copy (a stage that reads the array in its own type).
bool CheckDouble(vtkDataArray* array, std::string& error);

// Copies a one-component array to float, rejecting NaN/Inf (error names how many).
bool ToFloat(vtkDataArray* array, std::vector<float>& values, std::string& error);

// The values of a one-component array as floats: the array's own memory when it is a float array
// (no copy: copying BraTS costs ~50 ms, most of it page faults), else converted into `storage`.
// Null with `error` set when the array is unusable (components, type, NaN/Inf).
const float* FloatValues(vtkDataArray* array, std::vector<float>& storage, std::string& error);

// The local contrast (LocalContrast, ImageFilters.h) of each component of an image array, as a float
// array of as many components, kept while the array (the same object, unmodified), the frame and the
// scale stay the same: a seed edit reuses it.
class LocalContrastArray
{
public:
  LocalContrastArray();
  ~LocalContrastArray();
  // Null with `error` set when a value is NaN, infinite or beyond +-3.4e38, or the type is not supported.
  vtkDataArray* Of(vtkDataArray* values, const ImageGeometry& geometry, double scale, const ParallelFor& parallel,
    std::string& error);

private:
  vtkDataArray* Source = nullptr;
  unsigned long Time = 0;
  double Scale = 0.0;
  ImageGeometry Frame;
  vtkSmartPointer<vtkFloatArray> Result;
};

// The array a seeded cut reads: `values`, or with `contrast` its local contrast, kept in `kept` (made
// when first needed, released when the cut reads the values again). Null (with `values` null)
// passes through; null with `error` set when the contrast cannot be made.
vtkDataArray* CutValues(vtkDataArray* values, bool contrast, const ImageGeometry& geometry, double scale,
  std::unique_ptr<LocalContrastArray>& kept, std::string& error);

// The image as the filters read it: values on voxel centres (point data). An image whose values
// are cell data (each cell a voxel, as ParaView's GDAL reader gives a PNG or TIFF) becomes the image
// of its cell centres carrying those values; so does one whose chosen array (`arrayInfo`) is a cell
// array. Any other image is returned as it is. Null stays null.
vtkSmartPointer<vtkImageData> VoxelValuedImage(vtkImageData* image, vtkInformation* arrayInfo);

// The image point array named by SetInputArrayToProcess (looked up on `image`, whatever port the
// selection names), or the active point scalars when no name was given (ParaView sends an empty
// name when the input had not run yet). A missing named array falls back to the active scalars with
// a warning sentence; null with an error sentence when there are none.
vtkDataArray* ChosenArray(vtkImageData* image, vtkInformation* arrayInfo, std::string& error, std::string& warning);

// Adds a one-value double array `name` to the object's field data (summaries, timings).
void AddFieldValue(vtkDataObject* object, const char* name, double value);
// AddFieldValue of each (name, value), in order.
void AddFieldValues(vtkDataObject* object, std::initializer_list<std::pair<const char*, double>> values);

// Field data Labels (the count) and LabelNames (uint8, one tuple of the label values 0..k whose
// component names are the labels' names, from `names` split at ';', empty where it gives none).
void AddLabelTable(vtkDataObject* object, int labels, const std::string& names);

// A multi-label cut's field data: the label table, Sigma, Energy, ExpansionMoves, ExpansionCycles,
// ExpansionSeconds, GeodesicSeconds.
void AddMultiLabelFields(vtkDataObject* object, const MultiLabelResult& result, const std::string& labelNames);

// `image` in the frame of `geometry` with the uint8 point scalars Label (one per voxel).
void SetLabelImage(vtkImageData* image, const ImageGeometry& geometry, const std::vector<std::uint8_t>& labels);

// Adds the object components of a cut to the field data: ObjectComponents (their number),
// ObjectComponentVolumes (world units, largest first) and ConnectivityChanged.
void AddObjectComponents(vtkDataObject* object, const std::vector<double>& componentVoxels, double voxelVolume,
  std::int64_t connectivityChanged);
} // namespace featuremesh

#endif
