// Seed handling shared by the two cut filters: seed points to voxels, with the contract's errors.
#ifndef vtkFeatureMeshSeeds_h
#define vtkFeatureMeshSeeds_h

#include "Grid.h"

#include <cstdint>
#include <string>
#include <vector>

class vtkPointSet;

namespace featuremesh
{
struct GridGeometry
{
  Grid G;
  double Origin[3] = { 0, 0, 0 };
  double Spacing[3] = { 1, 1, 1 };
};

// Voxel index (nearest centre) of every seed; false with a sentence naming how many seeds fall
// outside the image, or when there are none. `what` names the seed kind in messages.
bool SeedVoxels(vtkPointSet* seeds, const GridGeometry& geometry, const char* what,
  std::vector<std::int64_t>& voxels, std::string& error);
} // namespace featuremesh

#endif
