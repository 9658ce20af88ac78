// `focal eval --scan` (eval_scans.h): H of each scan method, its range, variance and sign
// changes across edges, as CSV and Markdown, and optionally as vertex colours.
#include "eval_scans.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "eval_estimators.h"
#include "eval_tables.h"
#include "focal/io/mesh_io.h"

namespace focal::cli::eval {
namespace {

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

}  // namespace

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

}  // namespace focal::cli::eval
