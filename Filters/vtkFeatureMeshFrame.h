// The image frame between VTK and the core's ImageGeometry: read from an image, kept in field data,
// compared, given to an output image.
#ifndef vtkFeatureMeshFrame_h
#define vtkFeatureMeshFrame_h

#include "ImageGeometry.h"

#include <string>

class vtkDataObject;
class vtkImageData;

namespace featuremesh
{
// The frame of an image (its extent's first voxel is index 0), or an error sentence: the image
// must have at least 2 voxels along x and y, and a usable spacing and direction.
bool ImageGeometryOf(vtkImageData* image, ImageGeometry& geometry, std::string& error);

// The image frame in field data (ImageOrigin, ImageSpacing, ImageDimensions, ImageDirection), so
// that later stages can rasterise onto the grid without the image.
void AddImageGeometry(const ImageGeometry& geometry, vtkDataObject* object);
bool ImageGeometryFromFieldData(vtkDataObject* object, ImageGeometry& geometry, std::string& error);

// True when two frames describe the same grid (to 1e-9 of the spacing).
bool SameFrame(const ImageGeometry& a, const ImageGeometry& b);

// False, with a sentence, when `mesh` records an image frame (field data) that differs from the
// connected image's `frame`; a mesh without a recorded frame matches.
bool MeshMatchesImage(vtkDataObject* mesh, const ImageGeometry& frame, std::string& error);

// Gives `image` the frame's extent (from 0), origin, spacing and direction.
void SetImageFrame(vtkImageData* image, const ImageGeometry& geometry);
} // namespace featuremesh

#endif
