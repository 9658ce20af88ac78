// The tables of `focal eval` (eval_tables.h).
#include "eval_tables.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "focal/io/mesh_io.h"

namespace focal::cli::eval {
namespace {

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

}  // namespace

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

}  // namespace focal::cli::eval
