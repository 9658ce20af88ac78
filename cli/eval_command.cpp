// `focal eval`: every estimator over the analytic suite (paper Fig. 10's noise models), errors
// against the exact truth as CSV and a Markdown table; `--export` writes the cases for external
// tools; `--scan` measures the smoothness of H on scanned meshes without truth (paper Fig. 7).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <sstream>

#include "commands.h"
#include "eval_points.h"
#include "focal/core/error.h"
#include "focal/curvature/baselines.h"
#include "focal/curvature/recommended.h"
#include "focal/evaluation/evaluation.h"
#include "focal/io/mesh_io.h"
#include "focal/normals/vertex_normals.h"
#include "paths.h"

namespace focal::cli {
namespace {

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

/// One estimator: a name and how it runs on a mesh whose N holds the file's normals.
/// `reads_normals`: whether it uses the file's normals (else it sees positions only).
struct Estimator {
  std::string name;
  std::function<CurvatureResult(const Mesh&)> run;
  bool reads_normals = false;
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
std::string slug_of(const std::string& name) {
  std::string out;
  for (char ch : name) {
    if (std::isalnum(static_cast<unsigned char>(ch))) {
      out += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    } else if (!out.empty() && out.back() != '-') {
      out += '-';
    }
  }
  while (!out.empty() && out.back() == '-') out.pop_back();
  return out;
}

std::string percent(double fraction) {
  std::ostringstream s;
  s << fraction * 100.0 << "%";
  return s.str();
}

std::string noise_name(const Perturbation& p) {
  std::vector<std::string> parts;
  if (p.vertex_noise > 0) parts.push_back("vertex noise " + percent(p.vertex_noise));
  if (p.normal_noise > 0) parts.push_back("normal noise " + percent(p.normal_noise));
  if (p.outlier_normals > 0) parts.push_back(percent(p.outlier_normals) + " outlier normals");
  if (p.spikes > 0) parts.push_back(percent(p.spikes) + " spikes");
  if (parts.empty()) return "clean";
  std::string out = parts[0];
  for (std::size_t k = 1; k < parts.size(); ++k) out += " + " + parts[k];
  return out;
}

/// The baselines of issue 16 that read positions only (LRTC20 with Max's normals from the faces).
void add_positions_only_baselines(std::vector<Estimator>& out) {
  out.push_back(
      {"LRTC20 / Max normals", [](const Mesh& m) { return baselines::lachaud_2020(m.V, m.F); }});
  out.push_back({"YLHP06", [](const Mesh& m) { return baselines::yang_2006(m.V, m.F); }});
  out.push_back({"GGRZ06", [](const Mesh& m) { return baselines::grinspun_2006(m.V, m.F); }});
}

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

/// An analytic surface of the suite, `vertices` (0: --vertices) and `shape` adjusting the options.
std::function<AnalyticSurface(const EvalFlags&)> surface_maker(
    SurfaceKind kind, Triangulation triangulation, int vertices = 0,
    std::function<void(SurfaceOptions&)> shape = {}) {
  return [=](const EvalFlags& f) {
    SurfaceOptions o;
    o.kind = kind;
    o.triangulation = triangulation;
    o.target_vertices = vertices > 0 ? vertices : f.vertices;
    o.seed = f.seed;
    if (shape) shape(o);
    return make_surface(o);
  };
}

std::string triangulation_name(Triangulation t) {
  return t == Triangulation::regular ? "regular" : "irregular";
}

/// Today's suite: every surface, regular and irregular, clean and with the paper's Fig. 10 noise
/// (10% vertex noise with the exact normals; 5% normal noise on exact positions).
std::vector<Case> standard_cases() {
  std::vector<Case> out;
  const std::pair<Perturbation, const char*> noises[] = {{{}, "clean"},
                                                         {{.vertex_noise = 0.1}, "vertex-noise"},
                                                         {{.normal_noise = 0.05}, "normal-noise"}};
  for (SurfaceKind k : all_surfaces()) {
    for (auto t : {Triangulation::regular, Triangulation::irregular}) {
      for (const auto& [p, slug] : noises) {
        const std::string surface(surface_name(k));
        out.push_back({"standard", surface, triangulation_name(t), noise_name(p),
                       surface_maker(k, t), p, false,
                       surface + "-" + triangulation_name(t) + "-" + slug});
      }
    }
  }
  return out;
}

/// The hard cases of issue 16 (docs/ACCURACY.md, "Hard cases"): meshes and data as real files
/// have them, each category on several surfaces so that no choice is tuned to one.
std::vector<Case> hard_cases() {
  using enum SurfaceKind;
  constexpr auto regular = Triangulation::regular, irregular = Triangulation::irregular;
  std::vector<Case> out;
  const auto add = [&out](const std::string& category, SurfaceKind kind, const std::string& mesh,
                          std::function<AnalyticSurface(const EvalFlags&)> make,
                          Perturbation p = {}, bool band = false) {
    const std::string surface(surface_name(kind));
    out.push_back({category, surface, mesh, noise_name(p), std::move(make), p, band,
                   slug_of(category + " " + surface + " " + mesh + " " + noise_name(p))});
  };
  const auto aspect = [](double a) { return [a](SurfaceOptions& o) { o.aspect = a; }; };
  // Strips: CAD exports of surfaces of revolution (along the cylinder's axis; lat-long rows
  // with thin pole fans on the sphere and the ellipsoid), and thin cells across curvature.
  add("anisotropic", cylinder, "strips 8:1 along the axis",
      surface_maker(cylinder, regular, 0, aspect(1.0 / 8)));
  add("anisotropic", sphere, "lat-long 8:1 with pole fans",
      surface_maker(sphere, regular, 0, aspect(8)));
  add("anisotropic", ellipsoid, "lat-long 1:5 with pole fans",
      surface_maker(ellipsoid, regular, 0, aspect(1.0 / 5)));
  add("anisotropic", torus, "strips 8:1", surface_maker(torus, regular, 0, aspect(8)));
  add("anisotropic", saddle, "strips 20:1", surface_maker(saddle, regular, 0, aspect(20)));
  add("anisotropic", helix_tube, "strips 1:5", surface_maker(helix_tube, regular, 0, aspect(0.2)));
  const auto graded = [](SurfaceOptions& o) { o.grading = 10; };
  for (SurfaceKind k : {ellipsoid, torus, saddle, pear})
    add("graded density", k, "irregular with density 10:1", surface_maker(k, irregular, 0, graded));
  for (SurfaceKind k : {torus, ellipsoid, pear, helix_tube, monkey_saddle})
    add("coarse", k, "irregular with 850 vertices", surface_maker(k, irregular, 850));
  add("coarse", ellipsoid, "regular with 850 vertices", surface_maker(ellipsoid, regular, 850));
  for (const auto& [k, a] : {std::pair{sphere, 0.5},
                             {torus, 0.3},
                             {torus, 0.5},
                             {ellipsoid, 0.3},
                             {pear, 0.5},
                             {saddle, 0.3}})
    add("strong vertex noise", k, "irregular", surface_maker(k, irregular), {.vertex_noise = a});
  for (SurfaceKind k : {sphere, torus, ellipsoid, monkey_saddle})
    add("strong normal noise", k, "irregular", surface_maker(k, irregular), {.normal_noise = 0.3});
  for (SurfaceKind k : {torus, ellipsoid, pear})
    add("outliers", k, "irregular", surface_maker(k, irregular), {.outlier_normals = 0.02});
  for (SurfaceKind k : {sphere, torus, saddle})
    add("outliers", k, "irregular", surface_maker(k, irregular), {.spikes = 0.005});
  add("outliers", helix_tube, "irregular", surface_maker(helix_tube, irregular),
      {.outlier_normals = 0.02, .spikes = 0.005});
  for (SurfaceKind k : {saddle, monkey_saddle, cylinder, helix_tube})
    add("near boundaries", k, "irregular scored at rings 1-2", surface_maker(k, irregular), {},
        true);
  add("near boundaries", saddle, "irregular scored at rings 1-2", surface_maker(saddle, irregular),
      {.vertex_noise = 0.1}, true);
  const auto capped = [](const EvalFlags& f) { return make_capped_cylinder(1.0, 2.0, f.vertices); };
  for (const Perturbation& p :
       {Perturbation{}, Perturbation{.vertex_noise = 0.1}, Perturbation{.normal_noise = 0.05}}) {
    out.push_back({"creases", "capped-cylinder", "regular with rims not scored", noise_name(p),
                   capped, p, false, slug_of("creases capped-cylinder " + noise_name(p))});
  }
  return out;
}

std::vector<Case> cases(Suite suite) {
  std::vector<Case> out;
  if (suite != Suite::hard) out = standard_cases();
  if (suite != Suite::standard) {
    std::vector<Case> hard = hard_cases();
    out.insert(out.end(), hard.begin(), hard.end());
  }
  return out;
}

AnalyticSurface make_case(const Case& c, const EvalFlags& f) {
  AnalyticSurface s = c.make(f);
  const Perturbation& p = c.perturbation;
  if (p.vertex_noise > 0) add_position_noise(s.mesh, p.vertex_noise, f.seed + 1);
  if (p.normal_noise > 0) add_normal_noise(s.mesh, p.normal_noise, f.seed + 2);
  if (p.outlier_normals > 0) add_outlier_normals(s.mesh, p.outlier_normals, f.seed + 3);
  if (p.spikes > 0) add_spikes(s.mesh, p.spikes, kSpikeHeight, f.seed + 4);
  return s;
}

/// The vertices a case scores: the interior (more than 2 rings from a boundary), or rings 1-2.
VectorXu8 scored_vertices(const Case& c, const AnalyticSurface& s) {
  const int n = static_cast<int>(s.mesh.V.rows());
  return c.boundary_band ? boundary_band_mask(n, s.mesh.F, 1, 2) : interior_mask(n, s.mesh.F);
}

/// The case's evaluation: `interior` holds the scored vertices' errors.
Evaluation evaluate_case(const Case& c, const AnalyticSurface& s, const CurvatureResult& e) {
  Evaluation out = evaluate(s, e);
  if (c.boundary_band) out.interior = evaluate_at(s, e, scored_vertices(c, s));
  return out;
}

std::string case_label(const Case& c) { return c.surface + ", " + c.mesh + ", " + c.noise; }

struct Row {
  Case c;
  std::string method;
  Evaluation e;
};

std::string number(double x) {
  if (std::isnan(x)) return "nan";
  std::ostringstream s;
  s.precision(4);
  s << x;
  return s.str();
}

void write_csv_table(const std::string& path, const std::vector<Row>& rows) {
  std::vector<std::string> cols[20];
  const char* names[20] = {"surface",        "triangulation", "noise",
                           "method",         "vertices",      "undefined",
                           "rel_H",          "rel_K",         "rel_k1",
                           "rel_k2",         "rms_H",         "rms_K",
                           "rms_k1",         "rms_k2",        "median_angle_d1",
                           "mean_angle_d1",  "variance_H",    "boundary_vertices",
                           "boundary_rel_H", "category"};
  for (const Row& r : rows) {
    const ErrorMetrics& m = r.e.interior;
    const std::string values[20] = {r.c.surface,
                                    r.c.mesh,
                                    r.c.noise,
                                    r.method,
                                    std::to_string(m.vertices),
                                    std::to_string(m.undefined),
                                    number(m.relative_H),
                                    number(m.relative_K),
                                    number(m.relative_k1),
                                    number(m.relative_k2),
                                    number(m.rms_H),
                                    number(m.rms_K),
                                    number(m.rms_k1),
                                    number(m.rms_k2),
                                    number(m.median_angle_d1),
                                    number(m.mean_angle_d1),
                                    number(m.variance_H),
                                    std::to_string(r.e.near_boundary.vertices),
                                    number(r.e.near_boundary.relative_H),
                                    r.c.category};
    for (int k = 0; k < 20; ++k) cols[k].push_back(values[k]);
  }
  std::vector<CsvColumn> columns;
  for (int k = 0; k < 20; ++k) columns.push_back({names[k], cols[k]});
  write_csv(path, columns);
}

/// Whether `v` is at most `best`: within 0.1% (the 4 digits the tables show; the same estimator
/// on the same normals can differ in the last bits) or both below 1e-12 (exact up to rounding).
bool at_most(double v, double best) {
  return v <= best * (1.0 + 1e-3) || (v < 1e-12 && best < 1e-12);
}

/// How focal default fares in one case (rows [r, r + methods) of the table).
struct CaseWins {
  double file = NAN, none = NAN;  ///< focal default's relative H error, file normals / none
  double best_other = NAN;        ///< lowest of every other method (not focal default)
  double best_positions = NAN;    ///< lowest of the other positions-only methods
  bool file_wins = false, none_wins = false;
};

CaseWins wins_of(const std::vector<Row>& rows, std::size_t r, const std::vector<Estimator>& ms) {
  CaseWins w;
  w.file = rows[r].e.interior.relative_H, w.none = rows[r + 1].e.interior.relative_H;
  double best_other = INFINITY, best_positions = INFINITY;
  for (std::size_t k = 2; k < ms.size(); ++k) {  // rows 0 and 1 are focal default
    const double v = rows[r + k].e.interior.relative_H;
    if (std::isnan(v)) continue;
    best_other = std::min(best_other, v);
    if (!ms[k].reads_normals) best_positions = std::min(best_positions, v);
  }
  w.best_other = best_other, w.best_positions = best_positions;
  w.file_wins = at_most(w.file, best_other);
  w.none_wins = at_most(w.none, best_positions);
  return w;
}

double median_of(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

/// Per hard category: how often focal default has the lowest H error (issue 16's targets) and
/// the medians over the category's cases.
std::string category_summary(const std::vector<Row>& rows, const std::vector<Estimator>& ms) {
  std::vector<std::string> order;
  std::map<std::string, std::vector<CaseWins>> by;
  for (std::size_t r = 0; r < rows.size(); r += ms.size()) {
    const std::string& category = rows[r].c.category;
    if (category == "standard") continue;
    if (!by.contains(category)) order.push_back(category);
    by[category].push_back(wins_of(rows, r, ms));
  }
  if (order.empty()) return "";
  std::ostringstream s;
  s << "\nHard cases: focal default's relative H error against the lowest of every other method "
       "(file normals) and of the other positions-only methods (no normals); medians over the "
       "category's cases.\n\n| category | cases | lowest, file normals | lowest, no normals | "
       "median, file normals | median best other | median, no normals | median best "
       "positions-only |\n|---|---|---|---|---|---|---|---|\n";
  int cases = 0, file_wins = 0, none_wins = 0;
  for (const std::string& category : order) {
    const std::vector<CaseWins>& ws = by[category];
    std::vector<double> file, none, other, positions;
    int fw = 0, nw = 0;
    for (const CaseWins& w : ws) {
      file.push_back(w.file), none.push_back(w.none);
      other.push_back(w.best_other), positions.push_back(w.best_positions);
      fw += w.file_wins, nw += w.none_wins;
    }
    cases += static_cast<int>(ws.size()), file_wins += fw, none_wins += nw;
    s << "| " << category << " | " << ws.size() << " | " << fw << " | " << nw << " | "
      << number(median_of(file)) << " | " << number(median_of(other)) << " | "
      << number(median_of(none)) << " | " << number(median_of(positions)) << " |\n";
  }
  s << "| all | " << cases << " | " << file_wins << " | " << none_wins << " | | | | |\n";
  return s.str();
}

/// Markdown: one row per case, the relative RMS error of H per method, the best in bold.
std::string markdown_table(const std::vector<Row>& rows, const std::vector<Estimator>& ms,
                           const EvalFlags& f) {
  std::ostringstream s;
  s << "Relative RMS error of H (RMS error / RMS truth) at interior vertices (hard cases "
       "\"near boundaries\": at rings 1-2; creases not scored), about "
    << f.vertices << " vertices per mesh, seed " << f.seed
    << ". Best of each row in bold.\n\n| case |";
  for (const Estimator& m : ms) s << " " << m.name << " |";
  s << "\n|---|";
  for (std::size_t k = 0; k < ms.size(); ++k) s << "---|";
  s << "\n";
  int wins_file = 0, wins_max = 0, row_count = 0;
  for (std::size_t r = 0; r < rows.size(); r += ms.size()) {
    // Over all methods / the baselines / the baselines that do not read the file's normals.
    double best = INFINITY, best_other = INFINITY, best_positions = INFINITY;
    for (std::size_t k = 0; k < ms.size(); ++k) {
      const double v = rows[r + k].e.interior.relative_H;
      const std::string& name = rows[r + k].method;
      best = std::min(best, v);
      if (name.rfind("focal", 0) == 0) continue;
      best_other = std::min(best_other, v);
      if (!ms[k].reads_normals) best_positions = std::min(best_positions, v);
    }
    const Case& c = rows[r].c;
    s << "| " << (c.category == "standard" ? "" : c.category + ": ") << case_label(c) << " |";
    for (std::size_t k = 0; k < ms.size(); ++k) {
      const double v = rows[r + k].e.interior.relative_H;
      if (v == best) {
        s << " **" << number(v) << "** |";
      } else {
        s << " " << number(v) << " |";
      }
    }
    s << "\n";
    if (c.category != "standard") continue;
    ++row_count;
    // Rows 0 and 1 of each case are focal default with the file's normals and without normals.
    wins_file += rows[r].e.interior.relative_H < best_other;
    wins_max += rows[r + 1].e.interior.relative_H < best_positions;
  }
  if (row_count > 0) {
    s << "\nfocal default beats every baseline in " << wins_file << " of " << row_count
      << " cases with the file's normals and every positions-only baseline in " << wins_max
      << " of " << row_count << " without normals.\n";
  }
  s << category_summary(rows, ms);
  return s.str();
}

/// Creates an output folder; a failure is an IoError (exit 2), not an internal error.
void make_folder(const std::string& dir) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) throw IoError("cannot create folder '" + dir + "': " + error.message());
}

/// Writes DIR/cases.csv (slug, surface, triangulation, noise, vertices) and per case
/// DIR/<slug>.ply and DIR/<slug>.truth.csv (see focal::export_case).
void export_cases(const std::string& dir,
                  const std::vector<std::pair<Case, AnalyticSurface>>& all) {
  make_folder(dir);
  std::vector<std::string> slug, surface, triangulation, noise, category;
  Eigen::VectorXd vertices(static_cast<Eigen::Index>(all.size()));
  for (std::size_t k = 0; k < all.size(); ++k) {
    const auto& [c, s] = all[k];
    export_case(std::filesystem::path(dir) / (c.slug + ".ply"),
                std::filesystem::path(dir) / (c.slug + ".truth.csv"), s, scored_vertices(c, s));
    slug.push_back(c.slug);
    surface.push_back(c.surface);
    triangulation.push_back(c.mesh);
    noise.push_back(c.noise);
    category.push_back(c.category);
    vertices[static_cast<Eigen::Index>(k)] = static_cast<double>(s.mesh.V.rows());
  }
  const std::vector<CsvColumn> columns = {
      {"slug", slug},   {"surface", surface},   {"triangulation", triangulation},
      {"noise", noise}, {"vertices", vertices}, {"category", category}};
  write_csv(std::filesystem::path(dir) / "cases.csv", columns);
}

void run_eval(const EvalFlags& f, const Log& log) {
  const std::vector<Estimator> ms = methods();
  std::vector<Row> rows;
  std::vector<std::pair<Case, AnalyticSurface>> exported;
  for (const Case& c : cases(f.suite)) {
    Stage stage(log, case_label(c));
    AnalyticSurface s = make_case(c, f);
    for (const Estimator& m : ms) rows.push_back({c, m.name, evaluate_case(c, s, m.run(s.mesh))});
    if (!f.export_dir.empty()) exported.emplace_back(c, std::move(s));
  }
  if (!f.export_dir.empty()) {
    Stage stage(log, "export");
    export_cases(f.export_dir, exported);
  }
  const std::string table = markdown_table(rows, ms, f);
  if (!f.csv.empty()) write_csv_table(f.csv, rows);
  if (!f.markdown.empty()) write_text_file(f.markdown, table);
  std::fputs(table.c_str(), stdout);
}

/// The estimators of the scan table: focal default (with the file's normals when it has them) and
/// the paper's 1-ring fit with Max normals, and the positions-only baselines.
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

struct ScanRow {
  std::string scan;
  std::string method;
  FieldSmoothness s;
};

/// The mesh with H as a property and as red (positive) / blue (negative) vertex colours, white at
/// zero, saturated at |H h| = saturation, grey where undefined; MeshLab shows the colours as read.
void write_coloured_h(const std::filesystem::path& path, const Mesh& mesh, const Eigen::VectorXd& H,
                      double h, double saturation) {
  const Eigen::Index n = H.size();
  Eigen::VectorXd red(n), green(n), blue(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!std::isfinite(H[i])) {
      red[i] = green[i] = blue[i] = 128;
      continue;
    }
    const double t = std::clamp(H[i] * h / saturation, -1.0, 1.0);
    const double fade = std::round(255.0 * (1.0 - std::abs(t)));
    red[i] = t >= 0 ? 255 : fade;
    blue[i] = t <= 0 ? 255 : fade;
    green[i] = fade;
  }
  Mesh plain{mesh.V, mesh.F, RowMatrixX3d(0, 3), {}, {}};
  const std::vector<VertexProperty> properties = {{"red", red, PropertyType::uint8},
                                                  {"green", green, PropertyType::uint8},
                                                  {"blue", blue, PropertyType::uint8},
                                                  {"H", H, PropertyType::float32}};
  write_ply(path, plain, properties,
            {.binary = true,
             .comments = {"focal eval --scan: mean curvature H; colour saturates at |H h| = " +
                          number(saturation) + ", h = mean edge length " + number(h)}});
}

/// Every scan method on one scanned mesh; with an export folder also its coloured H fields.
std::vector<ScanRow> measure_scan(const std::string& path, const EvalFlags& f, const Log& log) {
  Mesh mesh;
  {
    Stage stage(log, "read " + path);
    mesh = read_mesh(path);
  }
  const std::string name = std::filesystem::path(path).stem().string();
  std::vector<ScanRow> rows;
  std::vector<Eigen::VectorXd> fields;
  for (const Estimator& m : scan_methods(mesh.has_normals())) {
    Stage stage(log, name + ": " + m.name);
    fields.push_back(m.run(mesh).H);
    rows.push_back({name, m.name, field_smoothness(mesh.V, mesh.F, fields.back())});
  }
  if (f.export_dir.empty()) return rows;
  // One colour scale for all methods of a scan (the median robust range), so that they compare.
  std::vector<double> ranges;
  for (const ScanRow& r : rows)
    ranges.push_back(std::max(std::abs(r.s.percentile_1), std::abs(r.s.percentile_99)));
  std::nth_element(ranges.begin(), ranges.begin() + ranges.size() / 2, ranges.end());
  const double saturation = ranges[ranges.size() / 2] > 0 ? ranges[ranges.size() / 2] : 1.0;
  make_folder(f.export_dir);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    write_coloured_h(
        std::filesystem::path(f.export_dir) / (name + "." + slug_of(rows[k].method) + ".ply"), mesh,
        fields[k], rows[k].s.edge_length, saturation);
  }
  return rows;
}

void write_scan_csv(const std::string& path, const std::vector<ScanRow>& rows) {
  std::vector<std::string> scan, method;
  const std::size_t n = rows.size();
  Eigen::VectorXd values[11];
  for (auto& v : values) v.resize(static_cast<Eigen::Index>(n));
  for (std::size_t k = 0; k < n; ++k) {
    const FieldSmoothness& s = rows[k].s;
    scan.push_back(rows[k].scan);
    method.push_back(rows[k].method);
    const double row[11] = {double(s.vertices),
                            double(s.undefined),
                            s.edge_length,
                            s.min,
                            s.max,
                            s.percentile_1,
                            s.percentile_99,
                            s.variance,
                            double(s.edges),
                            double(s.sign_changes),
                            s.sign_change_fraction};
    for (int c = 0; c < 11; ++c) values[c][static_cast<Eigen::Index>(k)] = row[c];
  }
  const char* names[11] = {"vertices",
                           "undefined",
                           "edge_length",
                           "min_Hh",
                           "max_Hh",
                           "p1_Hh",
                           "p99_Hh",
                           "variance_Hh",
                           "edges",
                           "sign_changes",
                           "sign_change_fraction"};
  std::vector<CsvColumn> columns = {{"scan", scan}, {"method", method}};
  for (int c = 0; c < 11; ++c) columns.push_back({names[c], values[c]});
  write_csv(path, columns);
}

std::string scan_markdown(const std::vector<ScanRow>& rows) {
  std::ostringstream s;
  s << "Mean curvature on scanned meshes, scale-free as H h (h = the mesh's mean edge length). "
       "Sign changes: fraction of edges across which H changes sign (|H h| <= 1e-9 counts as "
       "zero).\n\n"
       "| scan | method | undefined | min | 1st pct | 99th pct | max | variance | sign changes |\n"
       "|---|---|---|---|---|---|---|---|---|\n";
  for (const ScanRow& r : rows) {
    s << "| " << r.scan << " | " << r.method << " | " << r.s.undefined << " | " << number(r.s.min)
      << " | " << number(r.s.percentile_1) << " | " << number(r.s.percentile_99) << " | "
      << number(r.s.max) << " | " << number(r.s.variance) << " | "
      << number(r.s.sign_change_fraction) << " |\n";
  }
  return s.str();
}

void run_scans(const EvalFlags& f, const Log& log) {
  std::vector<ScanRow> rows;
  for (const std::string& path : f.scans) {
    std::vector<ScanRow> one = measure_scan(path, f, log);
    rows.insert(rows.end(), one.begin(), one.end());
  }
  const std::string table = scan_markdown(rows);
  if (!f.csv.empty()) write_scan_csv(f.csv, rows);
  if (!f.markdown.empty()) write_text_file(f.markdown, table);
  std::fputs(table.c_str(), stdout);
}

}  // namespace

void add_eval_command(CLI::App& app, const Log& log) {
  auto* cmd =
      app.add_subcommand("eval", "Accuracy of every estimator on the analytic test surfaces");
  auto f = std::make_shared<EvalFlags>();
  cmd->add_option("--vertices", f->vertices, "approximate vertices per mesh")
      ->check(CLI::Range(100, 1000000))
      ->default_str("4000");
  cmd->add_option("--seed", f->seed, "random seed of the irregular meshes and the noise")
      ->default_str("1");
  cmd->add_option("--suite", f->suite,
                  "standard: the paper's surfaces and noise (48 cases); hard: meshes as real "
                  "files have them (anisotropic, graded, coarse, strong noise, outliers, near "
                  "boundaries, creases); all: both")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, Suite>{
              {"standard", Suite::standard}, {"hard", Suite::hard}, {"all", Suite::all}},
          CLI::ignore_case))
      ->default_str("all");
  cmd->add_option("--csv", f->csv, "write every metric per case and method as CSV");
  cmd->add_option("--markdown", f->markdown, "write the summary table as Markdown");
  cmd->add_option("--export", f->export_dir,
                  "write every case to DIR for external tools: cases.csv, <case>.ply (the mesh "
                  "with its file normals), <case>.truth.csv (truth and interior flag); with "
                  "--scan: <scan>.<method>.ply, H as vertex colours");
  auto* scan = cmd->add_option("--scan", f->scans,
                               "scanned meshes: smoothness of H (range, variance, sign changes "
                               "across edges) per method instead of the analytic suite");
  auto* points = cmd->add_flag("--points", f->points,
                               "point clouds: the cloud estimator on samples of every surface "
                               "(exact/no normals, noise, graded density, outliers; POINTS.md)");
  points->excludes(scan);
  cmd->get_option("--export")->excludes(points);
  cmd->get_option("--vertices")->excludes(scan);
  cmd->get_option("--seed")->excludes(scan);
  cmd->get_option("--suite")->excludes(scan);
  cmd->footer(
      "Examples:\n  focal eval --csv eval.csv --markdown eval.md\n"
      "  focal eval --export cases/                      # meshes and truth for other tools\n"
      "  focal eval --scan bunny.off lion.off --csv scans.csv --export coloured/");
  cmd->parse_complete_callback([f] {
    if (!f->csv.empty()) require_extension("--csv", f->csv, {".csv"});
    if (!f->markdown.empty()) require_extension("--markdown", f->markdown, {".md"});
  });
  cmd->callback([f, &log] {
    if (f->points) {
      run_eval_points(f->vertices, f->seed, f->csv, f->markdown, log);
    } else if (f->scans.empty()) {
      run_eval(*f, log);
    } else {
      run_scans(*f, log);
    }
  });
}

}  // namespace focal::cli
