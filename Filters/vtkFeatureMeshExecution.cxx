#include "vtkFeatureMeshExecution.h"

#include "Contract.h"

#include "vtkAbstractArray.h"
#include "vtkAlgorithm.h"
#include "vtkDataObject.h"
#include "vtkDataSet.h"
#include "vtkDemandDrivenPipeline.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkSMPTools.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkType.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <string>
namespace featuremesh
{
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
