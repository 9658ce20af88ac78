// The recommended estimator's context (recommended_steps.h): the mesh with its 1-ring and Max's
// normals, and the fits that every step calls on it (the paper's two-slit fit, the roughness of
// a normal field, jets from Max's normals).
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "curvature/recommended_steps.h"
#include "curvature/vertex_fit.h"
#include "focal/core/error.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/normals/vertex_normals.h"
#include "mesh/prepared_access.h"
#include "normals/jet_normals_from.h"
#include "normals/vertex_normals_from.h"

namespace focal::detail::recommended {

void validate_options(const RecommendedOptions& o, const char* what) {
  const auto non_negative = [&](double x, const char* name) {
    if (!(x >= 0.0)) throw InvalidInput(std::string(what) + ": " + name + " must be >= 0");
  };
  non_negative(o.noise_for_two_rings, "noise_for_two_rings");
  non_negative(o.noise_for_three_rings, "noise_for_three_rings");
  non_negative(o.file_agreement, "file_agreement");
  non_negative(o.outlier_disagreement, "outlier_disagreement");
  non_negative(o.tolerances.zero, "zero_tolerance");
  non_negative(o.tolerances.umbilic, "umbilic_tolerance");
  non_negative(o.crease_angle, "crease_angle");
}

Context make_context(const PreparedMesh& mesh, const RecommendedOptions& options) {
  return {mesh, options, mesh.mean_edge_length(), detail::one_ring(mesh),
          detail::vertex_normals_from(mesh.V(), mesh.F(), *detail::incidence(mesh),
                                      NormalWeighting::max, 0)};
}

CurvatureOptions paper_options(const Context& c) {
  CurvatureOptions o;
  o.tolerances = c.options.tolerances;
  return o;
}

CurvatureResult two_slit_fit(const Context& c, const PreparedMesh& normals, int rings,
                             bool gaussian) {
  CurvatureOptions o = paper_options(c);
  o.rings = rings;
  o.weighting = gaussian && rings > 1 ? RayWeighting::gaussian : RayWeighting::uniform;
  const detail::UnitNormals& unit = detail::unit_normals(normals);
  const PositionsRef& V = c.mesh.V();
  if (rings == 1) return detail::fit_vertices({V, unit.N, unit.ok, *c.one_ring, c.edge_length}, o);
  const Neighbourhoods ring = k_ring(*c.one_ring, rings);
  return detail::fit_vertices({V, unit.N, unit.ok, ring, c.edge_length}, o);
}

Eigen::VectorXd roughness_of(const Context& c, NormalsRef normals) {
  const PreparedMesh with = c.mesh.with_normals(normals);
  const detail::UnitNormals& unit = detail::unit_normals(with);
  return detail::fit_roughness({c.mesh.V(), unit.N, unit.ok, *c.one_ring, c.edge_length},
                               paper_options(c));
}

Eigen::VectorXd roughness_at(const Context& c, NormalsRef normals,
                             const std::vector<int>& vertices) {
  const PreparedMesh with = c.mesh.with_normals(normals);
  const detail::UnitNormals& unit = detail::unit_normals(with);
  return detail::fit_roughness_at({c.mesh.V(), unit.N, unit.ok, *c.one_ring, c.edge_length},
                                  paper_options(c), vertices.data(),
                                  static_cast<Eigen::Index>(vertices.size()));
}

double finite_median(const Eigen::VectorXd& x) {
  std::vector<double> v;
  v.reserve(static_cast<std::size_t>(x.size()));
  for (double e : x) {
    if (std::isfinite(e)) v.push_back(e);
  }
  if (v.empty()) return NAN;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

JetOptions jet_options(int rings, int degree) {
  JetOptions o;
  o.rings = rings;
  o.degree = degree;
  o.iterations = 1;
  return o;
}

JetNormals local_jets(const Context& c, int rings, int degree) {
  return detail::jet_normals_from(c.mesh.V(), *c.one_ring, c.max, jet_options(rings, degree));
}

}  // namespace focal::detail::recommended
