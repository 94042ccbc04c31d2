// The voxel -> element owner map of stages 2 and 3: kept off the arrays writers save, found again
// by the mesh's digest, asked for (or not) by its consumers.
#ifndef vtkFeatureMeshVoxelOwners_h
#define vtkFeatureMeshVoxelOwners_h

#include "ElementRasterizer.h"

#include "vtkIntArray.h"
#include "vtkSmartPointer.h"

#include <cstdint>

class vtkDataObject;
class vtkInformationIntegerRequestKey;
class vtkInformationVector;
class vtkUnstructuredGrid;

namespace featuremesh
{
// The owner map of stages 2 and 3 (Contract.h, VoxelOwner): a fresh array of `voxels` tuples to fill
// (ComputeElementStatistics), or null when the consumers of `outputVector`'s port 0 asked for none
// (VoxelOwnersRequest); kept (when not null) in the written mesh's information and registered
// under the digest of its points and cells, off the arrays that writers save.
vtkSmartPointer<vtkIntArray> NewVoxelOwnerArray(vtkInformationVector* outputVector, std::int64_t voxels);
void AttachVoxelOwners(vtkUnstructuredGrid* mesh, vtkIntArray* owner);
// The owner map registered for `mesh`'s points and cells as they are now (any shallow copy of the
// mesh a stage wrote) when it has `voxels` tuples; else false (the caller rasterises).
// `owner` views the array (no copy) and keeps it alive.
bool AttachedVoxelOwners(vtkUnstructuredGrid* mesh, std::int64_t voxels, VoxelOwnerMap& owner);
// The request a consumer makes of a mesh's owner map, on the mesh's output information: 0 = none
// wanted. Stage 3 rasterises its own moved mesh, so it asks its input for none (0.54 GB at 512^3);
// any other consumer leaves it unset and the map is made. A request key: a change of request
// re-executes the producer. The executive passes it upstream through any filter (ParaView puts a
// pass-through filter on every output port); the stages stop it at their inputs.
vtkInformationIntegerRequestKey* VoxelOwnersRequest();
// Stage 3's request on every mesh connected to `port`: none, unless the mesh is already made and no
// request stands (asking now would make it again: ParaView's Apply runs stages one by one).
void RequestNoVoxelOwners(vtkInformationVector* portVector);
// Removes the request from every input connected to `port` (called in RequestUpdateExtent).
void StopVoxelOwnersRequest(vtkInformationVector* portVector);
// Releases the owner map registered for `mesh`'s points and cells from the stage output that keeps
// it: stage 3, which rasterises its own moved mesh, frees its input's map (0.54 GB at 512^3) when
// that mesh was made with one (ParaView's Apply runs stages one by one). A cut on that mesh
// afterwards rasterises it again.
void ReleaseVoxelOwners(vtkUnstructuredGrid* mesh);
// Releases the owner map kept in `object`'s information (a stage's output before it runs again).
void DropVoxelOwners(vtkDataObject* object);
// A 64-bit digest of a grid's points and cells as stored.
std::uint64_t MeshDigest(vtkUnstructuredGrid* grid);
} // namespace featuremesh

#endif
