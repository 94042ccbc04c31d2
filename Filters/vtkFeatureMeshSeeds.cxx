#include "vtkFeatureMeshSeeds.h"

#include "vtkPointSet.h"

#include <cmath>

namespace featuremesh
{
bool SeedVoxels(vtkPointSet* seeds, const GridGeometry& geo, const char* what, std::vector<std::int64_t>& voxels,
  std::string& error)
{
  voxels.clear();
  const vtkIdType n = seeds ? seeds->GetNumberOfPoints() : 0;
  if (n == 0)
  {
    error = std::string("no ") + what + " seeds were given; connect a point set with at least one point.";
    return false;
  }
  vtkIdType outside = 0;
  for (vtkIdType i = 0; i < n; ++i)
  {
    double x[3];
    seeds->GetPoint(i, x);
    int ijk[3];
    bool in = true;
    for (int a = 0; a < 3; ++a)
    {
      const double c = (x[a] - geo.Origin[a]) / geo.Spacing[a];
      // Half a voxel of slack: a seed belongs to the voxel that contains it.
      in = in && std::isfinite(c) && c > -0.5 && c < geo.G.Dims[a] - 0.5;
      ijk[a] = in ? static_cast<int>(std::lround(c)) : 0;
      if (in && geo.G.Dims[a] == 1)
      {
        ijk[a] = 0;
      }
    }
    if (!in)
    {
      ++outside;
      continue;
    }
    voxels.push_back(geo.G.Index(ijk[0], ijk[1], ijk[2]));
  }
  if (outside)
  {
    error = std::to_string(outside) + " of " + std::to_string(n) + " " + what + " seeds fall outside the image.";
    return false;
  }
  return true;
}
} // namespace featuremesh
