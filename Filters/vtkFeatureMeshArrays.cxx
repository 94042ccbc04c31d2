#include "vtkFeatureMeshArrays.h"
#include "vtkFeatureMeshExecution.h"
#include "vtkFeatureMeshFrame.h"

#include "Contract.h"
#include "ImageFilters.h"
#include "MultiLabelCut.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDataObject.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkSMPTools.h"
#include "vtkType.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <string>
namespace featuremesh
{
namespace
{
// Values beyond these are refused: float's range for stage 1's float arithmetic, and magnitudes
// whose squares and sums stay finite for the double arithmetic of stages 2 and 4.
template <typename T>
constexpr double LargestValue()
{
  return sizeof(T) == sizeof(float) ? 3.4028234663852886e38 : 1e150;
}

// With `values` null, only checks.
template <typename T>
bool ToValues(vtkDataArray* array, std::vector<T>* values, std::string& error)
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
  if (values)
  {
    values->resize(static_cast<size_t>(n));
  }
  std::vector<vtkIdType> badPerBlock(64, 0);
  const vtkIdType block = (n + 63) / 64;
  auto convert = [&](auto* data) {
    vtkSMPTools::For(0, 64, 1, [&](vtkIdType b0, vtkIdType b1) {
      for (vtkIdType b = b0; b < b1; ++b)
      {
        // A local count and a raw pointer let the compiler vectorise the conversion.
        vtkIdType bad = 0;
        T* out = values ? values->data() : nullptr;
        for (vtkIdType i = b * block, e = std::min(n, (b + 1) * block); i < e; ++i)
        {
          const double v = static_cast<double>(data[i]);
          const bool ok = std::isfinite(v) && std::fabs(v) <= LargestValue<T>();
          bad += ok ? 0 : 1;
          if (out)
          {
            out[i] = ok ? static_cast<T>(v) : T(0);
          }
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
      std::to_string(bad) + " values that are NaN, infinite or beyond +-" +
      (sizeof(T) == sizeof(float) ? "3.4e38" : "1e150") + "; replace or rescale them (e.g. with a Calculator) first.";
    return false;
  }
  return true;
}
} // namespace

bool ToFloat(vtkDataArray* array, std::vector<float>& values, std::string& error)
{
  return ToValues(array, &values, error);
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

LocalContrastArray::LocalContrastArray() = default;
LocalContrastArray::~LocalContrastArray() = default;

vtkDataArray* LocalContrastArray::Of(
  vtkDataArray* values, const ImageGeometry& g, double scale, const ParallelFor& parallel, std::string& error)
{
  if (this->Result && this->Source == values && this->Time == values->GetMTime() && this->Scale == scale &&
    SameFrame(this->Frame, g))
  {
    return this->Result;
  }
  this->Result = nullptr;
  const int components = values->GetNumberOfComponents();
  const vtkIdType n = values->GetNumberOfTuples();
  vtkNew<vtkFloatArray> result;
  result->SetName(values->GetName());
  result->SetNumberOfComponents(components);
  result->SetNumberOfTuples(n);
  // One component: the array's own floats when it holds them, the contrast written in place. More:
  // each component as a float array of the array's name (checked as any image array is), then
  // interleaved.
  vtkNew<vtkFloatArray> channel;
  std::vector<float> storage, contrast(components > 1 ? n : 0);
  for (int c = 0; c < components; ++c)
  {
    vtkDataArray* one = values;
    if (components > 1)
    {
      channel->SetName(values->GetName());
      channel->SetNumberOfTuples(n);
      channel->CopyComponent(0, values, c);
      one = channel;
    }
    const float* in = FloatValues(one, storage, error);
    if (!in)
    {
      return nullptr;
    }
    float* out = components > 1 ? contrast.data() : result->GetPointer(0);
    LocalContrast(in, out, g, scale, parallel);
    for (vtkIdType i = 0; i < n && components > 1; ++i)
    {
      result->SetValue(i * components + c, contrast[i]);
    }
  }
  this->Source = values;
  this->Time = values->GetMTime();
  this->Scale = scale;
  this->Frame = g;
  this->Result = result;
  return this->Result;
}

vtkDataArray* CutValues(vtkDataArray* values, bool contrast, const ImageGeometry& g, double scale,
  std::unique_ptr<LocalContrastArray>& kept, std::string& error)
{
  if (!contrast || !values)
  {
    kept.reset();
    return values;
  }
  if (!kept)
  {
    kept = std::make_unique<LocalContrastArray>();
  }
  return kept->Of(values, g, scale, SMPParallelFor(), error);
}

bool ToDouble(vtkDataArray* array, std::vector<double>& values, std::string& error)
{
  return ToValues(array, &values, error);
}

bool CheckDouble(vtkDataArray* array, std::string& error)
{
  return ToValues<double>(array, nullptr, error);
}

vtkSmartPointer<vtkImageData> VoxelValuedImage(vtkImageData* image, vtkInformation* arrayInfo)
{
  if (!image)
  {
    return nullptr;
  }
  vtkCellData* cells = image->GetCellData();
  // A cell array named by the selection; pvpython can carry a selection over from another source.
  const bool cellChosen = arrayInfo && arrayInfo->Has(vtkDataObject::FIELD_ASSOCIATION()) &&
    arrayInfo->Get(vtkDataObject::FIELD_ASSOCIATION()) == vtkDataObject::FIELD_ASSOCIATION_CELLS &&
    arrayInfo->Has(vtkDataObject::FIELD_NAME()) && cells->GetArray(arrayInfo->Get(vtkDataObject::FIELD_NAME()));
  const bool onlyCells = image->GetPointData()->GetNumberOfArrays() == 0 && cells->GetNumberOfArrays() > 0;
  if (!(cellChosen || onlyCells) || image->GetNumberOfCells() == 0)
  {
    return image;
  }
  int extent[6];
  image->GetExtent(extent);
  double half[3] = { 0.0, 0.0, 0.0 };
  for (int a = 0; a < 3; ++a)
  {
    if (extent[2 * a + 1] > extent[2 * a])
    {
      extent[2 * a + 1] -= 1;
      half[a] = 0.5;
    }
  }
  // Index i of the new image is the old continuous index i + 1/2: its origin is the old (1/2, ...).
  double origin[3];
  image->TransformContinuousIndexToPhysicalPoint(half[0], half[1], half[2], origin);
  vtkNew<vtkImageData> voxels;
  voxels->SetExtent(extent);
  voxels->SetSpacing(image->GetSpacing());
  voxels->SetDirectionMatrix(image->GetDirectionMatrix());
  voxels->SetOrigin(origin);
  voxels->GetPointData()->ShallowCopy(cells);
  voxels->GetPointData()->RemoveArray(vtkDataSetAttributes::GhostArrayName());
  voxels->GetFieldData()->ShallowCopy(image->GetFieldData());
  return voxels;
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

void AddFieldValues(vtkDataObject* object, std::initializer_list<std::pair<const char*, double>> values)
{
  for (const auto& v : values)
  {
    AddFieldValue(object, v.first, v.second);
  }
}

namespace
{
// A field array `name` of n values, value(i) each.
template <typename Value>
void AddFieldArray(vtkDataObject* object, const char* name, std::size_t n, Value&& value)
{
  vtkNew<vtkDoubleArray> array;
  array->SetName(name);
  array->SetNumberOfValues(static_cast<vtkIdType>(n));
  for (std::size_t i = 0; i < n; ++i)
  {
    array->SetValue(static_cast<vtkIdType>(i), value(i));
  }
  object->GetFieldData()->AddArray(array);
}
} // namespace

void AddObjectComponents(vtkDataObject* object, const std::vector<double>& componentVoxels, double voxelVolume,
  std::int64_t connectivityChanged)
{
  AddFieldValue(object, names::ObjectComponents, static_cast<double>(componentVoxels.size()));
  AddFieldArray(object, names::ObjectComponentVolumes, componentVoxels.size(),
    [&](std::size_t c) { return componentVoxels[c] * voxelVolume; });
  AddFieldValue(object, names::ConnectivityChanged, static_cast<double>(connectivityChanged));
}

void AddLabelTable(vtkDataObject* object, int labels, const std::string& text)
{
  AddFieldValue(object, names::Labels, labels);
  // Numbers named by their components, not strings: meshio reads no string arrays.
  vtkNew<vtkUnsignedCharArray> list;
  list->SetName(names::LabelNames);
  list->SetNumberOfComponents(labels);
  list->SetNumberOfTuples(1);
  std::size_t from = 0;
  for (int l = 0; l < labels; ++l)
  {
    std::string name;
    if (from <= text.size())
    {
      const std::size_t end = std::min(text.find(';', from), text.size());
      name = text.substr(from, end - from);
      from = end + 1;
    }
    list->SetComponentName(l, name.c_str());
    list->SetComponent(0, l, l);
  }
  object->GetFieldData()->AddArray(list);
}

void AddMultiLabelFields(vtkDataObject* object, const MultiLabelResult& result, const std::string& labelNames)
{
  AddLabelTable(object, result.Labels, labelNames);
  AddFieldValue(object, names::Sigma, result.Sigma);
  AddFieldValue(object, names::Energy, result.Energy);
  AddFieldValue(object, names::ExpansionMoves, result.Moves);
  AddFieldValue(object, names::ExpansionCycles, result.Cycles);
  AddFieldValue(object, names::ExpansionSeconds, result.ExpansionSeconds);
  AddFieldValue(object, names::GeodesicSeconds, result.GeodesicSeconds);
  const std::vector<double>& reach = result.ReachDistance;
  AddFieldArray(object, names::SeedReachDistance, static_cast<std::size_t>(std::max(result.Labels, 0)),
    [&](std::size_t l) { return l < reach.size() ? reach[l] : 0.0; });
}

void SetLabelImage(vtkImageData* image, const ImageGeometry& geometry, const std::vector<std::uint8_t>& labels)
{
  SetImageFrame(image, geometry);
  vtkNew<vtkUnsignedCharArray> array;
  array->SetName(names::Label);
  array->SetNumberOfTuples(geometry.Size());
  std::copy(labels.begin(), labels.end(), array->GetPointer(0));
  image->GetPointData()->SetScalars(array);
}
} // namespace featuremesh
