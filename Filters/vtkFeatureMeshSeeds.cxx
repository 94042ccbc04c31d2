#include "vtkFeatureMeshSeeds.h"

#include "Contract.h"
#include "MultiLabelCut.h"

#include "vtkAbstractArray.h"
#include "vtkDataArray.h"
#include "vtkDataObject.h"
#include "vtkDataSetAttributes.h"
#include "vtkFieldData.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkTable.h"
#include "vtkType.h"

#include <cstring>
#include <algorithm>
#include <string>
namespace featuremesh
{
std::vector<std::array<double, 3>> PointsOf(vtkPointSet* points)
{
  const vtkIdType n = points ? points->GetNumberOfPoints() : 0;
  std::vector<std::array<double, 3>> p(n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    points->GetPoint(i, p[i].data());
  }
  return p;
}

bool ObjectAndBackgroundVoxels(vtkDataObject* object, vtkDataObject* background, const ImageGeometry& geometry,
  std::vector<std::int64_t>& objectVoxels, std::vector<std::int64_t>& backgroundVoxels, std::string& error)
{
  std::vector<std::array<double, 3>> objectPoints, backgroundPoints;
  return SeedPointsOf(object, objectPoints, error) && SeedPointsOf(background, backgroundPoints, error) &&
    SeedVoxels(objectPoints, geometry, "object", objectVoxels, error) &&
    SeedVoxels(backgroundPoints, geometry, "background", backgroundVoxels, error);
}

namespace
{
bool SameName(const char* a, const char* b)
{
  if (!a || !b)
  {
    return false;
  }
  for (; *a && *b; ++a, ++b)
  {
    if (std::tolower(static_cast<unsigned char>(*a)) != std::tolower(static_cast<unsigned char>(*b)))
    {
      return false;
    }
  }
  return *a == *b;
}

vtkDataArray* NumericColumn(vtkFieldData* data, const char* name)
{
  for (int i = 0; data && i < data->GetNumberOfArrays(); ++i)
  {
    vtkAbstractArray* a = data->GetAbstractArray(i);
    if (a && SameName(a->GetName(), name))
    {
      return vtkDataArray::SafeDownCast(a);
    }
  }
  return nullptr;
}
} // namespace

bool SeedPointsOf(vtkDataObject* seeds, std::vector<std::array<double, 3>>& world, std::string& error)
{
  world.clear();
  if (!seeds)
  {
    return true;
  }
  if (auto* points = vtkPointSet::SafeDownCast(seeds))
  {
    world = PointsOf(points);
    return true;
  }
  auto* table = vtkTable::SafeDownCast(seeds);
  if (!table)
  {
    error = "the seeds must be a point set or a table (columns x, y, z).";
    return false;
  }
  vtkDataArray* xyz[3] = { NumericColumn(table->GetRowData(), "x"), NumericColumn(table->GetRowData(), "y"),
    NumericColumn(table->GetRowData(), "z") };
  if (table->GetNumberOfRows() > 0 && (!xyz[0] || !xyz[1]))
  {
    error = "the seed table needs numeric columns x, y (and z in 3D).";
    return false;
  }
  for (vtkIdType r = 0; r < table->GetNumberOfRows(); ++r)
  {
    world.push_back({ { xyz[0]->GetComponent(r, 0), xyz[1]->GetComponent(r, 0), xyz[2] ? xyz[2]->GetComponent(r, 0) : 0.0 } });
  }
  return true;
}

bool LabelledSeedVoxels(vtkDataObject* seeds, const char* labelArray, const ImageGeometry& geometry,
  LabelledSeeds& out, std::string& error)
{
  out = LabelledSeeds();
  const std::string name = labelArray && *labelArray ? labelArray : names::Label;
  std::vector<std::array<double, 3>> world;
  if (!SeedPointsOf(seeds, world, error))
  {
    return false;
  }
  vtkFieldData* columns = vtkPointSet::SafeDownCast(seeds) ? static_cast<vtkFieldData*>(vtkPointSet::SafeDownCast(seeds)->GetPointData())
                                                             : vtkTable::SafeDownCast(seeds)->GetRowData();
  vtkDataArray* label = NumericColumn(columns, name.c_str());
  if (!label || label->GetNumberOfComponents() != 1)
  {
    error = "the seeds have no one-component numeric array named " + name + " (0 background, 1..k objects).";
    return false;
  }
  std::vector<double> labels(label->GetNumberOfTuples());
  for (vtkIdType i = 0; i < label->GetNumberOfTuples(); ++i)
  {
    labels[i] = label->GetComponent(i, 0);
  }
  error = ValidateSeedLabels(labels);
  if (!error.empty() || !SeedVoxels(world, geometry, "labelled", out.Voxel, error))
  {
    return false;
  }
  for (double l : labels)
  {
    out.Label.push_back(static_cast<std::uint8_t>(l));
  }
  return true;
}

bool BinarySeedVoxels(const LabelledSeeds& seeds, std::vector<std::int64_t>& object, std::vector<std::int64_t>& background)
{
  if (std::any_of(seeds.Label.begin(), seeds.Label.end(), [](std::uint8_t l) { return l > 1; }))
  {
    return false;
  }
  for (std::size_t s = 0; s < seeds.Voxel.size(); ++s)
  {
    (seeds.Label[s] ? object : background).push_back(seeds.Voxel[s]);
  }
  return true;
}
} // namespace featuremesh
