// `focal eval`: every estimator over the analytic suite (paper Fig. 10's noise models), errors
// against the exact truth as CSV and a Markdown table.
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <sstream>

#include "commands.h"
#include "focal/baselines.h"
#include "focal/error.h"
#include "focal/evaluation.h"
#include "focal/mesh_io.h"
#include "focal/normals.h"
#include "paths.h"

namespace focal::cli {
namespace {

struct EvalFlags {
  int vertices = 4000;
  std::uint64_t seed = 1;
  std::string csv;
  std::string markdown;
};

/// One estimator: a name and how it runs on a mesh whose N holds the file's normals.
struct Estimator {
  std::string name;
  std::function<CurvatureResult(const Mesh&)> run;
};

enum class Noise { clean, positions, normals };

struct Case {
  SurfaceKind kind;
  Triangulation triangulation;
  Noise noise;
};

std::string noise_name(Noise n) {
  return n == Noise::clean       ? "clean"
         : n == Noise::positions ? "vertex noise 10%"
                                 : "normal noise 5%";
}

std::vector<Estimator> methods() {
  std::vector<Estimator> out;
  const auto focal_method = [&out](const std::string& name, CurvatureOptions o) {
    out.push_back({name + " / file normals",
                   [o](const Mesh& m) { return estimate_curvature(m.V, m.F, m.N, o); }});
    out.push_back({name + " / Max normals", [o](const Mesh& m) {
                     return estimate_curvature(m.V, m.F,
                                               vertex_normals(m.V, m.F, NormalWeighting::max), o);
                   }});
  };
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
  return out;
}

std::vector<Case> cases() {
  std::vector<Case> out;
  for (SurfaceKind k : all_surfaces()) {
    for (auto t : {Triangulation::regular, Triangulation::irregular}) {
      for (auto n : {Noise::clean, Noise::positions, Noise::normals}) out.push_back({k, t, n});
    }
  }
  return out;
}

AnalyticSurface make_case(const Case& c, const EvalFlags& f) {
  SurfaceOptions o;
  o.kind = c.kind;
  o.triangulation = c.triangulation;
  o.target_vertices = f.vertices;
  o.seed = f.seed;
  AnalyticSurface s = make_surface(o);
  if (c.noise == Noise::positions) add_position_noise(s.mesh, 0.1, f.seed + 1);
  if (c.noise == Noise::normals) add_normal_noise(s.mesh, 0.05, f.seed + 2);
  return s;
}

std::string case_label(const Case& c) {
  return std::string(surface_name(c.kind)) + ", " +
         (c.triangulation == Triangulation::regular ? "regular" : "irregular") + ", " +
         noise_name(c.noise);
}

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
  std::vector<std::string> cols[19];
  const char* names[19] = {"surface",       "triangulation", "noise",
                           "method",        "vertices",      "undefined",
                           "rel_H",         "rel_K",         "rel_k1",
                           "rel_k2",        "rms_H",         "rms_K",
                           "rms_k1",        "rms_k2",        "median_angle_d1",
                           "mean_angle_d1", "variance_H",    "boundary_vertices",
                           "boundary_rel_H"};
  for (const Row& r : rows) {
    const ErrorMetrics& m = r.e.interior;
    const std::string values[19] = {
        std::string(surface_name(r.c.kind)),
        r.c.triangulation == Triangulation::regular ? "regular" : "irregular",
        noise_name(r.c.noise),
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
        number(r.e.near_boundary.relative_H)};
    for (int k = 0; k < 19; ++k) cols[k].push_back(values[k]);
  }
  std::vector<CsvColumn> columns;
  for (int k = 0; k < 19; ++k) columns.push_back({names[k], cols[k]});
  write_csv(path, columns);
}

/// Markdown: one row per case, the relative RMS error of H per method, the best in bold.
std::string markdown_table(const std::vector<Row>& rows, const std::vector<Estimator>& ms,
                           const EvalFlags& f) {
  std::ostringstream s;
  s << "Relative RMS error of H (RMS error / RMS truth) at interior vertices, about " << f.vertices
    << " vertices per mesh, seed " << f.seed << ". Best of each row in bold.\n\n| case |";
  for (const Estimator& m : ms) s << " " << m.name << " |";
  s << "\n|---|";
  for (std::size_t k = 0; k < ms.size(); ++k) s << "---|";
  s << "\n";
  int wins_file = 0, wins_max = 0, row_count = 0;
  for (std::size_t r = 0; r < rows.size(); r += ms.size()) {
    double best = INFINITY, best_other = INFINITY;  // over all methods / over the non-focal ones
    for (std::size_t k = 0; k < ms.size(); ++k) {
      const double v = rows[r + k].e.interior.relative_H;
      best = std::min(best, v);
      if (rows[r + k].method.rfind("focal", 0) != 0) best_other = std::min(best_other, v);
    }
    s << "| " << case_label(rows[r].c) << " |";
    for (std::size_t k = 0; k < ms.size(); ++k) {
      const double v = rows[r + k].e.interior.relative_H;
      if (v == best) {
        s << " **" << number(v) << "** |";
      } else {
        s << " " << number(v) << " |";
      }
    }
    s << "\n";
    ++row_count;
    // Rows 0 and 1 of each case are the default estimator with the file's and with Max normals.
    wins_file += rows[r].e.interior.relative_H < best_other;
    wins_max += rows[r + 1].e.interior.relative_H < best_other;
  }
  s << "\nThe default (closed-form, 1-ring) beats every non-focal method in " << wins_file << " of "
    << row_count << " cases with the file's normals and in " << wins_max << " of " << row_count
    << " with normals estimated by Max's weights.\n";
  return s.str();
}

void run_eval(const EvalFlags& f, const Log& log) {
  const std::vector<Estimator> ms = methods();
  std::vector<Row> rows;
  for (const Case& c : cases()) {
    Stage stage(log, case_label(c));
    const AnalyticSurface s = make_case(c, f);
    for (const Estimator& m : ms) rows.push_back({c, m.name, evaluate(s, m.run(s.mesh))});
  }
  const std::string table = markdown_table(rows, ms, f);
  if (!f.csv.empty()) write_csv_table(f.csv, rows);
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
  cmd->add_option("--csv", f->csv, "write every metric per case and method as CSV");
  cmd->add_option("--markdown", f->markdown, "write the summary table as Markdown");
  cmd->footer("Example:\n  focal eval --csv eval.csv --markdown eval.md");
  cmd->parse_complete_callback([f] {
    if (!f->csv.empty()) require_extension("--csv", f->csv, {".csv"});
    if (!f->markdown.empty()) require_extension("--markdown", f->markdown, {".md"});
  });
  cmd->callback([f, &log] { run_eval(*f, log); });
}

}  // namespace focal::cli
