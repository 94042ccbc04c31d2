// VTK plumbing shared by the FeatureMesh filters, one header per concern.
#ifndef vtkFeatureMeshUtilities_h
#define vtkFeatureMeshUtilities_h

#include "vtkFeatureMeshArrays.h"
#include "vtkFeatureMeshExecution.h"
#include "vtkFeatureMeshFrame.h"
#include "vtkFeatureMeshMeshes.h"
#include "vtkFeatureMeshSeeds.h"
#include "vtkFeatureMeshVoxelOwners.h"

#endif
