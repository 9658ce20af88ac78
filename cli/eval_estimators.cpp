// The estimators of `focal eval` (eval_estimators.h).
#include "eval_estimators.h"

#include "focal/curvature/baselines.h"
#include "focal/curvature/recommended.h"
#include "focal/normals/vertex_normals.h"

namespace focal::cli::eval {
namespace {

/// The baselines of issue 16 that read positions only (LRTC20 with Max's normals from the faces).
void add_positions_only_baselines(std::vector<Estimator>& out) {
  out.push_back(
      {"LRTC20 / Max normals", [](const Mesh& m) { return baselines::lachaud_2020(m.V, m.F); }});
  out.push_back({"YLHP06", [](const Mesh& m) { return baselines::yang_2006(m.V, m.F); }});
  out.push_back({"GGRZ06", [](const Mesh& m) { return baselines::grinspun_2006(m.V, m.F); }});
}

}  // namespace

std::vector<Estimator> methods() {
  std::vector<Estimator> out;
  const auto focal_method = [&out](const std::string& name, CurvatureOptions o) {
    out.push_back({name + " / file normals",
                   [o](const Mesh& m) { return estimate_curvature(m.V, m.F, m.N, o); }, true});
    out.push_back({name + " / Max normals", [o](const Mesh& m) {
                     return estimate_curvature(m.V, m.F,
                                               vertex_normals(m.V, m.F, NormalWeighting::max), o);
                   }});
  };
  // "focal default" first: the markdown summary counts its wins from rows 0 and 1 of each case.
  out.push_back({"focal default / file normals",
                 [](const Mesh& m) {
                   return estimate_curvature_recommended(m.V, m.F, m.normals()).curvature;
                 },
                 true});
  out.push_back({"focal default / no normals", [](const Mesh& m) {
                   return estimate_curvature_recommended(m.V, m.F, std::nullopt).curvature;
                 }});
  CurvatureOptions o;
  focal_method("focal closed-form 1-ring", o);
  o.rings = 2;
  focal_method("focal closed-form 2-ring", o);
  o.rings = 1;
  o.solver = Solver::levenberg_marquardt;
  focal_method("focal LM 1-ring", o);
  o = {};
  o.method = focal::Method::triangle;
  focal_method("focal per-triangle", o);
  out.push_back({"MDSB03", [](const Mesh& m) { return baselines::meyer_2003(m.V, m.F); }});
  out.push_back(
      {"CSM03", [](const Mesh& m) { return baselines::cohen_steiner_morvan_2003(m.V, m.F); }});
  out.push_back({"LRTC20 / file normals",
                 [](const Mesh& m) { return baselines::lachaud_2020(m.V, m.F, m.normals()); },
                 true});
  add_positions_only_baselines(out);
  return out;
}

std::vector<Estimator> scan_methods(bool file_normals) {
  std::vector<Estimator> out;
  if (file_normals) {
    out.push_back({"focal default / file normals", [](const Mesh& m) {
                     return estimate_curvature_recommended(m.V, m.F, m.normals()).curvature;
                   }});
  }
  out.push_back({"focal default / no normals", [](const Mesh& m) {
                   return estimate_curvature_recommended(m.V, m.F, std::nullopt).curvature;
                 }});
  out.push_back({"focal closed-form 1-ring / Max normals", [](const Mesh& m) {
                   return estimate_curvature(m.V, m.F,
                                             vertex_normals(m.V, m.F, NormalWeighting::max));
                 }});
  out.push_back({"MDSB03", [](const Mesh& m) { return baselines::meyer_2003(m.V, m.F); }});
  out.push_back(
      {"CSM03", [](const Mesh& m) { return baselines::cohen_steiner_morvan_2003(m.V, m.F); }});
  add_positions_only_baselines(out);
  return out;
}

}  // namespace focal::cli::eval
