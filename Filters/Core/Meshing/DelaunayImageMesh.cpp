#include "DelaunayImageMesh.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_criteria_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_vertex_base_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Spatial_sort_traits_adapter_2.h>
#include <CGAL/property_map.h>
#include <CGAL/spatial_sort.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <tetgen.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <numeric>
#include <set>
#include <utility>

namespace featuremesh
{
namespace
{
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb2 = CGAL::Triangulation_vertex_base_with_info_2<std::int64_t, K>;
using Tds2 = CGAL::Triangulation_data_structure_2<Vb2>;
using DT2 = CGAL::Delaunay_triangulation_2<K, Tds2>;
using Vb3 = CGAL::Triangulation_vertex_base_with_info_3<std::int64_t, K>;
using Tds3 = CGAL::Triangulation_data_structure_3<Vb3>;
using DT3 = CGAL::Delaunay_triangulation_3<K, Tds3>;

double Orient3(const std::array<double, 3>& a, const std::array<double, 3>& b, const std::array<double, 3>& c,
  const std::array<double, 3>& d)
{
  const double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
  const double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
  const double w[3] = { d[0] - a[0], d[1] - a[1], d[2] - a[2] };
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
    u[2] * (v[0] * w[1] - v[1] * w[0]);
}

void OrientTetrahedra(DelaunayResult& r)
{
  for (size_t c = 0; c < r.Cells.size(); c += 4)
  {
    const auto& P = r.Points;
    if (Orient3(P[r.Cells[c]], P[r.Cells[c + 1]], P[r.Cells[c + 2]], P[r.Cells[c + 3]]) < 0)
    {
      std::swap(r.Cells[c + 2], r.Cells[c + 3]);
    }
  }
}

DelaunayResult TetrahedralizeCGAL(const std::vector<std::array<double, 3>>& points)
{
  DelaunayResult r;
  std::vector<std::pair<K::Point_3, std::int64_t>> input;
  input.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i)
  {
    input.emplace_back(K::Point_3(points[i][0], points[i][1], points[i][2]), static_cast<std::int64_t>(i));
  }
  DT3 dt(input.begin(), input.end());
  if (dt.dimension() < 3)
  {
    r.Error = "the nodes are coplanar (or collinear); a tetrahedral mesh needs nodes spanning a volume.";
    return r;
  }
  r.Points = points;
  r.VerticesPerCell = 4;
  r.Cells.reserve(4 * dt.number_of_finite_cells());
  for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c)
  {
    for (int v = 0; v < 4; ++v)
    {
      r.Cells.push_back(c->vertex(v)->info());
    }
  }
  OrientTetrahedra(r);
  return r;
}

// The indices of the eight corners of the points' bounding box (bit 0: x max, bit 1: y max, bit 2:
// z max); false when one of them is not a point.
bool BoxCorners(const std::vector<std::array<double, 3>>& points, std::array<int, 8>& corner, std::string& error)
{
  std::array<double, 3> lo = points[0], hi = points[0];
  for (const auto& p : points)
  {
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  }
  corner.fill(-1);
  for (size_t i = 0; i < points.size(); ++i)
  {
    int c = 0;
    bool isCorner = true;
    for (int a = 0; a < 3 && isCorner; ++a)
    {
      isCorner = points[i][a] == lo[a] || points[i][a] == hi[a];
      c |= (points[i][a] == hi[a] ? 1 : 0) << a;
    }
    if (isCorner && corner[c] < 0)
    {
      corner[c] = static_cast<int>(i);
    }
  }
  if (*std::min_element(corner.begin(), corner.end()) < 0)
  {
    error = "quality refinement needs the eight corners of the nodes' bounding box among the nodes.";
    return false;
  }
  return true;
}

DelaunayResult TetrahedralizeTetGen(const std::vector<std::array<double, 3>>& points, const DelaunayImageMeshParameters& o)
{
  DelaunayResult r;
  tetgenio in, out;
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(points.size());
  in.pointlist = new REAL[3 * points.size()]; // freed by tetgenio
  for (size_t i = 0; i < points.size(); ++i)
  {
    std::copy(points[i].begin(), points[i].end(), in.pointlist + 3 * i);
  }
  // Q quiet, z zero-based; no p: the Delaunay tetrahedralisation of the point set itself.
  std::string switches = "Qz";
  if (o.QualityRefinement)
  {
    // Refinement needs a domain: the box, as six quadrilateral facets on its corner nodes (p);
    // the other nodes are inserted into it. Without it TetGen's q discards every tetrahedron.
    std::array<int, 8> corner;
    std::string error;
    if (!BoxCorners(points, corner, error))
    {
      r.Error = error;
      return r;
    }
    // Each box face is a facet: its boundary loop through every node on the face's four edges, in
    // order (a node inside a boundary segment makes TetGen assert), and every other node on the
    // face as a one-vertex polygon.
    const std::array<double, 3> lo = points[corner[0]], hi = points[corner[7]];
    in.numberoffacets = 6;
    in.facetlist = new tetgenio::facet[6];
    in.facetmarkerlist = new int[6];
    for (int f = 0; f < 6; ++f)
    {
      const int axis = f / 2, u = (axis + 1) % 3, v = (axis + 2) % 3;
      const double plane = f % 2 ? hi[axis] : lo[axis];
      // Boundary nodes keyed by their position along the loop lo-u, hi-u, hi-v, ... (perimeter).
      std::vector<std::pair<double, int>> loop;
      std::vector<int> inside;
      const double du = hi[u] - lo[u], dv = hi[v] - lo[v];
      for (size_t i = 0; i < points.size(); ++i)
      {
        const auto& p = points[i];
        if (p[axis] != plane)
        {
          continue;
        }
        const bool uLo = p[u] == lo[u], uHi = p[u] == hi[u], vLo = p[v] == lo[v], vHi = p[v] == hi[v];
        double key = -1;
        if (vLo)
        {
          key = p[u] - lo[u];
        }
        else if (uHi)
        {
          key = du + (p[v] - lo[v]);
        }
        else if (vHi)
        {
          key = du + dv + (hi[u] - p[u]);
        }
        else if (uLo)
        {
          key = 2 * du + dv + (hi[v] - p[v]);
        }
        if (key >= 0)
        {
          loop.emplace_back(key, static_cast<int>(i));
        }
        else
        {
          inside.push_back(static_cast<int>(i));
        }
      }
      std::sort(loop.begin(), loop.end());
      tetgenio::facet& facet = in.facetlist[f];
      tetgenio::init(&facet);
      facet.numberofpolygons = 1 + static_cast<int>(inside.size());
      facet.polygonlist = new tetgenio::polygon[facet.numberofpolygons];
      for (int k = 0; k < facet.numberofpolygons; ++k)
      {
        tetgenio::polygon& polygon = facet.polygonlist[k];
        tetgenio::init(&polygon);
        polygon.numberofvertices = k == 0 ? static_cast<int>(loop.size()) : 1;
        polygon.vertexlist = new int[polygon.numberofvertices];
        for (int w = 0; w < polygon.numberofvertices; ++w)
        {
          polygon.vertexlist[w] = k == 0 ? loop[w].second : inside[k - 1];
        }
      }
      in.facetmarkerlist[f] = f + 1;
    }
    char buffer[64];
    std::snprintf(buffer, sizeof(buffer), "pq%g/%g%so/%g", o.RadiusEdgeRatio, o.MinDihedralAngle, o.PreserveBoundary ? "Y" : "",
      o.MaxDihedralAngle);
    switches += buffer;
  }
  std::vector<char> sw(switches.begin(), switches.end());
  sw.push_back('\0');
  try
  {
    tetrahedralize(sw.data(), &in, &out);
  }
  catch (int code)
  {
    r.Error = "TetGen failed (code " + std::to_string(code) +
      "); the nodes may be degenerate (coplanar, or too close to each other).";
    return r;
  }
  catch (const std::exception& e)
  {
    r.Error = std::string("TetGen failed: ") + e.what();
    return r;
  }
  if (out.numberoftetrahedra <= 0 || out.numberofpoints < static_cast<int>(points.size()))
  {
    r.Error = "TetGen produced no tetrahedra; the nodes are probably coplanar.";
    return r;
  }
  // Every node keeps its place: TetGen's optimisation smooths only the nodes it added.
  for (size_t i = 0; i < points.size(); ++i)
  {
    if (!std::equal(points[i].begin(), points[i].end(), out.pointlist + 3 * i))
    {
      r.Error = "TetGen moved node " + std::to_string(i) + "; please report this input.";
      return r;
    }
  }
  r.VerticesPerCell = 4;
  r.Points = points;
  for (int i = static_cast<int>(points.size()); i < out.numberofpoints; ++i)
  {
    r.Points.push_back({ { out.pointlist[3 * i], out.pointlist[3 * i + 1], out.pointlist[3 * i + 2] } });
  }
  r.Cells.assign(out.tetrahedronlist, out.tetrahedronlist + 4 * static_cast<size_t>(out.numberoftetrahedra));
  OrientTetrahedra(r);
  return r;
}
} // namespace

bool SpansDimension(const std::vector<std::array<double, 3>>& points, int dimension)
{
  if (points.size() < static_cast<size_t>(dimension + 1))
  {
    return false;
  }
  // A first distinct point, a first point off their line, then (3D) a first point off their plane.
  const auto& a = points[0];
  size_t bi = 0, ci = 0;
  for (size_t i = 1; i < points.size() && !bi; ++i)
  {
    if (points[i][0] != a[0] || points[i][1] != a[1] || (dimension == 3 && points[i][2] != a[2]))
    {
      bi = i;
    }
  }
  for (size_t i = bi + 1; bi && i < points.size() && !ci; ++i)
  {
    const bool offLine = dimension == 2
      ? CGAL::orientation(K::Point_2(a[0], a[1]), K::Point_2(points[bi][0], points[bi][1]),
          K::Point_2(points[i][0], points[i][1])) != CGAL::COLLINEAR
      : !CGAL::collinear(K::Point_3(a[0], a[1], a[2]), K::Point_3(points[bi][0], points[bi][1], points[bi][2]),
          K::Point_3(points[i][0], points[i][1], points[i][2]));
    if (offLine)
    {
      ci = i;
    }
  }
  if (!ci || dimension == 2)
  {
    return ci != 0;
  }
  for (size_t i = ci + 1; i < points.size(); ++i)
  {
    if (CGAL::orientation(K::Point_3(a[0], a[1], a[2]), K::Point_3(points[bi][0], points[bi][1], points[bi][2]),
          K::Point_3(points[ci][0], points[ci][1], points[ci][2]),
          K::Point_3(points[i][0], points[i][1], points[i][2])) != CGAL::COPLANAR)
    {
      return true;
    }
  }
  return false;
}

std::int64_t CountDuplicates(const std::vector<std::array<double, 3>>& points)
{
  std::vector<std::array<double, 3>> sorted(points);
  std::sort(sorted.begin(), sorted.end());
  std::int64_t duplicates = 0;
  for (size_t i = 1; i < sorted.size(); ++i)
  {
    duplicates += sorted[i] == sorted[i - 1] ? 1 : 0;
  }
  return duplicates;
}

DelaunayResult Triangulate2D(const std::vector<std::array<double, 3>>& points)
{
  DelaunayResult r;
  try
  {
    std::vector<std::pair<K::Point_2, std::int64_t>> input;
    input.reserve(points.size());
    for (size_t i = 0; i < points.size(); ++i)
    {
      input.emplace_back(K::Point_2(points[i][0], points[i][1]), static_cast<std::int64_t>(i));
    }
    DT2 dt(input.begin(), input.end());
    if (dt.dimension() < 2)
    {
      r.Error = "the nodes are collinear; a triangle mesh needs nodes spanning an area.";
      return r;
    }
    r.Points = points;
    r.VerticesPerCell = 3;
    r.Cells.reserve(3 * dt.number_of_faces());
    // CGAL's finite faces are counter-clockwise.
    for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f)
    {
      for (int v = 0; v < 3; ++v)
      {
        r.Cells.push_back(f->vertex(v)->info());
      }
    }
  }
  catch (const std::exception& e)
  {
    r = DelaunayResult();
    r.Error = std::string("CGAL failed: ") + e.what();
  }
  return r;
}

DelaunayResult RefineQuality2D(const std::vector<std::array<double, 3>>& points, double minAngle)
{
  using Vb = CGAL::Triangulation_vertex_base_with_info_2<std::int64_t, K, CGAL::Delaunay_mesh_vertex_base_2<K>>;
  using Fb = CGAL::Delaunay_mesh_face_base_2<K>;
  using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
  using CDT = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;
  using Criteria = CGAL::Delaunay_mesh_criteria_2<CDT>;
  DelaunayResult r;
  try
  {
    CDT cdt;
    double lo[2] = { points[0][0], points[0][1] }, hi[2] = { lo[0], lo[1] };
    for (const auto& p : points)
    {
      for (int a = 0; a < 2; ++a)
      {
        lo[a] = std::min(lo[a], p[a]);
        hi[a] = std::max(hi[a], p[a]);
      }
    }
    // Inserted along a Hilbert curve, each from the last one's face: one by one in input order
    // was most of the refinement's time.
    std::vector<K::Point_2> planar(points.size());
    std::transform(points.begin(), points.end(), planar.begin(), [](const std::array<double, 3>& p) { return K::Point_2(p[0], p[1]); });
    std::vector<std::size_t> order(points.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    using Map = CGAL::Pointer_property_map<K::Point_2>::type;
    CGAL::spatial_sort(order.begin(), order.end(),
      CGAL::Spatial_sort_traits_adapter_2<K, Map>(CGAL::make_property_map(planar)));
    std::vector<CDT::Vertex_handle> handle(points.size());
    CDT::Face_handle hint;
    for (const std::size_t i : order)
    {
      handle[i] = cdt.insert(planar[i], hint);
      handle[i]->info() = static_cast<std::int64_t>(i);
      hint = handle[i]->face();
    }
    // The box boundary: constrained segments between consecutive points on each side.
    for (int side = 0; side < 4; ++side)
    {
      const int axis = side / 2, other = 1 - axis;
      const double at = side % 2 ? hi[axis] : lo[axis];
      std::vector<std::pair<double, size_t>> on;
      for (size_t i = 0; i < points.size(); ++i)
      {
        if (points[i][axis] == at)
        {
          on.emplace_back(points[i][other], i);
        }
      }
      std::sort(on.begin(), on.end());
      for (size_t k = 1; k < on.size(); ++k)
      {
        cdt.insert_constraint(handle[on[k - 1].second], handle[on[k].second]);
      }
    }
    const double s = std::sin(std::min(minAngle, 20.7) * 3.14159265358979323846 / 180.0);
    CGAL::refine_Delaunay_mesh_2(cdt, Criteria(s * s));
    // The mesher only adds vertices: the input's handles stay valid.
    const std::set<CDT::Vertex_handle> input(handle.begin(), handle.end());
    r.Points = points;
    for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v)
    {
      if (!input.count(v))
      {
        v->info() = static_cast<std::int64_t>(r.Points.size());
        r.Points.push_back({ { v->point().x(), v->point().y(), 0.0 } });
      }
    }
    r.VerticesPerCell = 3;
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f)
    {
      if (f->is_in_domain())
      {
        for (int v = 0; v < 3; ++v)
        {
          r.Cells.push_back(f->vertex(v)->info());
        }
      }
    }
  }
  catch (const std::exception& e)
  {
    r = DelaunayResult();
    r.Error = std::string("CGAL failed: ") + e.what();
  }
  return r;
}

DelaunayResult Tetrahedralize(const std::vector<std::array<double, 3>>& points, const DelaunayImageMeshParameters& o)
{
  try
  {
    // Coplanarity is checked first with exact predicates: TetGen on such input is not
    // guaranteed to fail cleanly.
    const bool spansVolume = SpansDimension(points, 3);
    if (!spansVolume)
    {
      DelaunayResult r;
      r.Error = "the nodes are coplanar (or collinear); a tetrahedral mesh needs nodes spanning a volume.";
      return r;
    }
    return o.Backend == DelaunayBackend::CGAL ? TetrahedralizeCGAL(points) : TetrahedralizeTetGen(points, o);
  }
  catch (const std::exception& e)
  {
    DelaunayResult r;
    r.Error = std::string("tetrahedralisation failed: ") + e.what();
    return r;
  }
}

std::string ValidateParameters(const DelaunayImageMeshParameters& o, bool planar)
{
  // TetGen's refinement need not terminate beyond these bounds (its guarantee holds for a ratio of 2
  // and no angle bound): the liver's nodes never returned with a ratio of 1.0 or an angle of 25.
  if (!planar && o.QualityRefinement &&
    (!(o.RadiusEdgeRatio >= 1.2) || !(o.MinDihedralAngle >= 0.0 && o.MinDihedralAngle <= 18.0)))
  {
    return "quality refinement needs a radius-edge ratio of at least 1.2 and a minimum dihedral angle in [0, 18] "
           "degrees; TetGen may not terminate beyond them.";
  }
  return std::string();
}

std::string ImageMeshNodes(const ImageGeometry& geometry, std::vector<std::array<double, 3>>& index)
{
  const bool is2D = geometry.Is2D();
  const std::int64_t n = static_cast<std::int64_t>(index.size());
  if (n < (is2D ? 3 : 4))
  {
    return std::to_string(n) + " nodes are too few; a " + (is2D ? "triangle" : "tetrahedral") +
      " mesh needs at least " + (is2D ? "3" : "4") + ".";
  }
  // On voxel centres when Feature Nodes placed them, anywhere else too (the rasteriser owns each
  // voxel centre exactly whatever the nodes, as after stage 3).
  std::int64_t outside = 0, offPlane = 0;
  for (auto& p : index)
  {
    p = geometry.WorldToIndex(p);
    bool in = true;
    for (int a = 0; a < 3; ++a)
    {
      in = in && p[a] >= 0.0 && p[a] <= geometry.Dims[a] - 1.0;
    }
    outside += in ? 0 : 1;
    offPlane += (is2D && p[2] != 0.0) ? 1 : 0;
  }
  if (is2D && offPlane)
  {
    return "the image is 2D but " + std::to_string(offPlane) +
      " nodes lie off its slice plane; the nodes do not match the image's dimension.";
  }
  if (outside)
  {
    return std::to_string(outside) + " of " + std::to_string(n) + " nodes lie outside the image bounds.";
  }
  if (n > MaximumImageMeshNodes)
  {
    return std::to_string(n) + " nodes are more than the " + std::to_string(MaximumImageMeshNodes) +
      " this filter meshes; raise the node spacing in Feature Nodes.";
  }
  const std::int64_t duplicates = CountDuplicates(index);
  if (duplicates)
  {
    return std::to_string(duplicates) + " nodes duplicate other nodes; remove them (e.g. with Clean) first.";
  }
  if (!SpansDimension(index, is2D ? 2 : 3))
  {
    return std::string("the nodes are ") + (is2D ? "collinear" : "coplanar (or collinear)") +
      "; a mesh needs nodes spanning the image's " + (is2D ? "area." : "volume.");
  }
  std::vector<std::array<double, 3>> sorted(index);
  std::sort(sorted.begin(), sorted.end());
  for (int c = 0; c < (is2D ? 4 : 8); ++c)
  {
    const std::array<double, 3> corner = { { (c & 1) ? geometry.Dims[0] - 1.0 : 0.0,
      (c & 2) ? geometry.Dims[1] - 1.0 : 0.0, (c & 4) ? geometry.Dims[2] - 1.0 : 0.0 } };
    if (!std::binary_search(sorted.begin(), sorted.end(), corner))
    {
      index.push_back(corner);
    }
  }
  return std::string();
}
} // namespace featuremesh
