#pragma once
/// \file edge_lengths.h
/// mean_edge_length (mesh.h) in parts, for a reader that streams the faces.

#include <cstdint>
#include <vector>

#include "focal/core/mesh.h"

namespace focal {

/// The faces of one block of mean_edge_length's sum: blocks do not depend on the thread count.
inline constexpr std::int64_t kEdgeLengthBlock = std::int64_t{1} << 15;

/// mean_edge_length's partial sums: per block of kEdgeLengthBlock faces, in face order, the sum
/// of its finite edge lengths and their count. mean_edge_length adds them in block order, so a
/// reader that streams the faces in whole blocks (python/focal/stream.py) gets its bits.
struct EdgeLengthSums {
  std::vector<double> sums;
  std::vector<std::int64_t> counts;
};
[[nodiscard]] EdgeLengthSums edge_length_sums(PositionsRef V, FacesRef F);

}  // namespace focal
