#pragma once
// `focal eval`'s flags and the cases of its analytic suite (eval_cases.cpp): how each case's
// mesh is made and perturbed, which vertices are scored, and the export of the cases.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/evaluation/evaluation.h"

namespace focal::cli::eval {

/// Which cases `focal eval` runs: today's suite (paper Fig. 10), the hard cases, or both.
enum class Suite { standard, hard, all };

struct EvalFlags {
  int vertices = 4000;
  std::uint64_t seed = 1;
  Suite suite = Suite::all;
  std::string csv;
  std::string markdown;
  std::string export_dir;          ///< analytic mode: the cases; scan mode: coloured H fields
  std::vector<std::string> scans;  ///< scan mode when non-empty
  bool points = false;             ///< --points: the cloud estimator on analytic clouds
};

/// What a case does to the exact mesh: noise as in the paper's Fig. 10 (amplitudes in mean edge
/// lengths, resp. of the normal's perturbation), outlier normals and spikes (fractions of the
/// vertices; spikes are kSpikeHeight mean edge lengths long).
struct Perturbation {
  double vertex_noise = 0.0;
  double normal_noise = 0.0;
  double outlier_normals = 0.0;
  double spikes = 0.0;
};
constexpr double kSpikeHeight = 2.0;

/// One case: a category ("standard" for today's suite), its labels, how its exact mesh is made
/// (from --vertices and --seed), what is done to it and which vertices are scored.
struct Case {
  std::string category;
  std::string surface;
  std::string mesh;   ///< how it is triangulated: regular, irregular, strips 1:8, ...
  std::string noise;  ///< what is done to it: clean, vertex noise 10%, ...
  std::function<AnalyticSurface(const EvalFlags&)> make;
  Perturbation perturbation;
  bool boundary_band = false;  ///< scored at rings 1-2 of the boundary instead of the interior
  std::string slug;            ///< file-name form
};

/// "focal default / no normals" -> "focal-default-no-normals".
std::string slug_of(const std::string& name);

/// The cases of `suite`, today's suite first.
std::vector<Case> cases(Suite suite);

/// The case's mesh: made from `f`'s --vertices and --seed, then perturbed.
AnalyticSurface make_case(const Case& c, const EvalFlags& f);

/// The vertices a case scores: the interior (more than 2 rings from a boundary), or rings 1-2.
VectorXu8 scored_vertices(const Case& c, const AnalyticSurface& s);

/// The case's evaluation: `interior` holds the scored vertices' errors.
Evaluation evaluate_case(const Case& c, const AnalyticSurface& s, const CurvatureResult& e);

/// "surface, mesh, noise": the case's row label in the tables and the progress lines.
std::string case_label(const Case& c);

/// Creates an output folder; a failure is an IoError (exit 2), not an internal error.
void make_folder(const std::string& dir);

/// Writes DIR/cases.csv (slug, surface, triangulation, noise, vertices) and per case
/// DIR/<slug>.ply and DIR/<slug>.truth.csv (see focal::export_case).
void export_cases(const std::string& dir, const std::vector<std::pair<Case, AnalyticSurface>>& all);

}  // namespace focal::cli::eval
