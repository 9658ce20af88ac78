// CGAL 5.5 (Debian libcgal-dev) as a peer of focal's cloud curvature: for each point, its k
// nearest neighbours (CGAL's kd-tree) and Monge_via_jet_fitting (degree-2 jet, degree-2 Monge
// form) on the point and them. Normals: the file's when it has them, else
// CGAL::jet_estimate_normals (k neighbours) + CGAL::mst_orient_normals (k neighbours); the Monge
// form is turned to agree with that normal (comply_wrt_given_normal).
//
// Sign convention: CGAL's Monge coefficients k1 >= k2 are those of z = (k1 x^2 + k2 y^2) / 2 with
// z along the normal, so a sphere with outward normals has -1/r; focal's is +1/r. The output is
// negated (and k1, k2 swapped) into focal's convention.
//
// Usage: cgal_peer IN.xyz K OUT.csv   (IN: x y z [nx ny nz] per line). Writes k1,k2,H and d1 (the
// unit direction of focal's k1: CGAL's minimal principal direction, the sign being negated) per
// point and prints "normals_s fit_s" (wall seconds) on stdout.

#include <CGAL/Monge_via_jet_fitting.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Search_traits_adapter.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/jet_estimate_normals.h>
#include <CGAL/mst_orient_normals.h>
#include <CGAL/property_map.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "xyz_rows.h"

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Vector = Kernel::Vector_3;
// mst_orient_normals reorders its range (oriented points first): the input index travels along.
using PointWithNormal = std::tuple<Point, Vector, std::size_t>;
using PointMap = CGAL::Nth_of_tuple_property_map<0, PointWithNormal>;
using NormalMap = CGAL::Nth_of_tuple_property_map<1, PointWithNormal>;
using Traits = CGAL::Search_traits_3<Kernel>;
using Search = CGAL::Orthogonal_k_neighbor_search<Traits>;
using Monge = CGAL::Monge_via_jet_fitting<Kernel>;

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: cgal_peer IN.xyz K OUT.csv\n");
    return 1;
  }
  const unsigned k = static_cast<unsigned>(std::atoi(argv[2]));
  const XyzRows input = read_xyz_rows(argv[1]);
  const bool has_normals = input.has_normals;
  std::vector<PointWithNormal> points;
  for (const auto& v : input.rows) {
    points.emplace_back(Point(v[0], v[1], v[2]), Vector(v[3], v[4], v[5]), points.size());
  }
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  if (!has_normals) {
    CGAL::jet_estimate_normals<CGAL::Sequential_tag>(
        points, k, CGAL::parameters::point_map(PointMap()).normal_map(NormalMap()));
    CGAL::mst_orient_normals(points, k,
                             CGAL::parameters::point_map(PointMap()).normal_map(NormalMap()));
  }
  std::sort(points.begin(), points.end(),
            [](const auto& a, const auto& b) { return std::get<2>(a) < std::get<2>(b); });
  const auto t1 = Clock::now();
  std::vector<Point> positions;
  positions.reserve(points.size());
  for (const auto& p : points) positions.push_back(std::get<0>(p));
  Search::Tree tree(positions.begin(), positions.end());
  std::vector<double> k1(points.size()), k2(points.size());
  std::vector<Vector> d1(points.size());
  std::vector<Point> neighbourhood;
  for (std::size_t i = 0; i < points.size(); ++i) {
    neighbourhood.clear();
    Search search(tree, std::get<0>(points[i]), k + 1);  // the point itself first
    for (const auto& hit : search) neighbourhood.push_back(hit.first);
    Monge fitter;
    Monge::Monge_form form = fitter(neighbourhood.begin(), neighbourhood.end(), 2, 2);
    form.comply_wrt_given_normal(std::get<1>(points[i]));
    k1[i] = -form.principal_curvatures(1);  // focal's sign: bending away from the normal > 0
    k2[i] = -form.principal_curvatures(0);
    d1[i] = form.minimal_principal_direction();  // the direction of CGAL's k2, focal's k1
  }
  const auto t2 = Clock::now();
  std::ofstream out(argv[3]);
  out << "k1,k2,H,d1x,d1y,d1z\n";
  out.precision(17);
  for (std::size_t i = 0; i < points.size(); ++i) {
    out << k1[i] << ',' << k2[i] << ',' << 0.5 * (k1[i] + k2[i]) << ',' << d1[i].x() << ','
        << d1[i].y() << ',' << d1[i].z() << '\n';
  }
  std::printf("%.4f %.4f\n", std::chrono::duration<double>(t1 - t0).count(),
              std::chrono::duration<double>(t2 - t1).count());
  return 0;
}
