#include "focal/core/mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "focal/core/edge_lengths.h"
#include "focal/core/error.h"

namespace focal {

void validate_mesh_arrays(PositionsRef V, FacesRef F, NormalsRef N, const char* what) {
  const auto n = V.rows();
  // Checked in parallel blocks; only a mesh with a bad index is scanned again, in order, for the
  // first one.
  constexpr std::int64_t kBlock = 1 << 15;
  const std::int64_t faces = F.rows();
  std::vector<unsigned char> bad(static_cast<std::size_t>((faces + kBlock - 1) / kBlock), 0);
  detail::parallel_for_blocks(faces, kBlock, 0, [&](std::int64_t begin, std::int64_t end) {
    // One unsigned comparison per index (a negative one wraps above n), without branches, so
    // that the loop over the faces has no branch per index.
    const auto count = static_cast<std::uint64_t>(n);
    bool ok = true;
    for (std::int64_t f = begin; f < end; ++f) {
      for (int c = 0; c < 3; ++c) ok &= static_cast<std::uint64_t>(F(f, c)) < count;
    }
    if (!ok) bad[static_cast<std::size_t>(begin / kBlock)] = 1;
  });
  const bool any_bad = std::find(bad.begin(), bad.end(), 1) != bad.end();
  for (Eigen::Index f = 0; any_bad && f < F.rows(); ++f) {
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

EdgeLengthSums edge_length_sums(PositionsRef V, FacesRef F) {
  // Edges with a NaN or infinite end are left out: one bad coordinate would otherwise make the
  // tolerances derived from this length NaN for the whole mesh, not just near the bad vertex.
  const std::int64_t faces = F.rows();
  const std::int64_t blocks = (faces + kEdgeLengthBlock - 1) / kEdgeLengthBlock;
  EdgeLengthSums out{std::vector<double>(static_cast<std::size_t>(blocks), 0.0),
                     std::vector<std::int64_t>(static_cast<std::size_t>(blocks), 0)};
  detail::parallel_for_blocks(
      faces, kEdgeLengthBlock, 0, [&](std::int64_t begin, std::int64_t end) {
        double sum = 0.0;
        std::int64_t count = 0;
        for (std::int64_t f = begin; f < end; ++f) {
          for (int c = 0; c < 3; ++c) {
            const double length = (V.row(F(f, c)) - V.row(F(f, (c + 1) % 3))).norm();
            if (std::isfinite(length)) {
              sum += length;
              ++count;
            }
          }
        }
        out.sums[static_cast<std::size_t>(begin / kEdgeLengthBlock)] = sum;
        out.counts[static_cast<std::size_t>(begin / kEdgeLengthBlock)] = count;
      });
  return out;
}

double mean_edge_length(PositionsRef V, FacesRef F) {
  // The blocks' sums added in block order: blocks do not depend on the thread count, so
  // neither does the result (and a mesh of one block sums as before).
  const EdgeLengthSums blocks = edge_length_sums(V, F);
  double sum = 0.0;
  std::int64_t count = 0;
  for (std::size_t b = 0; b < blocks.sums.size(); ++b) {
    sum += blocks.sums[b];
    count += blocks.counts[b];
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
