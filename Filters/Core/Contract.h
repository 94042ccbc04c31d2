// The contract between FeatureMesh stages in code: every array and field-data name, node types and
// label values. docs/CONTRACT.md says the same in words; change both together.
#pragma once

#include <cstdint>

namespace featuremesh
{
// NodeType point array values (stage 1 writes 0-3, stage 2 adds 4).
enum class NodeType : std::uint8_t
{
  Canny = 0,
  Halftone = 1,
  Uniform = 2,
  Boundary = 3,
  Added = 4
};

// Label cell / voxel values of the cuts.
constexpr std::uint8_t LabelBackground = 0;
constexpr std::uint8_t LabelObject = 1;

// The value of the ContractVersion field array (docs/CONTRACT.md).
constexpr std::uint8_t ContractVersionNumber = 1;

namespace names
{
// Point arrays of nodes and mesh points.
constexpr const char* NodeType = "NodeType";         // uint8, NodeType
constexpr const char* Fixed = "Fixed";               // uint8, 1 = smoothing must not move the node
constexpr const char* SampleRadius = "SampleRadius"; // float, voxels
// Cell arrays of the image mesh (stages 2, 3).
constexpr const char* PixelCount = "PixelCount";           // voxel centres the element owns
constexpr const char* MeanIntensity = "MeanIntensity";     // over those voxels
constexpr const char* IntensityStdDev = "IntensityStdDev"; // over those voxels
constexpr const char* Interpolated = "Interpolated";       // 1 = owns no voxel; mean interpolated at its centroid
constexpr const char* MinAngle = "MinAngle";               // triangles, degrees
constexpr const char* MinDihedralAngle = "MinDihedralAngle"; // tetrahedra, degrees
constexpr const char* RadiusRatio = "RadiusRatio";         // 1 = equilateral
// Cut outputs: cell array of the labelled mesh, point array of the label images.
constexpr const char* Label = "Label";
// Stage 1's edge-map image.
constexpr const char* EdgeMap = "EdgeMap";
// Stage 5's image (the input grid): paths per voxel, the marching maps, the 2D contour's region,
// and the role of each sample point (0 source, 1 sink).
constexpr const char* EdgeConfidence = "EdgeConfidence";         // float
constexpr const char* ObjectDistance = "ObjectDistance";         // float, +inf beyond the sampling threshold
constexpr const char* BackgroundDistance = "BackgroundDistance"; // float
constexpr const char* ContourRegion = "ContourRegion";           // uint8, 1 = enclosed by the final contour
constexpr const char* SampleRole = "SampleRole";                 // uint8

// Field data: the image frame a mesh was made on (3, 3, 3 and 9 components; direction row-major).
// The first field array of every output: the contract's version (uint8, one value). One byte long,
// it also makes the raw offsets of the field arrays after it odd in a .vtu that ParaView saves
// (raw appended data): meshio re-encodes raw blocks to base64 (offsets multiples of 4) and finds
// each block's array by its offset, so an even raw offset equal to an earlier array's new offset
// loses that array (a meshio bug; Testing/Python/test_meshio_saved.py replays it).
constexpr const char* ContractVersion = "ContractVersion";
constexpr const char* ImageOrigin = "ImageOrigin";
constexpr const char* ImageSpacing = "ImageSpacing";
constexpr const char* ImageDimensions = "ImageDimensions";
constexpr const char* ImageDirection = "ImageDirection";
// The image mesh's owner map (stages 2, 3): the element owning each voxel centre (int32, one tuple
// per voxel of the frame in raster order, -1 none), kept in the mesh's information (key
// FeatureMesh.VOXEL_OWNERS, with FeatureMesh.VOXEL_OWNERS_DIGEST of the points and cells it was
// made for), so that writers do not save it; the cut reuses it instead of rasterising again while
// the mesh is unchanged and says so in OwnerMapReused (field data, 1 or 0).
constexpr const char* VoxelOwner = "VoxelOwner";
constexpr const char* OwnerMapReused = "OwnerMapReused";
// Field data: summaries.
constexpr const char* NodeCounts = "NodeCounts";   // stage 1, per type
constexpr const char* StepSeconds = "StepSeconds"; // stage 1, per step
constexpr const char* NoiseSigma = "NoiseSigma";   // stage 1, the image noise's standard deviation
constexpr const char* NumberOfNodes = "NumberOfNodes";
constexpr const char* NumberOfElements = "NumberOfElements";
constexpr const char* AddedNodes = "AddedNodes";
constexpr const char* SnappedNodes = "SnappedNodes"; // stage 3, 3D: nodes moved onto the image box
constexpr const char* MaxOfMinAngles = "MaxOfMinAngles";
constexpr const char* MaxOfMinDihedralAngles = "MaxOfMinDihedralAngles";
constexpr const char* DelaunayBackend = "DelaunayBackend"; // 0 TetGen, 1 CGAL (2D is always CGAL)
constexpr const char* DelaunaySeconds = "DelaunaySeconds";
constexpr const char* StatisticsSeconds = "StatisticsSeconds";
constexpr const char* TotalSeconds = "TotalSeconds";
// Stage 3: quality of the input mesh, what the smoothing did, its time.
constexpr const char* MinAngleBefore = "MinAngleBefore";
constexpr const char* MinDihedralAngleBefore = "MinDihedralAngleBefore";
constexpr const char* IterationsRun = "IterationsRun";
constexpr const char* SmoothingMoves = "SmoothingMoves";
constexpr const char* EdgeFlips = "EdgeFlips";
constexpr const char* SliverMoves = "SliverMoves";
constexpr const char* SliverFlips = "SliverFlips";       // 3D: 2-3 and 3-2 flips around slivers
constexpr const char* RefinementRuns = "RefinementRuns"; // 2 when refinement ran again (docs/smoothing.md)
constexpr const char* SmoothingSeconds = "SmoothingSeconds";
constexpr const char* SweepSeconds = "SweepSeconds";
constexpr const char* RefinementSeconds = "RefinementSeconds";
constexpr const char* SliverSeconds = "SliverSeconds";
// Stage 5.
constexpr const char* Paths = "Paths";
constexpr const char* PathVoxels = "PathVoxels";
constexpr const char* PathGridFactor = "PathGridFactor";
constexpr const char* ObjectThreshold = "ObjectThreshold";
constexpr const char* BackgroundThreshold = "BackgroundThreshold";
constexpr const char* GradientRange = "GradientRange";
constexpr const char* MarchingSeconds = "MarchingSeconds";
constexpr const char* PathSeconds = "PathSeconds";
// Stage 6: what the smoothing did.
constexpr const char* Shortfall = "Shortfall"; // point array: distance to the smoothed position (world units)
constexpr const char* BoundaryNodes = "BoundaryNodes";
constexpr const char* PinchedNodes = "PinchedNodes";         // non-manifold boundary nodes, kept in place
constexpr const char* NonManifoldEdges = "NonManifoldEdges"; // 3D boundary edges of other than two faces
constexpr const char* ShortNodes = "ShortNodes";             // boundary nodes short of their smoothed position
constexpr const char* MaxShortfall = "MaxShortfall";         // world units
constexpr const char* ReachedFraction = "ReachedFraction";   // 1 - summed shortfall / summed smoothing displacement
constexpr const char* RelaxedNodes = "RelaxedNodes";
constexpr const char* ObjectMeasureBefore = "ObjectMeasureBefore"; // object area (2D) / volume (3D), world units
constexpr const char* ObjectMeasureAfter = "ObjectMeasureAfter";
constexpr const char* MeasureChange = "MeasureChange";       // after / before - 1
constexpr const char* SurfaceSeconds = "SurfaceSeconds";
constexpr const char* VolumeSeconds = "VolumeSeconds";
// Stage 4.
constexpr const char* Sigma = "Sigma";
constexpr const char* Bins = "Bins";
constexpr const char* SeedOverlap = "SeedOverlap";     // the seeds' densities' Bhattacharyya coefficient (binary cut)
constexpr const char* SpatialWeight = "SpatialWeight"; // the geodesic weight a binary cut used (0: none)
// R of the seeds' reach, world units (0: none); with labelled seeds one value per label.
constexpr const char* SeedReachDistance = "SeedReachDistance";
constexpr const char* Flow = "Flow";
constexpr const char* ObjectElements = "ObjectElements";
constexpr const char* ObjectComponents = "ObjectComponents";
constexpr const char* ElementId = "ElementId"; // label image: the element owning each voxel, -1 none
constexpr const char* ObjectComponentVolumes = "ObjectComponentVolumes"; // world units, largest first
constexpr const char* ConnectivityChanged = "ConnectivityChanged"; // nodes the connectivity rule relabelled
constexpr const char* SetupSeconds = "SetupSeconds";
constexpr const char* GraphSeconds = "GraphSeconds";
constexpr const char* FlowSeconds = "FlowSeconds";
constexpr const char* GeodesicSeconds = "GeodesicSeconds"; // the seeds' spatial term (Task Object)
// The voxel refinement along the cut: the voxels labelled again, those whose label then differs
// from their element's, and its time.
constexpr const char* RefinedVoxels = "RefinedVoxels";
constexpr const char* RelabelledVoxels = "RelabelledVoxels";
constexpr const char* VoxelRefinementSeconds = "VoxelRefinementSeconds";
// Multi-label cuts (labelled seeds): the number of labels k + 1 and their names (string array, one
// per label, empty names when none were given), the Potts energy reached, the expansion moves that
// lowered it, the cycles over the labels, the alpha-expansion's time.
constexpr const char* Labels = "Labels";
constexpr const char* LabelNames = "LabelNames";
constexpr const char* Energy = "Energy";
constexpr const char* ExpansionMoves = "ExpansionMoves";
constexpr const char* ExpansionCycles = "ExpansionCycles";
constexpr const char* ExpansionSeconds = "ExpansionSeconds";
constexpr const char* CutTotalSeconds = "CutTotalSeconds";
} // namespace names
} // namespace featuremesh
