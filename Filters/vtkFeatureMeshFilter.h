// The base every FeatureMesh filter shares beside its VTK superclass and its Core parameters (TTK's
// ttkAlgorithm, as a mixin: the filters' VTK superclasses differ): the run RunFilter keeps across
// updates, failures reported with the filter's name, the start-up (validation, empty piece), the
// image frame and the chosen array. RequestData keeps the marshalling of its own stage.
#ifndef vtkFeatureMeshFilter_h
#define vtkFeatureMeshFilter_h

#include "FeatureMeshFiltersModule.h"
#include "vtkFeatureMeshExecution.h"

#include <chrono>
#include <initializer_list>
#include <string>

class vtkAlgorithm;
class vtkDataArray;
class vtkDataObject;
class vtkImageData;
class vtkInformation;
class vtkInformationVector;

namespace featuremesh
{
struct ImageGeometry;

class FEATUREMESHFILTERS_EXPORT FilterBase
{
public:
  virtual ~FilterBase() = default;
  /// Empty when the properties are usable, else the sentence Apply would fail with (the XML's
  /// ranges agree with it: FeatureMeshDefaultsTest).
  virtual std::string ValidateProperties() = 0;

protected:
  FilterBase(vtkAlgorithm* algorithm, const char* name)
    : Algorithm(algorithm)
    , Name(name)
  {
  }
  FilterBase(const FilterBase&) = delete;
  void operator=(const FilterBase&) = delete;

  // RequestData's body run by RunFilter with this filter's record of its last failure.
  template <typename Body>
  int Run(vtkInformationVector* outputVector, Body&& body)
  {
    this->Started = std::chrono::steady_clock::now();
    return RunFilter(this->Algorithm, this->Name, outputVector, this->FailedAt, this->FailedAtTime, body);
  }
  // The start-up: 0 (reported) when the properties are invalid, 1 (empty outputs) on a parallel
  // process without a piece of any of `inputs`, -1 to go on.
  int Start(vtkInformationVector* outputVector, std::initializer_list<vtkDataObject*> inputs);
  // Reports `why` as the filter's error and returns 0, RequestData's failure.
  int Fail(const std::string& why) const;
  void Warn(const std::string& what) const;
  // The image's frame; false after reporting why there is none.
  bool Frame(vtkImageData* image, ImageGeometry& geometry) const;
  // The array the user chose on `image` (`arrayInfo`: GetInputArrayInformation), a warning
  // reported when it was not the one asked for; nullptr after reporting why there is none.
  vtkDataArray* ChosenImageArray(vtkImageData* image, vtkInformation* arrayInfo) const;
  // Seconds since Run began.
  double Seconds() const;

private:
  vtkAlgorithm* Algorithm;
  const char* Name;
  vtkMTimeType FailedAt = 0;
  double FailedAtTime = 0.0;
  std::chrono::steady_clock::time_point Started;
};
} // namespace featuremesh

#endif
