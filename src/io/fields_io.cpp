#include "focal/io/fields_io.h"

#include <array>
#include <string>
#include <vector>

#include "focal/core/error.h"
#include "io/atomic_file.h"
#include "io/ply.h"
#include "io/text_scan.h"

namespace focal {
namespace {

std::string class_codes_comment() {
  std::string s = "class codes:";
  for (int c = 0; c <= static_cast<int>(PointClass::undefined); ++c) {
    s.append(" ")
        .append(std::to_string(c))
        .append("=")
        .append(class_name(static_cast<PointClass>(c)));
  }
  return s;
}

/// The numeric fields in file order (all but class).
std::vector<std::pair<std::string, Eigen::VectorXd>> numeric_fields(const CurvatureResult& r) {
  const auto& names = curvature_field_names();
  std::vector<std::pair<std::string, Eigen::VectorXd>> out;
  out.emplace_back(names[0], r.k1);
  out.emplace_back(names[1], r.k2);
  out.emplace_back(names[2], r.H);
  out.emplace_back(names[3], r.K);
  for (int c = 0; c < 3; ++c) out.emplace_back(names[4 + c], r.d1.col(c));
  for (int c = 0; c < 3; ++c) out.emplace_back(names[7 + c], r.d2.col(c));
  out.emplace_back(names[10], r.residual);
  return out;
}

/// Empty, or one flag per vertex of the fields.
void check_crease(const VectorXu8& crease, const CurvatureResult& fields, const char* what) {
  if (crease.size() != 0 && crease.size() != fields.k1.size()) {
    throw InvalidInput(std::string(what) + ": " + std::to_string(crease.size()) +
                       " crease flags for " + std::to_string(fields.k1.size()) + " vertices");
  }
}

}  // namespace

const std::vector<std::string>& curvature_field_names() {
  static const std::vector<std::string> names = {"k1",  "k2",  "H",   "K",   "d1x",      "d1y",
                                                 "d1z", "d2x", "d2y", "d2z", "residual", "class"};
  return names;
}

void write_curvature_csv(const std::filesystem::path& path, const CurvatureResult& fields,
                         const VectorXu8& crease) {
  write_curvature_csv(path, fields, crease, WriteOptions{});
}

void write_curvature_csv(const std::filesystem::path& path, const CurvatureResult& fields,
                         const VectorXu8& crease, const WriteOptions& options) {
  check_crease(crease, fields, "write_curvature_csv");
  std::vector<CsvColumn> columns;
  for (auto& [name, values] : numeric_fields(fields)) columns.push_back({name, std::move(values)});
  std::vector<std::string> words(static_cast<std::size_t>(fields.point_class.size()));
  for (std::size_t i = 0; i < words.size(); ++i) {
    words[i] = std::string(class_name(fields.class_of(static_cast<int>(i))));
  }
  columns.push_back({"class", std::move(words)});
  if (crease.size() > 0) columns.push_back({"crease", Eigen::VectorXd(crease.cast<double>())});
  write_csv(path, columns, options);
}

void write_curvature_ply(const std::filesystem::path& path, const Mesh& mesh,
                         const CurvatureResult& fields, const PlyWriteOptions& options,
                         const VectorXu8& crease) {
  check_crease(crease, fields, "write_curvature_ply");
  // Columns read in place: copying the eleven fields into VertexProperty vectors would cost
  // more than formatting them.
  const auto& names = curvature_field_names();
  const auto column = [&](std::size_t name, const double* values, Eigen::Index size,
                          Eigen::Index stride) {
    return io_detail::PlyColumn{names[name], PropertyType::float32, values, nullptr, size, stride};
  };
  // Column c of an n x 3 row-major matrix (no offset on the null data of an empty one).
  const auto column_of = [](const RowMatrixX3d& m, int c) {
    return m.size() > 0 ? m.data() + c : nullptr;
  };
  std::vector<io_detail::PlyColumn> columns = {column(0, fields.k1.data(), fields.k1.size(), 1),
                                               column(1, fields.k2.data(), fields.k2.size(), 1),
                                               column(2, fields.H.data(), fields.H.size(), 1),
                                               column(3, fields.K.data(), fields.K.size(), 1)};
  for (int c = 0; c < 3; ++c) {
    columns.push_back(column(4 + c, column_of(fields.d1, c), fields.d1.rows(), 3));
  }
  for (int c = 0; c < 3; ++c) {
    columns.push_back(column(7 + c, column_of(fields.d2, c), fields.d2.rows(), 3));
  }
  columns.push_back(column(10, fields.residual.data(), fields.residual.size(), 1));
  columns.push_back({names[11], PropertyType::uint8, nullptr, fields.point_class.data(),
                     fields.point_class.size(), 1});
  if (crease.size() > 0) {
    columns.push_back({"crease", PropertyType::uint8, nullptr, crease.data(), crease.size(), 1});
  }
  PlyWriteOptions o = options;
  o.comments.push_back("focal curvature fields; " + class_codes_comment());
  io_detail::write_ply_columns(path, mesh, columns, o);
}

void write_focal_mesh_ply(const std::filesystem::path& path, const FocalMesh& focal,
                          const PlyWriteOptions& options) {
  const std::array<VertexProperty, 1> flag = {
      VertexProperty{"focal_flag", focal.flag.cast<double>(), PropertyType::uint8}};
  PlyWriteOptions o = options;
  o.comments.push_back("focal mesh; focal_flag codes: 0=finite 1=infinite(clamped) 2=undefined");
  write_ply(path, focal.mesh, flag, o);
}

void write_focal_meshes_ply(const std::filesystem::path& path1, const std::filesystem::path& path2,
                            const FocalMeshes& meshes, const PlyWriteOptions& options) {
  io_detail::AtomicFileGroup group;
  write_focal_mesh_ply(path1, meshes.gamma1, options);
  write_focal_mesh_ply(path2, meshes.gamma2, options);
  group.commit();
}

}  // namespace focal
