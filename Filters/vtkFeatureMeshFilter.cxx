#include "vtkFeatureMeshFilter.h"

#include "ImageGeometry.h"
#include "vtkFeatureMeshArrays.h"
#include "vtkFeatureMeshFrame.h"

#include "vtkAlgorithm.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"

namespace featuremesh
{
int FilterBase::Start(vtkInformationVector* outputVector, std::initializer_list<vtkDataObject*> inputs)
{
  const std::string error = this->ValidateProperties();
  if (!error.empty())
  {
    return this->Fail(error);
  }
  for (vtkDataObject* input : inputs)
  {
    if (IsEmptyPiece(outputVector, input))
    {
      return 1;
    }
  }
  return -1;
}

int FilterBase::Fail(const std::string& why) const
{
  vtkErrorWithObjectMacro(this->Algorithm, << this->Name << ": " << why);
  return 0;
}

void FilterBase::Warn(const std::string& what) const
{
  vtkWarningWithObjectMacro(this->Algorithm, << this->Name << ": " << what);
}

bool FilterBase::Frame(vtkImageData* image, ImageGeometry& geometry) const
{
  std::string error;
  return ImageGeometryOf(image, geometry, error) || this->Fail(error);
}

vtkDataArray* FilterBase::ChosenImageArray(vtkImageData* image, vtkInformation* arrayInfo) const
{
  std::string error, warning;
  vtkDataArray* array = ChosenArray(image, arrayInfo, error, warning);
  if (!warning.empty())
  {
    this->Warn(warning);
  }
  if (!array)
  {
    this->Fail(error);
  }
  return array;
}

double FilterBase::Seconds() const
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - this->Started).count();
}
} // namespace featuremesh
