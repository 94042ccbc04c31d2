#include "vtkFeatureMeshFrame.h"

#include "Contract.h"

#include "vtkDataArray.h"
#include "vtkDataObject.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkNew.h"
#include "vtkType.h"

#include <algorithm>
#include <cmath>
#include <string>
namespace featuremesh
{
bool ImageGeometryOf(vtkImageData* image, ImageGeometry& geometry, std::string& error)
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
  ImageGeometry g;
  g.Dims = { { dims[0], dims[1], dims[2] } };
  std::copy(image->GetSpacing(), image->GetSpacing() + 3, g.Spacing.begin());
  const double* d = image->GetDirectionMatrix()->GetData();
  std::copy(d, d + 9, g.Direction.begin());
  const int* ext = image->GetExtent();
  image->TransformContinuousIndexToPhysicalPoint(ext[0], ext[2], ext[4], g.Origin.data());
  error = g.Validate();
  if (!error.empty())
  {
    return false;
  }
  geometry = g;
  return true;
}

void AddImageGeometry(const ImageGeometry& g, vtkDataObject* object)
{
  auto add = [&](const char* name, const double* v, int n) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->SetNumberOfComponents(n);
    a->InsertNextTuple(v);
    object->GetFieldData()->AddArray(a);
  };
  const double dims[3] = { double(g.Dims[0]), double(g.Dims[1]), double(g.Dims[2]) };
  add(names::ImageOrigin, g.Origin.data(), 3);
  add(names::ImageSpacing, g.Spacing.data(), 3);
  add(names::ImageDimensions, dims, 3);
  add(names::ImageDirection, g.Direction.data(), 9);
}

bool ImageGeometryFromFieldData(vtkDataObject* object, ImageGeometry& geometry, std::string& error)
{
  vtkFieldData* fd = object->GetFieldData();
  vtkDataArray* o = fd->GetArray(names::ImageOrigin);
  vtkDataArray* s = fd->GetArray(names::ImageSpacing);
  vtkDataArray* d = fd->GetArray(names::ImageDimensions);
  vtkDataArray* r = fd->GetArray(names::ImageDirection);
  if (!o || !s || !d || o->GetNumberOfComponents() != 3 || s->GetNumberOfComponents() != 3 ||
    d->GetNumberOfComponents() != 3 || o->GetNumberOfTuples() < 1 || s->GetNumberOfTuples() < 1 ||
    d->GetNumberOfTuples() < 1)
  {
    error = "the mesh's field data hold no image frame (ImageOrigin, ImageSpacing, ImageDimensions); meshes made by "
            "Delaunay Image Mesh and the filters after it carry one.";
    return false;
  }
  ImageGeometry g;
  for (int a = 0; a < 3; ++a)
  {
    g.Origin[a] = o->GetComponent(0, a);
    g.Spacing[a] = s->GetComponent(0, a);
    const double n = d->GetComponent(0, a);
    g.Dims[a] = n >= 1 && n <= 1e9 ? static_cast<int>(n) : 0;
  }
  // Meshes written before the direction was recorded have an identity frame.
  if (r && r->GetNumberOfComponents() == 9 && r->GetNumberOfTuples() >= 1)
  {
    for (int k = 0; k < 9; ++k)
    {
      g.Direction[k] = r->GetComponent(0, k);
    }
  }
  error = g.Validate();
  if (!error.empty())
  {
    error = "the mesh's image frame (field data): " + error;
    return false;
  }
  geometry = g;
  return true;
}

bool SameFrame(const ImageGeometry& a, const ImageGeometry& b)
{
  if (a.Dims != b.Dims)
  {
    return false;
  }
  const double tol = 1e-9 * std::max({ std::fabs(a.Spacing[0]), std::fabs(a.Spacing[1]), std::fabs(a.Spacing[2]) });
  for (int k = 0; k < 3; ++k)
  {
    if (std::fabs(a.Origin[k] - b.Origin[k]) > tol || std::fabs(a.Spacing[k] - b.Spacing[k]) > tol)
    {
      return false;
    }
  }
  for (int k = 0; k < 9; ++k)
  {
    if (std::fabs(a.Direction[k] - b.Direction[k]) > 1e-9)
    {
      return false;
    }
  }
  return true;
}

bool MeshMatchesImage(vtkDataObject* mesh, const ImageGeometry& frame, std::string& error)
{
  ImageGeometry recorded;
  std::string ignored;
  if (ImageGeometryFromFieldData(mesh, recorded, ignored) && !SameFrame(recorded, frame))
  {
    error = "the mesh was made on another image grid than the connected Image (dimensions, origin, spacing or "
            "direction differ); connect the image the mesh was made from.";
    return false;
  }
  return true;
}

void SetImageFrame(vtkImageData* image, const ImageGeometry& g)
{
  image->SetExtent(0, g.Dims[0] - 1, 0, g.Dims[1] - 1, 0, g.Dims[2] - 1);
  image->SetOrigin(g.Origin.data());
  image->SetSpacing(g.Spacing.data());
  image->SetDirectionMatrix(g.Direction.data());
}
} // namespace featuremesh
