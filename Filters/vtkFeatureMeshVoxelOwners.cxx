#include "vtkFeatureMeshVoxelOwners.h"

#include "Contract.h"
#include "Digest.h"
#include "Memory.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkDataObject.h"
#include "vtkDataSet.h"
#include "vtkInformation.h"
#include "vtkInformationIntegerRequestKey.h"
#include "vtkInformationObjectBaseKey.h"
#include "vtkInformationVector.h"
#include "vtkType.h"
#include "vtkUnstructuredGrid.h"
#include "vtkWeakPointer.h"

#include <algorithm>
#include <mutex>
namespace featuremesh
{
vtkSmartPointer<vtkIntArray> NewVoxelOwnerArray(vtkInformationVector* outputVector, std::int64_t voxels)
{
  vtkInformation* info = outputVector->GetInformationObject(0);
  if (info->Has(VoxelOwnersRequest()) && info->Get(VoxelOwnersRequest()) == 0)
  {
    return nullptr;
  }
  auto owner = vtkSmartPointer<vtkIntArray>::New();
  owner->SetName(names::VoxelOwner);
  owner->SetNumberOfTuples(static_cast<vtkIdType>(voxels));
  AdviseHugePages(owner->GetPointer(0), static_cast<std::size_t>(voxels) * sizeof(std::int32_t));
  return owner;
}

std::uint64_t MeshDigest(vtkUnstructuredGrid* grid)
{
  // Each array's type, length and bytes.
  std::uint64_t h = DigestSeed;
  auto add = [&](vtkDataArray* a) {
    if (!a)
    {
      h = DigestWord(h, 0);
      return;
    }
    const size_t bytes = static_cast<size_t>(a->GetDataSize()) * static_cast<size_t>(a->GetDataTypeSize());
    h = DigestWord(h, static_cast<std::uint64_t>(a->GetDataType()));
    h = DigestWord(h, bytes);
    h = DigestBytes(h, a->GetVoidPointer(0), bytes);
  };
  add(grid->GetPoints() ? grid->GetPoints()->GetData() : nullptr);
  vtkCellArray* cells = grid->GetCells();
  add(cells ? cells->GetConnectivityArray() : nullptr);
  add(cells ? cells->GetOffsetsArray() : nullptr);
  return h;
}

namespace
{
// The owner map is not on the data object's arrays, which writers save (4 bytes per voxel): the
// producer's output keeps it in its information, which no writer saves, and a registry finds it
// by the digest of the points and cells it was made for. The consumer's input is a shallow copy
// (ParaView puts a pass-through filter on every port), which shares the points and cells but not
// the information.
vtkInformationObjectBaseKey* OwnerMapKey()
{
  static vtkInformationObjectBaseKey* const key =
    new vtkInformationObjectBaseKey("VOXEL_OWNERS", "FeatureMesh", "vtkIntArray"); // VTK's key manager deletes it
  return key;
}

// A stage output holding a map, and the digest of the points and cells the map was made for.
struct OwnerMapEntry
{
  std::uint64_t Digest;
  vtkWeakPointer<vtkDataObject> Holder;
};

std::mutex OwnerMapsMutex;
std::vector<OwnerMapEntry>& OwnerMaps()
{
  static std::vector<OwnerMapEntry> maps;
  return maps;
}
} // namespace

void AttachVoxelOwners(vtkUnstructuredGrid* mesh, vtkIntArray* owner)
{
  DropVoxelOwners(mesh);
  if (!owner)
  {
    return;
  }
  mesh->GetInformation()->Set(OwnerMapKey(), owner);
  const std::uint64_t digest = MeshDigest(mesh);
  std::lock_guard<std::mutex> lock(OwnerMapsMutex);
  OwnerMaps().push_back({ digest, mesh });
}

namespace
{
// A request key whose data key (what the mesh was made with) is its own.
class VoxelOwnersKey : public vtkInformationIntegerRequestKey
{
public:
  VoxelOwnersKey()
    : vtkInformationIntegerRequestKey("VOXEL_OWNERS_REQUEST", "FeatureMesh")
  {
    this->DataKey = vtkInformationIntegerKey::MakeKey("VOXEL_OWNERS_MADE", "FeatureMesh");
  }
};
} // namespace

vtkInformationIntegerRequestKey* VoxelOwnersRequest()
{
  static vtkInformationIntegerRequestKey* const key = new VoxelOwnersKey; // VTK's key manager deletes it
  return key;
}

void RequestNoVoxelOwners(vtkInformationVector* portVector)
{
  for (int c = 0; c < portVector->GetNumberOfInformationObjects(); ++c)
  {
    vtkInformation* info = portVector->GetInformationObject(c);
    vtkDataSet* made = vtkDataSet::SafeDownCast(info->Get(vtkDataObject::DATA_OBJECT()));
    if (info->Has(VoxelOwnersRequest()) || (made && made->GetNumberOfPoints() == 0))
    {
      info->Set(VoxelOwnersRequest(), 0);
    }
  }
}

void StopVoxelOwnersRequest(vtkInformationVector* portVector)
{
  for (int c = 0; c < portVector->GetNumberOfInformationObjects(); ++c)
  {
    portVector->GetInformationObject(c)->Remove(VoxelOwnersRequest());
  }
}


void ReleaseVoxelOwners(vtkUnstructuredGrid* mesh)
{
  const std::uint64_t digest = MeshDigest(mesh);
  std::vector<vtkSmartPointer<vtkDataObject>> holders;
  {
    std::lock_guard<std::mutex> lock(OwnerMapsMutex);
    for (const OwnerMapEntry& e : OwnerMaps())
    {
      if (e.Digest == digest && e.Holder)
      {
        holders.emplace_back(e.Holder.GetPointer());
      }
    }
  }
  for (vtkDataObject* holder : holders)
  {
    DropVoxelOwners(holder);
  }
}

void DropVoxelOwners(vtkDataObject* object)
{
  object->GetInformation()->Remove(OwnerMapKey());
  // Its entry goes too, with those of outputs that no longer exist.
  std::lock_guard<std::mutex> lock(OwnerMapsMutex);
  auto& maps = OwnerMaps();
  maps.erase(std::remove_if(maps.begin(), maps.end(),
               [object](const OwnerMapEntry& e) { return !e.Holder || e.Holder == object; }),
    maps.end());
}

bool AttachedVoxelOwners(vtkUnstructuredGrid* mesh, std::int64_t voxels, VoxelOwnerMap& owner)
{
  vtkSmartPointer<vtkIntArray> array;
  {
    const std::uint64_t digest = MeshDigest(mesh);
    std::lock_guard<std::mutex> lock(OwnerMapsMutex);
    for (const OwnerMapEntry& e : OwnerMaps())
    {
      vtkIntArray* map = e.Digest == digest && e.Holder
        ? vtkIntArray::SafeDownCast(e.Holder->GetInformation()->Get(OwnerMapKey()))
        : nullptr;
      if (map && map->GetNumberOfComponents() == 1 && map->GetNumberOfTuples() == voxels)
      {
        array = map;
      }
    }
  }
  if (!array)
  {
    return false;
  }
  // No one edits the map (it is on no data object's arrays): the same points and cells, the same ids.
  owner.View(array->GetPointer(0), voxels, std::make_shared<vtkSmartPointer<vtkIntArray>>(array));
  return true;
}
} // namespace featuremesh
