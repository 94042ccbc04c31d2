// Exact orientation signs (CGAL's filtered predicates), for the rare evaluations that rounding
// cannot decide. A library of its own so that CGAL's compile flags stay out of the hot loops.
#pragma once

#include <array>

namespace featuremesh
{
// Sign of det[b - a, c - a, d - a]: +1, 0 or -1, exactly.
int Orientation3(const std::array<double, 3>& a, const std::array<double, 3>& b, const std::array<double, 3>& c,
  const std::array<double, 3>& d);
// Sign of the cross product (b - a) x (c - a) in the xy plane, exactly.
int Orientation2(const std::array<double, 3>& a, const std::array<double, 3>& b, const std::array<double, 3>& c);
// +1 when d lies inside the circle through the counter-clockwise triangle a, b, c (xy plane), 0 on
// it, -1 outside; exactly.
int InCircle(const std::array<double, 3>& a, const std::array<double, 3>& b, const std::array<double, 3>& c,
  const std::array<double, 3>& d);
} // namespace featuremesh
