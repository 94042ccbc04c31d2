// Seeds from VTK data: point sets or CSV tables, binary or labelled, as voxels of the image.
#ifndef vtkFeatureMeshSeeds_h
#define vtkFeatureMeshSeeds_h

#include "ImageGeometry.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

class vtkDataObject;
class vtkPointSet;

namespace featuremesh
{
struct LabelledSeeds;

// The points of a point set, world coordinates (empty for null).
std::vector<std::array<double, 3>> PointsOf(vtkPointSet* points);

// The world positions of seeds given as a point set, or as a table with columns x, y (and z),
// matched without case, as ParaView's CSV reader gives them (empty for null); false with a sentence
// for another data type or a table without the columns.
bool SeedPointsOf(vtkDataObject* seeds, std::vector<std::array<double, 3>>& world, std::string& error);

// The voxels of the object and background seeds (point sets or tables, SeedPointsOf; SeedVoxels for
// each); false with the sentence of the first that fails.
bool ObjectAndBackgroundVoxels(vtkDataObject* object, vtkDataObject* background, const ImageGeometry& geometry,
  std::vector<std::int64_t>& objectVoxels, std::vector<std::int64_t>& backgroundVoxels, std::string& error);

// Labelled seeds from a point set (a point array named `labelArray`) or a table (columns x, y, z and
// `labelArray`, as a CSV reader gives them), names matched without case: their voxels and labels
// (0 background, 1..k objects, checked by ValidateSeedLabels). False with a sentence.
bool LabelledSeedVoxels(vtkDataObject* seeds, const char* labelArray, const ImageGeometry& geometry,
  LabelledSeeds& out, std::string& error);

// True when `seeds` hold the labels 0 and 1 only, the binary cut's seeds: `object` and `background`
// then get their voxels.
bool BinarySeedVoxels(const LabelledSeeds& seeds, std::vector<std::int64_t>& object, std::vector<std::int64_t>& background);
} // namespace featuremesh

#endif
