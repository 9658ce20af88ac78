#include "curvature/spike_repair.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/parallel.h"

namespace focal::detail {
namespace {

/// The mean length of the edges at vertex i projected onto the plane of its unit normal n: the
/// sampling's scale, which a spike along n does not stretch.
double tangent_edge_length(PositionsRef V, const Neighbourhoods& ring, int i,
                           const Eigen::Vector3d& n) {
  double sum = 0.0;
  int count = 0;
  for (const int* j = ring.begin(i); j != ring.end(i); ++j, ++count) {
    const Eigen::Vector3d e = (V.row(*j) - V.row(i)).transpose();
    sum += (e - n * n.dot(e)).norm();
  }
  return count > 0 ? sum / count : 0.0;
}

}  // namespace

namespace {

/// normal_offsets at vertex v.
double offset_at(PositionsRef V, const RowMatrixX3d& N, const Neighbourhoods& ring, int v,
                 bool own_normal) {
  const Eigen::Vector3d n = N.row(v).transpose(), p = V.row(v).transpose();
  if (!n.allFinite()) return NAN;
  const auto size = static_cast<std::size_t>(ring.end(v) - ring.begin(v));
  // No allocation for the usual 1-ring: this runs at every vertex of a clean mesh with normals.
  std::array<double, 32> small;
  std::vector<double> large(size > small.size() ? size : 0);
  double* t = size > small.size() ? large.data() : small.data();
  std::size_t count = 0;
  double length = 0.0;
  for (const int* j = ring.begin(v); j != ring.end(v); ++j) {
    const Eigen::Vector3d e = p - V.row(*j).transpose();
    length += (e - n * n.dot(e)).norm();
    const Eigen::Vector3d m = N.row(*j).transpose();
    if (!m.allFinite()) continue;
    if (!own_normal) {
      t[count++] = e.dot(m);
      continue;
    }
    const double d = 1.0 + n.dot(m);
    if (d > 0.5) t[count++] = e.dot(n + m) / d;  // normals within 120 degrees
  }
  length /= static_cast<double>(size);
  // A median of a minority says nothing: a wild own normal leaves most neighbours out.
  if (count == 0 || 2 * count < size || !(length > 0.0)) return NAN;
  double* mid = t + count / 2;
  std::nth_element(t, mid, t + count);
  double median = *mid;
  if (count % 2 == 0) median = 0.5 * (median + *std::max_element(t, mid));
  return median / length;
}

}  // namespace

Eigen::VectorXd normal_offsets(PositionsRef V, const RowMatrixX3d& N, const Neighbourhoods& ring,
                               int threads, bool own_normal) {
  Eigen::VectorXd out(V.rows());
  parallel_for(V.rows(), threads, [&](std::int64_t i) {
    out[i] = offset_at(V, N, ring, static_cast<int>(i), own_normal);
  });
  return out;
}

std::vector<int> find_spikes(PositionsRef V, const RowMatrixX3d& N, const Neighbourhoods& ring,
                             const Eigen::VectorXd& offset) {
  std::vector<int> out;
  for (int i = 0; i < offset.size(); ++i) {
    if (!(std::abs(offset[i]) > kSpikeOffset)) continue;
    // The neighbours' planes alone, at the few candidates only.
    if (!(std::abs(offset_at(V, N, ring, i, false)) > kSpikeOffset)) continue;
    int beside = 0;  // neighbours off the surface too: one is a pair of spikes, two a line
    for (const int* j = ring.begin(i); j != ring.end(i); ++j) {
      beside += std::abs(offset[*j]) > 0.5 * kSpikeOffset;
    }
    if (beside <= 1) out.push_back(i);
  }
  return out;
}

RowMatrixX3d repaired_positions(PositionsRef V, const RowMatrixX3d& N, const Neighbourhoods& ring,
                                const Eigen::VectorXd& offset, const std::vector<int>& spikes) {
  RowMatrixX3d out = V;
  for (const int i : spikes) {
    const Eigen::Vector3d n = N.row(i).transpose();
    out.row(i) -= offset[i] * tangent_edge_length(V, ring, i, n) * N.row(i);
  }
  return out;
}

}  // namespace focal::detail
