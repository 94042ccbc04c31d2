#include "vtkFeatureMeshUtilities.h"

#include "vtkAlgorithm.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkNew.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkPointData.h"
#include "vtkSMPTools.h"
#include "vtkType.h"

#include <algorithm>

#include <cmath>
#include <cstdlib>
#include <string>

namespace featuremesh
{
void EnsureThreadedBackend()
{
  if (!std::getenv("VTK_SMP_BACKEND_IN_USE") && std::string(vtkSMPTools::GetBackend()) == "Sequential")
  {
    vtkSMPTools::SetBackend("STDThread");
  }
}

ParallelFor SMPParallelFor()
{
  return [](std::int64_t n, std::int64_t grain, const RangeFunction& f) {
    if (n <= 0)
    {
      return;
    }
    // VTK 9.2's STDThread backend starts its threads on every For and queues one job per grain
    // under a lock: two jobs per thread at least. Loops here balance well, and their results do
    // not depend on the split.
    const std::int64_t threads = std::max(1, vtkSMPTools::GetEstimatedNumberOfThreads());
    grain = std::max(grain, (n + 2 * threads - 1) / (2 * threads));
    vtkSMPTools::For(0, static_cast<vtkIdType>(n), static_cast<vtkIdType>(grain),
      [&f](vtkIdType b, vtkIdType e) { f(b, e); });
  };
}

ProgressFunction AlgorithmProgress(vtkAlgorithm* algorithm, double begin, double end)
{
  return [=](double t) {
    algorithm->UpdateProgress(begin + (end - begin) * t);
    return !algorithm->GetAbortExecute();
  };
}

bool ImageGrid(vtkImageData* image, Grid& grid, std::string& error)
{
  if (!image || image->GetNumberOfPoints() == 0)
  {
    error = "the image is empty.";
    return false;
  }
  int dims[3];
  image->GetDimensions(dims);
  if (dims[0] < 2 || dims[1] < 2)
  {
    error = "the image is " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
      std::to_string(dims[2]) +
      " voxels; FeatureMesh needs at least 2 voxels along x and y (2D images lie in the xy plane).";
    return false;
  }
  grid.Dims = { { dims[0], dims[1], dims[2] } };
  return true;
}

void RequestWholeImage(vtkInformationVector* portVector)
{
  for (int c = 0; c < portVector->GetNumberOfInformationObjects(); ++c)
  {
    vtkInformation* info = portVector->GetInformationObject(c);
    if (!info->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
    {
      continue;
    }
    int ext[6];
    info->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), ext);
    info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), ext, 6);
    info->Set(vtkStreamingDemandDrivenPipeline::EXACT_EXTENT(), 1);
  }
}

namespace
{
template <typename T>
bool ToValues(vtkDataArray* array, std::vector<T>& values, std::string& error)
{
  if (!array)
  {
    error = "the image has no point scalars to process; choose a point data array.";
    return false;
  }
  if (array->GetNumberOfComponents() != 1)
  {
    error = std::string("the array '") + (array->GetName() ? array->GetName() : "") + "' has " +
      std::to_string(array->GetNumberOfComponents()) +
      " components; choose a single-component array (e.g. extract a component or compute a magnitude first).";
    return false;
  }
  const vtkIdType n = array->GetNumberOfTuples();
  values.resize(static_cast<size_t>(n));
  std::vector<vtkIdType> badPerBlock(64, 0);
  const vtkIdType block = (n + 63) / 64;
  auto convert = [&](auto* data) {
    vtkSMPTools::For(0, 64, 1, [&](vtkIdType b0, vtkIdType b1) {
      for (vtkIdType b = b0; b < b1; ++b)
      {
        // A local count and a raw pointer let the compiler vectorise the conversion.
        vtkIdType bad = 0;
        T* out = values.data();
        for (vtkIdType i = b * block, e = std::min(n, (b + 1) * block); i < e; ++i)
        {
          const double v = static_cast<double>(data[i]);
          const bool ok = std::isfinite(v);
          bad += ok ? 0 : 1;
          out[i] = ok ? static_cast<T>(v) : T(0);
        }
        badPerBlock[b] = bad;
      }
    });
  };
  switch (array->GetDataType())
  {
    vtkTemplateMacro(convert(static_cast<VTK_TT*>(array->GetVoidPointer(0))));
    default:
      error = "the array's value type is not supported.";
      return false;
  }
  vtkIdType bad = 0;
  for (vtkIdType c : badPerBlock)
  {
    bad += c;
  }
  if (bad)
  {
    error = std::string("the array '") + (array->GetName() ? array->GetName() : "") + "' holds " +
      std::to_string(bad) + " NaN or infinite values; replace them (e.g. with a Calculator) first.";
    return false;
  }
  return true;
}
} // namespace

bool ToFloat(vtkDataArray* array, std::vector<float>& values, std::string& error)
{
  return ToValues(array, values, error);
}

const float* FloatValues(vtkDataArray* array, std::vector<float>& storage, std::string& error)
{
  vtkFloatArray* floats = vtkFloatArray::SafeDownCast(array);
  if (floats && floats->GetNumberOfComponents() == 1)
  {
    const float* data = floats->GetPointer(0);
    const vtkIdType n = floats->GetNumberOfTuples();
    const vtkIdType block = (n + 63) / 64;
    std::vector<vtkIdType> badPerBlock(64, 0);
    vtkSMPTools::For(0, 64, 1, [&](vtkIdType b0, vtkIdType b1) {
      for (vtkIdType b = b0; b < b1; ++b)
      {
        vtkIdType bad = 0;
        for (vtkIdType i = b * block, e = std::min(n, (b + 1) * block); i < e; ++i)
        {
          bad += std::isfinite(data[i]) ? 0 : 1;
        }
        badPerBlock[b] = bad;
      }
    });
    if (std::all_of(badPerBlock.begin(), badPerBlock.end(), [](vtkIdType c) { return c == 0; }))
    {
      return data;
    }
  }
  // Conversion, or the NaN/Inf error message.
  return ToFloat(array, storage, error) ? storage.data() : nullptr;
}

bool ToDouble(vtkDataArray* array, std::vector<double>& values, std::string& error)
{
  return ToValues(array, values, error);
}

vtkDataArray* ChosenArray(vtkImageData* image, vtkInformation* arrayInfo, std::string& error, std::string& warning)
{
  const char* name = arrayInfo && arrayInfo->Has(vtkDataObject::FIELD_NAME()) ? arrayInfo->Get(vtkDataObject::FIELD_NAME()) : nullptr;
  vtkDataArray* array = nullptr;
  if (name && *name)
  {
    array = image->GetPointData()->GetArray(name);
    if (array)
    {
      return array;
    }
    // pvpython can carry a name over from a previously active source: fall back to the image's
    // active scalars, and say so.
    array = image->GetPointData()->GetScalars();
    if (!array)
    {
      error = std::string("the image has no point array named '") + name + "'.";
      return nullptr;
    }
    warning = std::string("the image has no point array named '") + name + "'; using its active scalars '" +
      (array->GetName() ? array->GetName() : "") + "'.";
    return array;
  }
  array = image->GetPointData()->GetScalars();
  if (!array)
  {
    error = "the image has no point scalars to process; choose a point data array.";
  }
  return array;
}

void AddFieldValue(vtkDataObject* object, const char* name, double value)
{
  vtkNew<vtkDoubleArray> a;
  a->SetName(name);
  a->InsertNextValue(value);
  object->GetFieldData()->AddArray(a);
}

void WorldToIndex(vtkImageData* image, const double world[3], double index[3])
{
  image->TransformPhysicalPointToContinuousIndex(world, index);
  const int* ext = image->GetExtent();
  for (int a = 0; a < 3; ++a)
  {
    index[a] -= ext[2 * a];
  }
}

void IndexToWorld(vtkImageData* image, const double index[3], double world[3])
{
  const int* ext = image->GetExtent();
  image->TransformContinuousIndexToPhysicalPoint(
    index[0] + ext[0], index[1] + ext[2], index[2] + ext[4], world);
}
} // namespace featuremesh
