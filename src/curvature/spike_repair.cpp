#include "curvature/spike_repair.h"

#include <algorithm>
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

Eigen::VectorXd normal_offsets(PositionsRef V, const RowMatrixX3d& N, const Neighbourhoods& ring,
                               int threads, bool own_normal) {
  Eigen::VectorXd out(V.rows());
  parallel_for(V.rows(), threads, [&](std::int64_t i) {
    const int v = static_cast<int>(i);
    const Eigen::Vector3d n = N.row(i).transpose(), p = V.row(i).transpose();
    out[i] = NAN;
    if (!n.allFinite()) return;
    std::vector<double> t;
    for (const int* j = ring.begin(v); j != ring.end(v); ++j) {
      const Eigen::Vector3d e = p - V.row(*j).transpose();
      const Eigen::Vector3d m = N.row(*j).transpose();
      if (!m.allFinite()) continue;
      if (!own_normal) {
        t.push_back(e.dot(m));
        continue;
      }
      const double d = 1.0 + n.dot(m);
      if (d > 0.5) t.push_back(e.dot(n + m) / d);  // normals within 120 degrees
    }
    const double length = tangent_edge_length(V, ring, v, n);
    // A median of a minority says nothing: a wild own normal leaves most neighbours out.
    const auto size = static_cast<std::size_t>(ring.end(v) - ring.begin(v));
    if (t.empty() || 2 * t.size() < size || !(length > 0.0)) return;
    const auto mid = t.begin() + static_cast<std::ptrdiff_t>(t.size() / 2);
    std::nth_element(t.begin(), mid, t.end());
    double median = *mid;
    if (t.size() % 2 == 0) median = 0.5 * (median + *std::max_element(t.begin(), mid));
    out[i] = median / length;
  });
  return out;
}

std::vector<int> find_spikes(const Eigen::VectorXd& offset, const Eigen::VectorXd& off_planes,
                             const Neighbourhoods& ring) {
  std::vector<int> out;
  for (int i = 0; i < offset.size(); ++i) {
    if (!(std::abs(offset[i]) > kSpikeOffset) || !(std::abs(off_planes[i]) > kSpikeOffset)) continue;
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
