#include "normals/winding_orientation.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/parallel.h"
#include "points/winding_number.h"

namespace focal::detail {
namespace {

/// A neighbour is near a point's tangent plane when its chord's normal part is at most this
/// share of the chord (60 deg from the normal): across a thin part the chord runs along it.
constexpr double kTangentChord = 0.5;
constexpr int kFewestTangent = 3;

/// A segment's edges lie in both tangent planes within this share of their length (15 deg):
/// where two sheets nearly touch, a diagonal chord from one to the other is tangent to both
/// within 30 deg and would join the one's turned patch to the other's right one.
constexpr double kSegmentChord = 0.25;

/// Signed normals of a segment's neighbours agree at least this much.
constexpr double kSegmentAgreement = 0.5;

/// With `across`, segments are joined across thin parts too: by edges whose chord runs along
/// both normals (|n . e| >= this share of |e|) where the signed normals are opposite, as they
/// are on the two sides of a plate: a side turned alone only raises the residual where both
/// sides are wrong (two sheets that touch, turned together by the tree).
constexpr double kAcrossChord = 0.7;

/// The segment of each point (the smallest row in it): the points joined by edges of `graph`
/// whose chord lies in both tangent planes within kSegmentChord of its length and whose signed
/// normals agree (s_i s_j n_i . n_j > kSegmentAgreement); with `across`, also by the edges
/// across thin parts (kAcrossChord).
std::vector<int> segments(PositionsRef V, const Neighbourhoods& graph,
                          const std::vector<int>* rename, const RowMatrixX3d& N,
                          const Eigen::VectorXd& s, bool across) {
  const auto name = [rename](int r) { return rename ? (*rename)[static_cast<std::size_t>(r)] : r; };
  const auto n = static_cast<int>(V.rows());
  std::vector<int> parent(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) parent[static_cast<std::size_t>(i)] = i;
  const auto find = [&](int i) {
    while (parent[static_cast<std::size_t>(i)] != i) {
      parent[static_cast<std::size_t>(i)] =
          parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
      i = parent[static_cast<std::size_t>(i)];
    }
    return i;
  };
  for (int row = 0; row < n; ++row) {
    const int i = name(row);
    if (!N.row(i).allFinite()) continue;
    for (const int* jr = graph.begin(row); jr != graph.end(row); ++jr) {
      const int j = name(*jr);
      if (j == i || !N.row(j).allFinite()) continue;
      const Eigen::RowVector3d e = V.row(j) - V.row(i);
      const double e2 = e.squaredNorm(), a = N.row(i).dot(e), c = N.row(j).dot(e);
      const double limit = kSegmentChord * kSegmentChord * e2;
      const double agreement = s[i] * s[j] * N.row(i).dot(N.row(j));
      const bool along = a * a <= limit && c * c <= limit && agreement > kSegmentAgreement;
      const double normal = kAcrossChord * kAcrossChord * e2;
      const bool through =
          across && a * a >= normal && c * c >= normal && agreement < -kSegmentAgreement;
      if (!along && !through) continue;
      const int ri = find(i), rj = find(j);
      if (ri != rj) parent[static_cast<std::size_t>(std::max(ri, rj))] = std::min(ri, rj);
    }
  }
  for (int i = 0; i < n; ++i) parent[static_cast<std::size_t>(i)] = find(i);
  return parent;
}

/// Serial, in index order: the same bits for any thread count.
double dot(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  double s = 0.0;
  for (Eigen::Index i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

/// Whether point i carries a dipole: a finite position and normal and a positive area.
bool has_dipole(PositionsRef V, const Eigen::VectorXd& area, NormalsRef N, Eigen::Index i) {
  return V.row(i).allFinite() && area[i] > 0.0 && N.row(i).allFinite();
}

/// a_i n_i per point (#V x 3), zero where there is no dipole.
RowMatrixX3d dipoles(PositionsRef V, const Eigen::VectorXd& area, NormalsRef N) {
  RowMatrixX3d A = RowMatrixX3d::Zero(V.rows(), 3);
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    if (has_dipole(V, area, N, i)) A.row(i) = area[i] * N.row(i).normalized();
  }
  return A;
}

/// The tree over V, each dipole smoothed by options.smoothing times the square root of its area.
WindingTree tree_of(PositionsRef V, const Eigen::VectorXd& area, NormalsRef N,
                    const WindingOrientationOptions& o) {
  Eigen::VectorXd smoothing = Eigen::VectorXd::Zero(V.rows());
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    if (has_dipole(V, area, N, i)) smoothing[i] = o.smoothing * std::sqrt(area[i]);
  }
  return WindingTree(V, smoothing, o.beta);
}

/// The jumps' lengths (#V): jump_offset times the square root of each point's area.
Eigen::VectorXd jump_lengths(const Eigen::VectorXd& area, const WindingOrientationOptions& o) {
  return o.jump_offset * area.cwiseMax(0.0).cwiseSqrt();
}

/// jump_lengths, each at most jump_gap times |n_i . e| over the point's neighbours in `graph`
/// (renamed as in `segments`) whose chord e runs along both normals (|n . e| >= kAcrossChord |e|
/// for n_i and n_j): the distance to another sheet across the point, where an offset that
/// reaches past that sheet also reads its jump, of the opposite sign where two sheets face
/// each other (a contact).
Eigen::VectorXd contact_lengths(PositionsRef V, const Neighbourhoods& graph,
                                const std::vector<int>* rename, const Eigen::VectorXd& area,
                                const RowMatrixX3d& N, const WindingOrientationOptions& o) {
  const auto name = [rename](int r) { return rename ? (*rename)[static_cast<std::size_t>(r)] : r; };
  Eigen::VectorXd length = jump_lengths(area, o);
  for (int row = 0; row < static_cast<int>(V.rows()); ++row) {
    const int i = name(row);
    if (!N.row(i).allFinite()) continue;
    const Eigen::RowVector3d n = N.row(i).normalized();
    for (const int* jr = graph.begin(row); jr != graph.end(row); ++jr) {
      const int j = name(*jr);
      if (!N.row(j).allFinite()) continue;
      const Eigen::RowVector3d e = V.row(j) - V.row(i);
      const double along = std::abs(n.dot(e)), limit = kAcrossChord * e.norm();
      if (along > 0.0 && along >= limit && std::abs(N.row(j).normalized().dot(e)) >= limit) {
        length[i] = std::min(length[i], o.jump_gap * along);
      }
    }
  }
  return length;
}

/// Rounds of per-point turns: each point takes the side that the field's jump across it says
/// (positive: its signed normal points out), all at once, until a round turns none. The jump
/// leaves the point's own dipole out, so a point alone in a consistent sheet follows the sheet,
/// and across a thin part or a contact the nearer sheet's jump outweighs the other's. After the
/// first round a jump is evaluated again only at the points turned and their neighbours in
/// `graph` (renamed as in `segments`): a sign turned at distance r changes the jump across a
/// point by about its dipole's gradient times the offset, which falls as 1 / r^3. Returns the
/// turns made.
int turn_by_jumps(const WindingTree& tree, const Neighbourhoods& graph,
                  const std::vector<int>* rename, const Eigen::VectorXd& length,
                  const RowMatrixX3d& A, const WindingOrientationOptions& options,
                  Eigen::VectorXd& s, int threads) {
  const auto name = [rename](int r) { return rename ? (*rename)[static_cast<std::size_t>(r)] : r; };
  const Eigen::Index n = A.rows();
  Eigen::VectorXd again;  // the lengths of the points evaluated again, zero elsewhere
  std::vector<char> turned(static_cast<std::size_t>(n), 0);
  Eigen::VectorXd J;
  int total = 0;
  for (int round = 0; round < options.jump_rounds; ++round) {
    if (round == 0) {
      J = tree.jump_along(A, length, A, s, threads);
    } else {
      again = Eigen::VectorXd::Zero(n);
      for (int row = 0; row < graph.vertex_count(); ++row) {
        const int i = name(row);
        bool near = turned[static_cast<std::size_t>(i)] != 0;
        for (const int* jr = graph.begin(row); !near && jr != graph.end(row); ++jr)
          near = turned[static_cast<std::size_t>(name(*jr))] != 0;
        if (near) again[i] = length[i];
      }
      const Eigen::VectorXd update = tree.jump_along(A, again, A, s, threads);
      for (Eigen::Index i = 0; i < n; ++i) {
        if (again[i] != 0.0) J[i] = update[i];
      }
    }
    int count = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      turned[static_cast<std::size_t>(i)] = 0;
      if (A.row(i).isZero() || s[i] * J[i] >= 0.0) continue;
      s[i] = -s[i];
      turned[static_cast<std::size_t>(i)] = 1;
      ++count;
    }
    total += count;
    if (count == 0) break;
  }
  return total;
}

}  // namespace

int side_by_jumps(PositionsRef V, const Eigen::VectorXd& area, NormalsRef N, RowMatrixX3d& L,
                  int threads, const WindingOrientationOptions& options) {
  const RowMatrixX3d A = dipoles(V, area, N);
  const Eigen::VectorXd J =
      tree_of(V, area, N, options)
          .jump_along(L, jump_lengths(area, options), A, Eigen::VectorXd(), threads);
  int turned = 0;
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    if (J[i] >= 0.0) continue;
    L.row(i) *= -1.0;
    ++turned;
  }
  return turned;
}

Eigen::VectorXd patch_areas(PositionsRef V, const Neighbourhoods& neighbours, NormalsRef N,
                            int threads) {
  Eigen::VectorXd area = Eigen::VectorXd::Zero(V.rows());
  parallel_for(V.rows(), threads, [&](std::int64_t i) {
    if (!V.row(i).allFinite() || !N.row(i).allFinite()) return;
    const Eigen::RowVector3d n = N.row(i).normalized();
    int m = 0, all = 0;
    double tangent2 = 0.0, last2 = 0.0;
    for (const int* j = neighbours.begin(static_cast<int>(i));
         j != neighbours.end(static_cast<int>(i)); ++j) {
      const Eigen::RowVector3d e = V.row(*j) - V.row(i);
      const double e2 = e.squaredNorm();
      if (!std::isfinite(e2)) continue;
      ++all;
      last2 = std::max(last2, e2);
      const double normal = n.dot(e);
      if (normal * normal <= kTangentChord * kTangentChord * e2) {
        ++m;
        tangent2 = std::max(tangent2, e2);
      }
    }
    if (m >= kFewestTangent) {
      area[i] = std::numbers::pi * tangent2 / m;
    } else if (all > 0) {
      area[i] = std::numbers::pi * last2 / all;
    }
  });
  return area;
}

WindingOrientationReport orient_by_winding(PositionsRef V, const Neighbourhoods& graph,
                                           const std::vector<int>* rename,
                                           const Eigen::VectorXd& area, RowMatrixX3d& N,
                                           int threads, const WindingOrientationOptions& options) {
  const Eigen::Index n = V.rows();
  WindingOrientationReport report;
  // a_j n_j per point (zero where there is no dipole), the smoothing lengths, the target 1/2 at
  // every finite point.
  const RowMatrixX3d A = dipoles(V, area, N);
  const WindingTree tree = tree_of(V, area, N, options);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
  for (Eigen::Index i = 0; i < n; ++i) b[i] = V.row(i).allFinite() ? 0.5 : 0.0;
  const auto K = [&](const Eigen::VectorXd& s) { return tree.winding(A, s, threads); };
  const auto Kt = [&](const Eigen::VectorXd& r) { return tree.transpose(A, r, threads); };
  const double lambda = options.damping;
  const double norm_b = std::sqrt(dot(b, b));
  // Rounds of damped CGLS for d = s - s0 on min |K d - c|^2 + lambda |d|^2, c = b - K s0, each
  // seeded from the signs of the last (s0 = 1: the tree's).
  Eigen::VectorXd s = Eigen::VectorXd::Ones(n);
  for (int round = 0; round < options.rounds; ++round) {
    Eigen::VectorXd r = b - K(s);
    if (round == 0) report.residual_before = std::sqrt(dot(r, r)) / norm_b;
    Eigen::VectorXd d = Eigen::VectorXd::Zero(n);
    Eigen::VectorXd g = Kt(r);
    Eigen::VectorXd p = g;
    double gamma = dot(g, g);
    // Only the signs of s + d are taken: once a step turns none of them against the step
    // before, the iteration stops (on a plate the first step turns a whole side and the next
    // four none; on thin parts with contacts they move at every step).
    std::vector<char> turns(static_cast<std::size_t>(n), 0);
    for (int it = 0; it < options.iterations && gamma > 0.0; ++it) {
      const Eigen::VectorXd q = K(p);
      const double alpha = gamma / (dot(q, q) + lambda * dot(p, p));
      d += alpha * p;
      bool moved = false;
      for (Eigen::Index i = 0; i < n; ++i) {
        const char t = (s[i] + d[i]) * s[i] < 0.0 ? 1 : 0;
        moved = moved || t != turns[static_cast<std::size_t>(i)];
        turns[static_cast<std::size_t>(i)] = t;
      }
      // The last step's gradient would only set a next direction: its product is not taken.
      if (it + 1 == options.iterations || (it > 0 && !moved)) break;
      r -= alpha * q;
      g = Kt(r) - lambda * d;
      const double next = dot(g, g);
      p = g + (next / gamma) * p;
      gamma = next;
    }
    int turned = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (A.row(i).isZero() || (s[i] + d[i]) * s[i] >= 0.0) continue;
      s[i] = -s[i];
      ++turned;
    }
    if (turned == 0) break;
  }
  // Then sweeps over segments (see `segments`), the pieces that the signs turn as a whole (a
  // point alone turned in a consistent sheet only raises the residual), by turns without and
  // with the joins across thin parts. A segment S turns where that lowers |K s - b|^2 to first
  // order: sum_S s_k (K^T (K s - b))_k > sum_S |K e_k|^2 (its points' own terms; left out for
  // the segments joined across, whose sides' terms largely cancel). All such turn at once; a
  // sweep that does not lower the residual is undone, and two such in a row end the sweeps.
  // r = K s - b for the signs s (kept through the sweeps).
  Eigen::VectorXd r = K(s) - b;
  if (options.sweeps > 0) {
    const Eigen::VectorXd column = tree.near_column_norms(A, threads);
    double energy = dot(r, r);
    bool failed = false;  // the last sweep turned nothing
    Eigen::VectorXd g;    // K^T r, kept while a sweep that turned nothing leaves r as it was
    for (int sweep = 0; sweep < options.sweeps; ++sweep) {
      const std::vector<int> label = segments(V, graph, rename, N, s, sweep % 2 == 1);
      if (!failed) g = Kt(r);
      std::vector<double> gain(static_cast<std::size_t>(n), 0.0);
      for (Eigen::Index i = 0; i < n; ++i) {
        if (A.row(i).isZero()) continue;
        gain[static_cast<std::size_t>(label[i])] +=
            s[i] * g[i] - (sweep % 2 == 1 ? 0.0 : column[i]);
      }
      bool lowered = false;
      Eigen::VectorXd next = s, r_next;
      double e_next = energy;
      int turned = 0;
      for (Eigen::Index i = 0; i < n; ++i) {
        if (!A.row(i).isZero() && gain[static_cast<std::size_t>(label[i])] > 0.0) {
          next[i] = -s[i];
          ++turned;
        }
      }
      if (turned > 0) {
        r_next = K(next) - b;
        e_next = dot(r_next, r_next);
        lowered = e_next < energy;
      }
      if (!lowered) {
        if (failed) break;
        failed = true;
        continue;
      }
      failed = false;
      s = next;
      r = r_next;
      energy = e_next;
    }
  }
  report.residual_after = std::sqrt(dot(r, r)) / norm_b;
  // The field's own verdict on whether it decides: a closed surface sampled with consistent
  // normals has w near 1/2 at every sample; an open one (a scan from one side) or one noisy
  // beyond its spacing does not, whatever the signs, and then the tree's signs stay.
  report.decided = report.residual_after <= options.closed_residual &&
                   report.residual_after <= options.closed_gain * report.residual_before;
  if (!report.decided) return report;
  report.jump_turned =
      turn_by_jumps(tree, graph, rename, contact_lengths(V, graph, rename, area, N, options), A,
                    options, s, threads);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (s[i] > 0.0) continue;
    N.row(i) *= -1.0;
    ++report.flipped;
  }
  return report;
}

}  // namespace focal::detail
