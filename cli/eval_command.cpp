// `focal eval`: every estimator over the analytic suite (paper Fig. 10's noise models), errors
// against the exact truth as CSV and a Markdown table; `--export` writes the cases for external
// tools; `--scan` measures the smoothness of H on scanned meshes without truth (paper Fig. 7).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <sstream>

#include "commands.h"
#include "eval_points.h"
#include "focal/core/error.h"
#include "focal/curvature/baselines.h"
#include "focal/curvature/recommended.h"
#include "focal/evaluation/evaluation.h"
#include "focal/io/mesh_io.h"
#include "focal/mesh/normals.h"
#include "paths.h"

namespace focal::cli {
namespace {

struct EvalFlags {
  int vertices = 4000;
  std::uint64_t seed = 1;
  std::string csv;
  std::string markdown;
  std::string export_dir;          ///< analytic mode: the cases; scan mode: coloured H fields
  std::vector<std::string> scans;  ///< scan mode when non-empty
  bool points = false;             ///< --points: the cloud estimator on analytic clouds
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
  // "focal default" first: the markdown summary counts its wins from rows 0 and 1 of each case.
  out.push_back({"focal default / file normals", [](const Mesh& m) {
                   return estimate_curvature_recommended(m.V, m.F, m.normals()).curvature;
                 }});
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

/// File-name form of a case: sphere-irregular-vertex-noise.
std::string case_slug(const Case& c) {
  const std::string noise = c.noise == Noise::clean       ? "clean"
                            : c.noise == Noise::positions ? "vertex-noise"
                                                          : "normal-noise";
  return std::string(surface_name(c.kind)) + "-" +
         (c.triangulation == Triangulation::regular ? "regular" : "irregular") + "-" + noise;
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
    // Rows 0 and 1 of each case are focal default with the file's normals and without normals.
    wins_file += rows[r].e.interior.relative_H < best_other;
    wins_max += rows[r + 1].e.interior.relative_H < best_other;
  }
  s << "\nfocal default beats MDSB03 and CSM03 in " << wins_file << " of " << row_count
    << " cases with the file's normals and in " << wins_max << " of " << row_count
    << " without normals.\n";
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
  std::vector<std::string> slug, surface, triangulation, noise;
  Eigen::VectorXd vertices(static_cast<Eigen::Index>(all.size()));
  for (std::size_t k = 0; k < all.size(); ++k) {
    const auto& [c, s] = all[k];
    export_case(std::filesystem::path(dir) / (case_slug(c) + ".ply"),
                std::filesystem::path(dir) / (case_slug(c) + ".truth.csv"), s);
    slug.push_back(case_slug(c));
    surface.emplace_back(surface_name(c.kind));
    triangulation.emplace_back(c.triangulation == Triangulation::regular ? "regular" : "irregular");
    noise.push_back(noise_name(c.noise));
    vertices[static_cast<Eigen::Index>(k)] = static_cast<double>(s.mesh.V.rows());
  }
  const std::vector<CsvColumn> columns = {{"slug", slug},
                                          {"surface", surface},
                                          {"triangulation", triangulation},
                                          {"noise", noise},
                                          {"vertices", vertices}};
  write_csv(std::filesystem::path(dir) / "cases.csv", columns);
}

void run_eval(const EvalFlags& f, const Log& log) {
  const std::vector<Estimator> ms = methods();
  std::vector<Row> rows;
  std::vector<std::pair<Case, AnalyticSurface>> exported;
  for (const Case& c : cases()) {
    Stage stage(log, case_label(c));
    AnalyticSurface s = make_case(c, f);
    for (const Estimator& m : ms) rows.push_back({c, m.name, evaluate(s, m.run(s.mesh))});
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
/// the paper's 1-ring fit with Max normals, MDSB03, CSM03.
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
  return out;
}

struct ScanRow {
  std::string scan;
  std::string method;
  FieldSmoothness s;
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
