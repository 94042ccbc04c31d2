#include "vtkFeatureMeshExecution.h"

#include "Contract.h"

#include "vtkAbstractArray.h"
#include "vtkAlgorithm.h"
#include "vtkAOSDataArrayTemplate.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDataObject.h"
#include "vtkDataSet.h"
#include "vtkDemandDrivenPipeline.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationDoubleVectorKey.h"
#include "vtkInformationInformationVectorKey.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPointSet.h"
#include "vtkSetGet.h"
#include "vtkSMPTools.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkType.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace featuremesh
{
namespace
{
// Lowest and highest of `n` values `stride` apart; false when one is NaN.
template <typename T, typename Stride>
bool MinMax(const T* values, vtkIdType n, Stride stride, T& low, T& high)
{
  low = high = values[0];
  bool nan = false;
  for (vtkIdType t = 0; t < n; ++t)
  {
    const T v = values[t * stride];
    if constexpr (std::is_floating_point<T>::value)
    {
      nan |= v != v;
    }
    low = v < low ? v : low;
    high = v > high ? v : high;
  }
  return !nan;
}

// Per component: lowest and highest value (`range`), and of the finite values (`finite`); false
// when a value is NaN or no value of a component is finite.
template <typename T>
bool ComponentRanges(const T* values, vtkIdType tuples, int components, std::vector<double>& range, std::vector<double>& finite)
{
  range.assign(2 * components, 0.0);
  finite.assign(2 * components, 0.0);
  for (int c = 0; c < components; ++c)
  {
    T low, high;
    // One component is a contiguous loop, which the compiler vectorises (under 1 ms for BraTS's voxels).
    if (!(components == 1 ? MinMax(values, tuples, std::integral_constant<int, 1>(), low, high)
                          : MinMax(values + c, tuples, components, low, high)))
    {
      return false;
    }
    double finiteLow = static_cast<double>(low), finiteHigh = static_cast<double>(high);
    if (!(std::isfinite(finiteLow) && std::isfinite(finiteHigh)))
    {
      finiteLow = std::numeric_limits<double>::infinity();
      finiteHigh = -finiteLow;
      for (vtkIdType t = 0; t < tuples; ++t)
      {
        const double v = static_cast<double>(values[t * components + c]);
        if (std::isfinite(v))
        {
          finiteLow = std::min(finiteLow, v);
          finiteHigh = std::max(finiteHigh, v);
        }
      }
      if (finiteLow > finiteHigh)
      {
        return false;
      }
    }
    range[2 * c] = static_cast<double>(low);
    range[2 * c + 1] = static_cast<double>(high);
    finite[2 * c] = finiteLow;
    finite[2 * c + 1] = finiteHigh;
  }
  return true;
}

bool ComponentRanges(vtkDataArray* array, std::vector<double>& range, std::vector<double>& finite)
{
  const vtkIdType tuples = array->GetNumberOfTuples();
  const int components = array->GetNumberOfComponents();
  switch (array->GetDataType())
  {
    vtkTemplateMacro(auto* typed = vtkAOSDataArrayTemplate<VTK_TT>::FastDownCast(array);
                     return typed && ComponentRanges(typed->GetPointer(0), tuples, components, range, finite));
  }
  return false;
}

// True when `key` holds a range for every component that is newer than the array's values.
bool HasCurrentRanges(vtkDataArray* array, vtkInformationInformationVectorKey* key)
{
  vtkInformationVector* perComponent = array->GetInformation()->Get(key);
  if (!perComponent || perComponent->GetNumberOfInformationObjects() < array->GetNumberOfComponents())
  {
    return false;
  }
  for (int c = 0; c < array->GetNumberOfComponents(); ++c)
  {
    vtkInformation* info = perComponent->GetInformationObject(c);
    if (!info->Has(vtkDataArray::COMPONENT_RANGE()) || array->GetMTime() > info->GetMTime())
    {
      return false;
    }
  }
  return true;
}

bool StoreValueRange(vtkDataArray* array)
{
  if (!array || array->GetNumberOfTuples() == 0 ||
    (HasCurrentRanges(array, vtkAbstractArray::PER_COMPONENT()) &&
      HasCurrentRanges(array, vtkAbstractArray::PER_FINITE_COMPONENT())))
  {
    return false;
  }
  std::vector<double> range, finite;
  if (!ComponentRanges(array, range, finite))
  {
    return false;
  }
  for (const auto& kind : { std::make_pair(vtkAbstractArray::PER_COMPONENT(), &range),
         std::make_pair(vtkAbstractArray::PER_FINITE_COMPONENT(), &finite) })
  {
    vtkNew<vtkInformationVector> perComponent;
    perComponent->SetNumberOfInformationObjects(array->GetNumberOfComponents());
    for (int c = 0; c < array->GetNumberOfComponents(); ++c)
    {
      perComponent->GetInformationObject(c)->Set(vtkDataArray::COMPONENT_RANGE(), kind.second->data() + 2 * c, 2);
    }
    array->GetInformation()->Set(kind.first, perComponent);
  }
  return true;
}
} // namespace

int StoreValueRanges(vtkInformationVector* outputVector)
{
  int stored = 0;
  for (int port = 0; port < outputVector->GetNumberOfInformationObjects(); ++port)
  {
    vtkDataSet* data = vtkDataSet::SafeDownCast(outputVector->GetInformationObject(port)->Get(vtkDataObject::DATA_OBJECT()));
    if (!data)
    {
      continue;
    }
    for (vtkDataSetAttributes* attributes : { static_cast<vtkDataSetAttributes*>(data->GetPointData()),
           static_cast<vtkDataSetAttributes*>(data->GetCellData()) })
    {
      for (int i = 0; i < attributes->GetNumberOfArrays(); ++i)
      {
        stored += StoreValueRange(attributes->GetArray(i));
      }
    }
    vtkPointSet* points = vtkPointSet::SafeDownCast(data);
    if (points && points->GetPoints())
    {
      stored += StoreValueRange(points->GetPoints()->GetData());
    }
  }
  return stored;
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
    return !algorithm->CheckAbort();
  };
}

int ReportException(vtkAlgorithm* algorithm, const char* filter, const std::exception_ptr& error)
{
  try
  {
    std::rethrow_exception(error);
  }
  catch (const std::bad_alloc&)
  {
    vtkErrorWithObjectMacro(algorithm, << filter << ": out of memory; try a smaller image or fewer nodes.");
  }
  catch (const std::exception& e)
  {
    vtkErrorWithObjectMacro(algorithm, << filter << ": " << e.what());
  }
  catch (...)
  {
    vtkErrorWithObjectMacro(algorithm, << filter << ": an unknown error.");
  }
  return 0;
}

RunState PipelineState(vtkAlgorithm* algorithm, vtkInformationVector* outputVector)
{
  // Not the inputs' times: the pipeline regenerates and touches them on every pass.
  RunState state;
  vtkDemandDrivenPipeline* executive = vtkDemandDrivenPipeline::SafeDownCast(algorithm->GetExecutive());
  state.Modified = executive ? std::max(executive->GetPipelineMTime(), algorithm->GetMTime()) : algorithm->GetMTime();
  vtkInformation* info = outputVector->GetInformationObject(0);
  if (info && info->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()))
  {
    state.TimeStep = info->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
  }
  return state;
}

bool IsEmptyPiece(vtkInformationVector* outputVector, vtkDataObject* input)
{
  vtkInformation* info = outputVector->GetInformationObject(0);
  const int piece = info->Has(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER())
    ? info->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER())
    : 0;
  vtkDataSet* data = vtkDataSet::SafeDownCast(input);
  return piece > 0 && (!input || (data && data->GetNumberOfPoints() == 0));
}

void PutContractVersionFirst(vtkInformationVector* outputVector)
{
  for (int port = 0; port < outputVector->GetNumberOfInformationObjects(); ++port)
  {
    vtkDataObject* object = outputVector->GetInformationObject(port)->Get(vtkDataObject::DATA_OBJECT());
    vtkFieldData* fields = object ? object->GetFieldData() : nullptr;
    if (!fields || (fields->GetNumberOfArrays() > 0 && fields->GetAbstractArray(0)->GetName() &&
                     std::string(fields->GetAbstractArray(0)->GetName()) == names::ContractVersion))
    {
      continue;
    }
    vtkNew<vtkFieldData> ordered;
    vtkNew<vtkUnsignedCharArray> version;
    version->SetName(names::ContractVersion);
    version->InsertNextValue(ContractVersionNumber);
    ordered->AddArray(version);
    for (int i = 0; i < fields->GetNumberOfArrays(); ++i)
    {
      vtkAbstractArray* a = fields->GetAbstractArray(i);
      if (!(a->GetName() && std::string(a->GetName()) == names::ContractVersion))
      {
        ordered->AddArray(a);
      }
    }
    object->SetFieldData(ordered);
  }
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
} // namespace featuremesh
