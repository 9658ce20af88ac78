// The sides of a crease (smoothing/creases.h).
#include "smoothing/creases.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace focal::detail::smoothing {
namespace {

/// Lloyd rounds of the groups.
constexpr int kGroupRounds = 4;

}  // namespace

int crease_sides(const RowMatrixX3d& frames, int i, const std::vector<int>& ring, double cos_crease,
                 bool oriented, std::vector<int> (&side)[kMaxSides],
                 Eigen::Vector3d (&mean)[kMaxSides], std::vector<Eigen::Vector3d>& scratch) {
  const Eigen::Vector3d ni = frames.row(i).transpose();
  const auto normal = [&](int j) {
    const Eigen::Vector3d n = frames.row(j).transpose();
    return !oriented && n.dot(ni) < 0.0 ? Eigen::Vector3d(-n) : n;
  };
  const auto usable = [&](int j) { return j != i && frames.row(j).allFinite(); };
  // A crease at all: some normal of the ring beyond the crease angle from the one farthest from
  // n_i (on a smooth surface none is, and the ring costs one pass more).
  int far = -1;
  double lowest = 2.0;
  for (const int j : ring) {
    if (!usable(j)) continue;
    const double d = normal(j).dot(ni);
    if (d < lowest) lowest = d, far = j;
  }
  if (far < 0) return 0;
  const Eigen::Vector3d first = normal(far);
  bool spread = false;
  for (const int j : ring) spread = spread || (usable(j) && normal(j).dot(first) < cos_crease);
  if (!spread) return 0;
  // Seeds at the modes: each the normal with the most others within half the crease
  // angle, among those beyond the crease angle from every seed so far. Normals of the crease's
  // own points (between the sides, and few: a line of them) are never the densest.
  std::vector<Eigen::Vector3d>& n = scratch;
  n.clear();
  for (const int j : ring) {
    if (usable(j)) n.push_back(normal(j));
  }
  const double cos_mode = std::cos(0.5 * std::acos(cos_crease));
  std::vector<int> density(n.size(), 0);
  for (std::size_t a = 0; a < n.size(); ++a) {
    for (std::size_t b = a + 1; b < n.size(); ++b) {
      if (n[a].dot(n[b]) >= cos_mode) ++density[a], ++density[b];
    }
  }
  int seeds = 0;
  while (seeds < kMaxSides) {
    int best = -1;
    for (std::size_t a = 0; a < n.size(); ++a) {
      bool apart = true;
      for (int k = 0; k < seeds && apart; ++k) apart = n[a].dot(mean[k]) < cos_crease;
      if (apart && (best < 0 || density[a] > density[static_cast<std::size_t>(best)]))
        best = static_cast<int>(a);
    }
    if (best < 0 || density[static_cast<std::size_t>(best)] + 1 < kMinSidePoints) break;
    mean[seeds++] = n[static_cast<std::size_t>(best)];
  }
  if (seeds < 2) return 0;
  int count = seeds;
  for (int round = 0; round < kGroupRounds; ++round) {
    Eigen::Vector3d sum[kMaxSides];
    for (int k = 0; k < count; ++k) side[k].clear(), sum[k].setZero();
    for (const int j : ring) {
      if (!usable(j)) continue;
      const Eigen::Vector3d n = normal(j);
      int best = 0;
      for (int k = 1; k < count; ++k) {
        if (n.dot(mean[k]) > n.dot(mean[best])) best = k;
      }
      side[best].push_back(j);
      sum[best] += n;
    }
    // Groups too small for a fit, or whose means came within the crease angle, are merged away:
    // their members go to the nearest remaining group in the next round.
    int kept = 0;
    for (int k = 0; k < count; ++k) {
      if (side[k].size() < static_cast<std::size_t>(kMinSidePoints) || !(sum[k].norm() > 0.0))
        continue;
      const Eigen::Vector3d m = sum[k].normalized();
      bool close = false;
      for (int q = 0; q < kept; ++q) close = close || m.dot(mean[q]) >= cos_crease;
      if (close) continue;
      mean[kept] = m;
      side[kept].swap(side[k]);
      ++kept;
    }
    if (kept < 2) return 0;
    if (kept < count) {
      count = kept;
      round = -1;  // regroup from the remaining means
      continue;
    }
  }
  // Normals between the sides (the crease's own points, whose normal belongs to no side) are in
  // none: more than half the crease angle from their side's mean. A side left with too few
  // members for a fit is dropped (its points in no fit), the others kept.
  const double cos_half = std::cos(0.5 * std::acos(cos_crease));
  int kept = 0;
  for (int k = 0; k < count; ++k) {
    auto& members = side[k];
    members.erase(std::remove_if(members.begin(), members.end(),
                                 [&](int j) { return normal(j).dot(mean[k]) < cos_half; }),
                  members.end());
    if (members.size() < static_cast<std::size_t>(kMinSidePoints)) continue;
    std::sort(members.begin(), members.end());
    if (kept != k) side[kept].swap(members), mean[kept] = mean[k];
    ++kept;
  }
  return kept;
}

Eigen::Vector3d onto_planes(const Eigen::Vector3d& p, const LocalSurface* const* surfaces,
                            int count) {
  Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMaxSides, 3> A(count, 3);
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxSides, 1> b(count);
  for (int k = 0; k < count; ++k) {
    A.row(k) = surfaces[k]->normal.transpose();
    b[k] = surfaces[k]->normal.dot(surfaces[k]->point - p);
  }
  // The least-norm move onto all planes (minimum norm least squares when they do not meet).
  return p + A.completeOrthogonalDecomposition().solve(b);
}

}  // namespace focal::detail::smoothing
