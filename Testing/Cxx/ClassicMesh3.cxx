// The classic pipeline's meshing step, for the benchmark only: CGAL Mesh_3 on a label image (what a
// user without FeatureMesh runs after a voxel cut to get a simulation mesh). Object and background
// are both meshed (labels 2 and 1 to CGAL, whose label 0 is outside), as FeatureMesh's mesh tiles
// the whole box.
//
// usage: FeatureMeshClassicMesh3 labels.raw nx ny nz sx sy sz [facet_distance]
// labels.raw: nx*ny*nz uint8 labels, x fastest. Prints one line: seconds (meshing only, not I/O),
// vertices and tetrahedra of the complex.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Image_3.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/make_mesh_3.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <vector>

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Domain = CGAL::Labeled_mesh_domain_3<K>;
using Tr = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr>;
using Criteria = CGAL::Mesh_criteria_3<Tr>;

int main(int argc, char** argv)
{
  if (argc < 8)
  {
    std::fprintf(stderr, "usage: %s labels.raw nx ny nz sx sy sz [facet_distance]\n", argv[0]);
    return 2;
  }
  const int n[3] = { std::atoi(argv[2]), std::atoi(argv[3]), std::atoi(argv[4]) };
  const double s[3] = { std::atof(argv[5]), std::atof(argv[6]), std::atof(argv[7]) };
  const double distance = argc > 8 ? std::atof(argv[8]) : 2.0;
  const size_t voxels = static_cast<size_t>(n[0]) * n[1] * n[2];
  std::vector<unsigned char> labels(voxels);
  std::ifstream in(argv[1], std::ios::binary);
  if (!in.read(reinterpret_cast<char*>(labels.data()), static_cast<std::streamsize>(voxels)))
  {
    std::fprintf(stderr, "cannot read %zu bytes from %s\n", voxels, argv[1]);
    return 2;
  }
  const auto t0 = std::chrono::steady_clock::now();
  _image* image = ::_createImage(n[0], n[1], n[2], 1, s[0], s[1], s[2], 1, WK_FIXED, SGN_UNSIGNED);
  unsigned char* data = static_cast<unsigned char*>(image->data);
  for (size_t v = 0; v < voxels; ++v)
  {
    data[v] = static_cast<unsigned char>(labels[v] ? 2 : 1);
  }
  CGAL::Image_3 wrapped(image);
  const Domain domain = Domain::create_labeled_image_mesh_domain(wrapped);
  // CGAL's examples' criteria, with the facet distance the issue names.
  namespace params = CGAL::parameters;
  const Criteria criteria(params::facet_angle = 30, params::facet_size = 6, params::facet_distance = distance,
    params::cell_radius_edge_ratio = 3, params::cell_size = 8);
  const C3t3 c3t3 = CGAL::make_mesh_3<C3t3>(domain, criteria, params::no_perturb(), params::no_exude());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("seconds %.3f vertices %zu tetrahedra %zu\n", seconds,
    static_cast<size_t>(c3t3.triangulation().number_of_vertices()), static_cast<size_t>(c3t3.number_of_cells_in_complex()));
  return 0;
}
