// `focal eval`: every estimator over the analytic suite (paper Fig. 10's noise models), errors
// against the exact truth as CSV and a Markdown table; `--export` writes the cases for external
// tools; `--scan` measures the smoothness of H on scanned meshes without truth (paper Fig. 7).
#include <cstdio>
#include <map>
#include <memory>

#include "commands.h"
#include "eval_cases.h"
#include "eval_estimators.h"
#include "eval_points.h"
#include "eval_scans.h"
#include "eval_tables.h"
#include "focal/io/mesh_io.h"
#include "paths.h"

namespace focal::cli {
namespace {

using namespace eval;

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
