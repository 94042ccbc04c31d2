// Topological sliver removal in a tetrahedral mesh: 2-3 and 3-2 flips (the first two of Klingner &
// Shewchuk's flips, "Aggressive tetrahedral mesh improvement", IMR 2007). A tetrahedron whose four
// vertices may not move (Canny nodes) can only leave the mesh this way: sliver perturbation moves
// vertices, and TetGen's optimisation flips by the largest dihedral angle, which can lower the
// smallest one.
#pragma once

#include "ImageGeometry.h"

#include <array>
#include <cstdint>
#include <vector>

namespace featuremesh
{
// Around each tetrahedron whose smallest dihedral angle is below `angle` degrees (and, with
// `movable`, none of whose vertices is movable: the others are left to perturbation), worst first, takes
// the 2-3 flip of one of its faces or the 3-2 flip of one of its edges that most raises the smallest
// dihedral angle of the tetrahedra it replaces, if any raises it. Points never move; faces with one
// tetrahedron (the boundary) and the tiling stay (exact orientation tests in index space, angles in
// the frame). `cells` holds 4 point ids per tetrahedron, positively oriented, and stays so; `points`
// in index space. At most `rounds` passes, each over the tetrahedra still below `angle`;
// deterministic. Returns the flips made.
std::int64_t FlipSlivers(const ImageGeometry& geometry, const std::vector<std::array<double, 3>>& points,
  std::vector<std::int64_t>& cells, double angle, int rounds = 4, const std::vector<std::uint8_t>* movable = nullptr);
} // namespace featuremesh
