#include "focal/mesh.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "focal/error.h"

namespace focal {

void validate_mesh_arrays(PositionsRef V, FacesRef F, NormalsRef N, const char* what) {
  const auto n = V.rows();
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const auto idx = F(f, c);
      if (idx < 0 || idx >= n) {
        throw InvalidInput(std::string(what) + ": face " + std::to_string(f) +
                           " refers to vertex " + std::to_string(idx) + ", but there are " +
                           std::to_string(n) + " vertices");
      }
    }
  }
  if (N.rows() != 0 && N.rows() != n) {
    throw InvalidInput(std::string(what) + ": " + std::to_string(N.rows()) + " normals for " +
                       std::to_string(n) + " vertices");
  }
}

double mean_edge_length(PositionsRef V, FacesRef F) {
  // Edges with a NaN or infinite end are left out: one bad coordinate would otherwise make the
  // tolerances derived from this length NaN for the whole mesh, not just near the bad vertex.
  double sum = 0.0;
  std::int64_t count = 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const double length = (V.row(F(f, c)) - V.row(F(f, (c + 1) % 3))).norm();
      if (std::isfinite(length)) {
        sum += length;
        ++count;
      }
    }
  }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

double bounding_box_diagonal(PositionsRef V) {
  // Rows with a NaN or infinite coordinate are left out (Eigen's min/max are unspecified for
  // NaN), so that clamping distances stay finite when a few vertices are broken.
  Eigen::RowVector3d lo = Eigen::RowVector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::RowVector3d hi = -lo;
  bool any = false;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    if (!V.row(i).allFinite()) continue;
    lo = lo.cwiseMin(V.row(i));
    hi = hi.cwiseMax(V.row(i));
    any = true;
  }
  return any ? (hi - lo).norm() : 0.0;
}

}  // namespace focal
