#include "focal/mesh.h"

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
  if (F.rows() == 0) return 0.0;
  double sum = 0.0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      sum += (V.row(F(f, c)) - V.row(F(f, (c + 1) % 3))).norm();
    }
  }
  return sum / (3.0 * static_cast<double>(F.rows()));
}

double bounding_box_diagonal(PositionsRef V) {
  if (V.rows() == 0) return 0.0;
  return (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
}

}  // namespace focal
