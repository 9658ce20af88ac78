// `focal eval --points`: the cloud estimator on point samples of every analytic surface
// (focal/evaluation/cloud_evaluation.h), a Markdown table on stdout, --csv / --markdown files.

#include "eval_points.h"

#include <cstdio>
#include <string>
#include <vector>

#include "focal/evaluation/cloud_evaluation.h"
#include "focal/io/mesh_io.h"

namespace focal::cli {

void run_eval_points(int points, std::uint64_t seed, const std::string& csv,
                     const std::string& markdown, const Log& log) {
  std::vector<CloudCaseResult> rows;
  {
    Stage stage(log, "clouds");
    for (const CloudCase& c : cloud_cases(points, seed)) rows.push_back(evaluate_cloud_case(c));
  }
  std::string table =
      "| case | points | k | noise | rel. RMS H | rel. RMS K | undefined |\n"
      "|---|---|---|---|---|---|---|\n";
  char line[256];
  for (const CloudCaseResult& r : rows) {
    std::snprintf(line, sizeof line, "| %s | %d | %d | %.4f | %.4f | %.4f | %d |\n", r.name.c_str(),
                  r.points, r.k, r.noise, r.h_relative_rms, r.k_relative_rms, r.undefined);
    table += line;
  }
  std::fputs(table.c_str(), stdout);
  if (!markdown.empty()) write_text_file(markdown, table);
  if (csv.empty()) return;
  std::vector<std::string> names;
  Eigen::VectorXd n(rows.size()), k(rows.size()), noise(rows.size()), h(rows.size()),
      kk(rows.size()), undefined(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto e = static_cast<Eigen::Index>(i);
    names.push_back(rows[i].name);
    n[e] = rows[i].points, k[e] = rows[i].k, noise[e] = rows[i].noise;
    h[e] = rows[i].h_relative_rms, kk[e] = rows[i].k_relative_rms, undefined[e] = rows[i].undefined;
  }
  const std::vector<CsvColumn> columns = {
      {"case", names},   {"points", n},           {"k", k}, {"noise", noise}, {"rel_rms_H", h},
      {"rel_rms_K", kk}, {"undefined", undefined}};
  write_csv(csv, columns);
}

}  // namespace focal::cli
