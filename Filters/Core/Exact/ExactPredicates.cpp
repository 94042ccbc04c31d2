#include "ExactPredicates.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

namespace featuremesh
{
using K = CGAL::Exact_predicates_inexact_constructions_kernel;

int Orientation3(const std::array<double, 3>& a, const std::array<double, 3>& b, const std::array<double, 3>& c,
  const std::array<double, 3>& d)
{
  return static_cast<int>(CGAL::orientation(K::Point_3(a[0], a[1], a[2]), K::Point_3(b[0], b[1], b[2]),
    K::Point_3(c[0], c[1], c[2]), K::Point_3(d[0], d[1], d[2])));
}

int Orientation2(const std::array<double, 3>& a, const std::array<double, 3>& b, const std::array<double, 3>& c)
{
  return static_cast<int>(
    CGAL::orientation(K::Point_2(a[0], a[1]), K::Point_2(b[0], b[1]), K::Point_2(c[0], c[1])));
}

int InCircle(const std::array<double, 3>& a, const std::array<double, 3>& b, const std::array<double, 3>& c,
  const std::array<double, 3>& d)
{
  return static_cast<int>(CGAL::side_of_oriented_circle(
    K::Point_2(a[0], a[1]), K::Point_2(b[0], b[1]), K::Point_2(c[0], c[1]), K::Point_2(d[0], d[1])));
}
} // namespace featuremesh
