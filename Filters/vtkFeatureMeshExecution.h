// How a FeatureMesh filter runs: the thread backend, the parallel-for and progress adapters for the
// VTK-free core, exceptions at the VTK boundary, failed runs not repeated, empty pieces, property setters.
#ifndef vtkFeatureMeshExecution_h
#define vtkFeatureMeshExecution_h

#include "Parallel.h"

#include "vtkSMPTools.h"
#include "vtkObject.h"

#include <cstdlib>
#include <exception>
#include <string>

class vtkAlgorithm;
class vtkDataObject;
class vtkInformationVector;

namespace featuremesh
{
// Reports an exception that escaped a filter's body as its error (out of memory, or a library's
// failure); returns 0.
int ReportException(vtkAlgorithm* algorithm, const char* filter, const std::exception_ptr& error);

// A property's setter where the filter's Core parameter differs in name or type (an enumeration,
// an unsigned or 64-bit count): the parameter takes the value, and the filter is Modified when it changed.
template <typename Parameter, typename Value>
void SetParameter(vtkObject* filter, Parameter& parameter, Value value)
{
  const Parameter v = static_cast<Parameter>(value);
  if (parameter != v)
  {
    parameter = v;
    filter->Modified();
  }
}

// SetParameter of an enumeration property, clamped to [low, high] as vtkSetClampMacro does.
template <typename Parameter>
void SetClampedParameter(vtkObject* filter, Parameter& parameter, int value, int low, int high)
{
  SetParameter(filter, parameter, value < low ? low : (value > high ? high : value));
}

// The accessors of the properties whose Core field has another name or type, which both seeded cuts
// (vtkSuperVoxelCut, vtkVoxelCut: featuremesh::SeededCutParameters and MultiLabelParameters)
// declare; defined once here, expanded in each cut's .cxx.
#define FEATUREMESH_SEEDED_CUT_ACCESSORS(cls)                                                                      \
  void cls::SetTask(int value) { featuremesh::SetParameter(this, this->featuremesh::SeededCutParameters::Task, value); } \
  int cls::GetTask() { return static_cast<int>(this->featuremesh::SeededCutParameters::Task); }                    \
  void cls::SetConnectivity(int value)                                                                             \
  {                                                                                                                \
    featuremesh::SetClampedParameter(this, this->featuremesh::SeededCutParameters::Connectivity, value, 0, 3);    \
  }                                                                                                                \
  int cls::GetConnectivity() { return static_cast<int>(this->featuremesh::SeededCutParameters::Connectivity); }    \
  void cls::SetIntensity(int value) { featuremesh::SetParameter(this, this->featuremesh::SeededCutParameters::Intensity, value); } \
  int cls::GetIntensity() { return static_cast<int>(this->featuremesh::SeededCutParameters::Intensity); }          \
  void cls::SetGeodesicWeight(double value) { featuremesh::SetParameter(this, this->Geodesic.Weight, value); }     \
  double cls::GetGeodesicWeight() { return this->Geodesic.Weight; }                                                \
  void cls::SetGeodesicLength(double value) { featuremesh::SetParameter(this, this->Geodesic.LengthWeight, value); } \
  double cls::GetGeodesicLength() { return this->Geodesic.LengthWeight; }                                          \
  void cls::SetAdaptiveGeodesicWeight(bool value) { featuremesh::SetParameter(this, this->Geodesic.Adaptive, value); } \
  bool cls::GetAdaptiveGeodesicWeight() { return this->Geodesic.Adaptive; }                                        \
  void cls::SetSeedReach(double value) { featuremesh::SetParameter(this, this->featuremesh::SeededCutParameters::Reach.Reach, value); } \
  double cls::GetSeedReach() { return this->featuremesh::SeededCutParameters::Reach.Reach; }                      \
  void cls::SetSeedReachWeight(double value) { featuremesh::SetParameter(this, this->featuremesh::SeededCutParameters::Reach.Weight, value); } \
  double cls::GetSeedReachWeight() { return this->featuremesh::SeededCutParameters::Reach.Weight; }               \
  void cls::SetChannelModel(int value) { featuremesh::SetClampedParameter(this, this->Channels, value, 0, 2); }    \
  int cls::GetChannelModel() { return static_cast<int>(this->Channels); }

// What a run depends on: the newest modification of the filter or of anything upstream, and the
// requested time step (a time series changes the data, not the modification times).
struct RunState
{
  vtkMTimeType Modified = 0;
  double TimeStep = 0.0;
  bool operator==(const RunState& other) const
  {
    return this->Modified == other.Modified && this->TimeStep == other.TimeStep;
  }
};
RunState PipelineState(vtkAlgorithm* algorithm, vtkInformationVector* outputVector);

// Puts the field array ContractVersion (Contract.h) first in the field data of every output.
void PutContractVersionFirst(vtkInformationVector* outputVector);

// Stores the exact value range of each component of every point and cell array (and of the points)
// of every output in the array's information (vtkDataArray::COMPONENT_RANGE, the cache GetRange and
// GetFiniteRange read; Modified() drops it). ParaView asks for both ranges of every array after each
// Apply, and VTK 9.2 computes each at ~20 ns per value: 0.4 s for a BraTS label image, several times
// what the re-cut took. Arrays holding NaN are left to VTK. Returns the arrays stored.
int StoreValueRanges(vtkInformationVector* outputVector);

// Runs a filter's body (returning int): on the STDThread SMP backend when VTK runs its Sequential
// default and the user chose none with VTK_SMP_BACKEND_IN_USE (the host's backend is left as it
// was), and with every exception caught at the VTK boundary. A failure is not run (and reported)
// again until the filter or its inputs change: ParaView updates every output port, and a failed
// run leaves them all out of date. `failedAt` and `failedAtTime` are the filter's record of it.
template <typename Body>
int RunFilter(vtkAlgorithm* algorithm, const char* filter, vtkInformationVector* outputVector,
  vtkMTimeType& failedAt, double& failedAtTime, Body&& body)
{
  const RunState state = PipelineState(algorithm, outputVector);
  if (failedAt && state == RunState{ failedAt, failedAtTime })
  {
    return 0;
  }
  int result = 0;
  try
  {
    if (std::getenv("VTK_SMP_BACKEND_IN_USE") || std::string(vtkSMPTools::GetBackend()) != "Sequential")
    {
      result = body();
    }
    else
    {
      vtkSMPTools::LocalScope(vtkSMPTools::Config(std::string("STDThread")), [&]() { result = body(); });
    }
  }
  catch (...)
  {
    result = ReportException(algorithm, filter, std::current_exception());
  }
  if (result)
  {
    PutContractVersionFirst(outputVector);
    StoreValueRanges(outputVector);
  }
  failedAt = result ? 0 : state.Modified;
  failedAtTime = state.TimeStep;
  return result;
}

// True on a parallel process that holds no piece of the data: the input is empty and this is not
// piece 0. The filters then succeed with empty outputs and say nothing (the whole image is on one
// process; see docs/CONTRACT.md).
bool IsEmptyPiece(vtkInformationVector* outputVector, vtkDataObject* input);

// A parallel-for on vtkSMPTools.
ParallelFor SMPParallelFor();

// Maps core progress [0,1] to [begin,end] of the algorithm's progress; false once abort is asked
// (CheckAbort: the executive then clears the outputs and re-executes on the next update).
ProgressFunction AlgorithmProgress(vtkAlgorithm* algorithm, double begin, double end);

// Sets the update extent of every image connected to `port` to its whole extent.
void RequestWholeImage(vtkInformationVector* portVector);
} // namespace featuremesh

#endif
