#include "points/winding_number.h"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <numbers>

#include "core/parallel.h"
#include "core/simd_lanes.h"
#include "focal/core/error.h"

namespace focal::detail {
namespace {

constexpr double kInvFourPi = 0.25 * std::numbers::inv_pi;
/// Nodes deeper than this are leaves whatever their count (coincident points).
constexpr int kMaxDepth = 48;

/// The term of one dipole m at a point q, m . (p - q) = mr, rho2 = |p - q|^2 plus the smoothing:
/// 4 pi times its winding number.
inline double dipole_term(double mr, double rho2) { return mr / (rho2 * std::sqrt(rho2)); }

/// The near sums run four source points per step in lanes (two SSE2 or one AVX vector), each
/// lane summing every fourth point of a leaf, the lanes added in a fixed order at the end: the
/// same bits for any thread count. A leaf's last lanes past its end are sources of no weight.
using Near = Lanes4;
constexpr int kNearLanes = static_cast<int>(sizeof(Near) / sizeof(double));

/// Lane l of the step at j: x[j + l], or `pad` past `end`.
FOCAL_LANE_INLINE Near near_lanes(const double* x, int j, int end, double pad) {
  if (j + kNearLanes <= end) return load_lanes<Near>(x + j);
  return lanes_of<Near>([&](int l) { return j + l < end ? x[j + l] : pad; });
}

FOCAL_LANE_INLINE double lane_sum(Near x) { return (x[0] + x[1]) + (x[2] + x[3]); }

/// 1 / (rho2 sqrt(rho2)) per lane, 0 where rho2 is 0 (a coincident point without smoothing:
/// no term).
FOCAL_LANE_INLINE Near inverse_cube(Near rho2) {
  const Near r3 = rho2 * lane_sqrt(rho2);
  return rho2 > 0.0 ? 1.0 / r3 : Near{};
}

}  // namespace

WindingTree::WindingTree(PositionsRef V, const Eigen::VectorXd& smoothing, double beta)
    : rows_(V.rows()), beta2_(beta * beta) {
  if (smoothing.size() != V.rows()) {
    throw InvalidInput("WindingTree: smoothing does not have #V entries");
  }
  if (!(beta > 1.0) || !std::isfinite(beta)) throw InvalidInput("WindingTree: beta must be > 1");
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    if (V.row(i).allFinite()) order_.push_back(static_cast<int>(i));
  }
  const auto n = static_cast<Eigen::Index>(order_.size());
  P_.resize(n, 3);
  s2_.resize(n);
  if (n == 0) return;
  Eigen::Vector3d low = V.row(order_[0]).transpose(), high = low;
  for (const int i : order_) {
    low = low.cwiseMin(V.row(i).transpose());
    high = high.cwiseMax(V.row(i).transpose());
  }
  nodes_.push_back({});
  nodes_[0].begin = 0;
  nodes_[0].end = static_cast<int>(n);
  build(V, 0, low, (high - low).maxCoeff(), 0);
  nodes_.shrink_to_fit();  // the growth's spare capacity, up to as much again
  for (Eigen::Index t = 0; t < n; ++t) {
    const int i = order_[static_cast<std::size_t>(t)];
    P_.row(t) = V.row(i);
    const double s = std::isfinite(smoothing[i]) ? smoothing[i] : 0.0;
    s2_[t] = 0.5 * s * s;
  }
  for (Node& node : nodes_) {
    double sum = 0.0;
    for (int t = node.begin; t < node.end; ++t) sum += s2_[t];
    node.s2 = sum / (node.end - node.begin);
  }
}

void WindingTree::build(PositionsRef V, int node, const Eigen::Vector3d& low, double size,
                        int depth) {
  const int begin = nodes_[node].begin, end = nodes_[node].end;
  Eigen::Vector3d lo = V.row(order_[begin]).transpose(), hi = lo;
  for (int t = begin; t < end; ++t) {
    lo = lo.cwiseMin(V.row(order_[t]).transpose());
    hi = hi.cwiseMax(V.row(order_[t]).transpose());
  }
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  double r2 = 0.0;
  for (int t = begin; t < end; ++t)
    r2 = std::max(r2, (V.row(order_[t]).transpose() - centre).squaredNorm());
  nodes_[node].centre = centre;
  nodes_[node].radius = std::sqrt(r2);
  nodes_[node].open2 = beta2_ * r2;
  if (end - begin <= kLeafPoints || depth >= kMaxDepth || r2 == 0.0) return;
  // The eight octants of the cube (low, size), each point in the octant of its position against
  // the cube's midpoint; a stable counting sort keeps rows in order within each octant.
  const Eigen::Vector3d mid = low + Eigen::Vector3d::Constant(0.5 * size);
  const auto octant = [&](int i) {
    return (V(i, 0) >= mid.x() ? 1 : 0) | (V(i, 1) >= mid.y() ? 2 : 0) |
           (V(i, 2) >= mid.z() ? 4 : 0);
  };
  std::array<int, 9> start{};
  for (int t = begin; t < end; ++t) ++start[static_cast<std::size_t>(octant(order_[t])) + 1];
  for (std::size_t o = 0; o < 8; ++o) start[o + 1] += start[o];
  std::vector<int> sorted(static_cast<std::size_t>(end - begin));
  std::array<int, 8> fill{};
  for (std::size_t o = 0; o < 8; ++o) fill[o] = start[o];
  for (int t = begin; t < end; ++t) {
    const int i = order_[t];
    sorted[static_cast<std::size_t>(fill[static_cast<std::size_t>(octant(i))]++)] = i;
  }
  std::copy(sorted.begin(), sorted.end(), order_.begin() + begin);
  const int first = static_cast<int>(nodes_.size());
  int children = 0;
  for (std::size_t o = 0; o < 8; ++o) {
    if (start[o + 1] == start[o]) continue;
    Node child;
    child.begin = begin + start[o];
    child.end = begin + start[o + 1];
    nodes_.push_back(child);
    ++children;
  }
  nodes_[node].first_child = first;
  nodes_[node].children = children;
  int c = first;
  for (std::size_t o = 0; o < 8; ++o) {
    if (start[o + 1] == start[o]) continue;
    const Eigen::Vector3d child_low(o & 1 ? mid.x() : low.x(), o & 2 ? mid.y() : low.y(),
                                    o & 4 ? mid.z() : low.z());
    build(V, c++, child_low, 0.5 * size, depth + 1);
  }
}

template <class Far, class Near>
void WindingTree::visit(const Eigen::Vector3d& q, Far&& far, Near&& near) const {
  int stack[8 * kMaxDepth + 8];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const auto k = static_cast<std::size_t>(stack[--top]);
    const Node& node = nodes_[k];
    const double d2 = (node.centre - q).squaredNorm();
    if (d2 > node.open2) {
      far(node, k, d2);
    } else if (node.first_child < 0) {
      near(node);
    } else {
      for (int c = node.first_child + node.children - 1; c >= node.first_child; --c)
        stack[top++] = c;
    }
  }
}

WindingTree::Moments WindingTree::moments(const RowMatrixX3d& M,
                                          const Eigen::VectorXd& sign) const {
  if (M.rows() != rows_) throw InvalidInput("WindingTree::winding: M does not have #V rows");
  if (sign.size() != 0 && sign.size() != rows_) {
    throw InvalidInput("WindingTree::winding: sign is neither empty nor #V long");
  }
  const auto n = static_cast<Eigen::Index>(order_.size());
  Moments d;
  d.M.resize(n, 3);
  for (Eigen::Index t = 0; t < n; ++t) {
    const int row = order_[static_cast<std::size_t>(t)];
    const Eigen::RowVector3d m = sign.size() != 0 ? Eigen::RowVector3d(sign[row] * M.row(row))
                                                  : Eigen::RowVector3d(M.row(row));
    d.M.row(t) = m.allFinite() ? m : Eigen::RowVector3d::Zero();
  }
  d.far.resize(nodes_.size());
  if (!nodes_.empty()) far_moments(0, d);
  return d;
}

std::pair<Eigen::Vector3d, Eigen::Matrix3d> WindingTree::far_moments(int k, Moments& d) const {
  // Depth first, children in order: the sums and second moments of each node about its centre
  // from its children's (no array of them beside the far terms), then its far term's
  // coefficients.
  const Node& node = nodes_[static_cast<std::size_t>(k)];
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  Eigen::Matrix3d T = Eigen::Matrix3d::Zero();
  if (node.first_child < 0) {
    for (int t = node.begin; t < node.end; ++t) {
      const Eigen::Vector3d m = d.M.row(t).transpose();
      s += m;
      T += m * (P_.row(t).transpose() - node.centre).transpose();
    }
  } else {
    for (int c = node.first_child; c < node.first_child + node.children; ++c) {
      const auto [cs, cT] = far_moments(c, d);
      s += cs;
      T += cT + cs * (nodes_[static_cast<std::size_t>(c)].centre - node.centre).transpose();
    }
  }
  d.far[static_cast<std::size_t>(k)] = {s.x(),
                                        s.y(),
                                        s.z(),
                                        T.trace(),
                                        T(0, 0),
                                        T(1, 1),
                                        T(2, 2),
                                        T(0, 1) + T(1, 0),
                                        T(0, 2) + T(2, 0),
                                        T(1, 2) + T(2, 1)};
  return {s, T};
}

double WindingTree::winding_sum(const Eigen::Vector3d& q, double own, const Moments& d) const {
  double w = 0.0;
  visit(
      q,
      [&](const Node& node, std::size_t k, double d2) {
        const double x = node.centre.x() - q.x(), y = node.centre.y() - q.y(),
                     z = node.centre.z() - q.z();
        const double rho2 = d2 + own + node.s2;
        const double inv2 = 1.0 / rho2, inv3 = inv2 / std::sqrt(rho2);
        const std::array<double, 10>& f = d.far[k];
        const double xTx =
            f[4] * x * x + f[5] * y * y + f[6] * z * z + f[7] * x * y + f[8] * x * z + f[9] * y * z;
        w += inv3 * (f[0] * x + f[1] * y + f[2] * z + f[3] - 3.0 * inv2 * xTx);
      },
      [&](const Node& node) {
        // Lanes past the leaf's end: at q, no dipole, smoothing 1 (a finite zero term).
        Near sum{};
        for (int j = node.begin; j < node.end; j += kNearLanes) {
          const Near rx = near_lanes(P_.col(0).data(), j, node.end, q.x()) - q.x();
          const Near ry = near_lanes(P_.col(1).data(), j, node.end, q.y()) - q.y();
          const Near rz = near_lanes(P_.col(2).data(), j, node.end, q.z()) - q.z();
          const Near mr = near_lanes(d.M.col(0).data(), j, node.end, 0.0) * rx +
                          near_lanes(d.M.col(1).data(), j, node.end, 0.0) * ry +
                          near_lanes(d.M.col(2).data(), j, node.end, 0.0) * rz;
          const Near rho2 =
              rx * rx + ry * ry + rz * rz + own + near_lanes(s2_.data(), j, node.end, 1.0);
          sum += mr * inverse_cube(rho2);
        }
        w += lane_sum(sum);
      });
  return w;
}

Eigen::VectorXd WindingTree::winding(const RowMatrixX3d& M, const Eigen::VectorXd& sign,
                                     int threads) const {
  const Moments d = moments(M, sign);
  const auto n = static_cast<Eigen::Index>(order_.size());
  Eigen::VectorXd out = Eigen::VectorXd::Zero(rows_);
  parallel_for(n, threads, [&](std::int64_t t) {
    const double w = winding_sum(P_.row(t).transpose(), s2_[t], d);
    out[order_[static_cast<std::size_t>(t)]] = kInvFourPi * w;
  });
  return out;
}

Eigen::VectorXd WindingTree::jump(const RowMatrixX3d& E, const RowMatrixX3d& M,
                                  const Eigen::VectorXd& sign, int threads) const {
  if (E.rows() != rows_) throw InvalidInput("WindingTree::jump: E does not have #V rows");
  return jumps(M, sign, threads,
               [&](int row) -> Eigen::Vector3d { return E.row(row).transpose(); });
}

Eigen::VectorXd WindingTree::jump_along(const RowMatrixX3d& lines, const Eigen::VectorXd& length,
                                        const RowMatrixX3d& M, const Eigen::VectorXd& sign,
                                        int threads) const {
  if (lines.rows() != rows_ || length.size() != rows_) {
    throw InvalidInput("WindingTree::jump_along: lines or length do not have #V rows");
  }
  return jumps(M, sign, threads, [&](int row) -> Eigen::Vector3d {
    const double l = lines.row(row).norm();
    if (M.row(row).isZero() || !(l > 0.0) || !std::isfinite(l)) return Eigen::Vector3d::Zero();
    return (length[row] / l * lines.row(row)).transpose();
  });
}

template <class Offset>
Eigen::VectorXd WindingTree::jumps(const RowMatrixX3d& M, const Eigen::VectorXd& sign, int threads,
                                   Offset&& offset) const {
  const Moments d = moments(M, sign);
  const auto n = static_cast<Eigen::Index>(order_.size());
  Eigen::VectorXd out = Eigen::VectorXd::Zero(rows_);
  parallel_for(n, threads, [&](std::int64_t t) {
    const int row = order_[static_cast<std::size_t>(t)];
    const Eigen::Vector3d e = offset(row);
    if (!e.allFinite() || e.isZero()) return;
    const Eigen::Vector3d p = P_.row(t).transpose(), m = d.M.row(t).transpose();
    const double own = s2_[t];
    // The own dipole's term at p -/+ e is +/- m . e / rho^3: left out of both.
    const double self = dipole_term(m.dot(e), e.squaredNorm() + 2.0 * own);
    const double inside = winding_sum(p - e, own, d) - self;
    const double outside = winding_sum(p + e, own, d) + self;
    out[row] = kInvFourPi * (inside - outside);
  });
  return out;
}

RowMatrixX3d WindingTree::field(const Eigen::VectorXd& q, int threads) const {
  RowMatrixX3d out = RowMatrixX3d::Zero(rows_, 3);
  each_field(q, threads, [&](int row, const Eigen::Vector3d& g) { out.row(row) = g.transpose(); });
  return out;
}

Eigen::VectorXd WindingTree::transpose(const RowMatrixX3d& A, const Eigen::VectorXd& q,
                                       int threads) const {
  if (A.rows() != rows_) throw InvalidInput("WindingTree::transpose: A does not have #V rows");
  Eigen::VectorXd out = Eigen::VectorXd::Zero(rows_);
  each_field(q, threads, [&](int row, const Eigen::Vector3d& g) { out[row] = A.row(row).dot(g); });
  return out;
}

template <class Out>
void WindingTree::each_field(const Eigen::VectorXd& q, int threads, Out&& result) const {
  if (q.size() != rows_) throw InvalidInput("WindingTree::field: q does not have #V entries");
  const auto n = static_cast<Eigen::Index>(order_.size());
  if (n == 0) return;
  Eigen::VectorXd qt(n);
  for (Eigen::Index t = 0; t < n; ++t) {
    const double v = q[order_[static_cast<std::size_t>(t)]];
    qt[t] = std::isfinite(v) ? v : 0.0;
  }
  const auto count = static_cast<std::size_t>(nodes_.size());
  std::vector<double> charge(count);
  std::vector<Eigen::Vector3d> dipole(count);
  for (std::size_t k = count; k-- > 0;) {
    const Node& node = nodes_[k];
    double Q = 0.0;
    Eigen::Vector3d D = Eigen::Vector3d::Zero();
    if (node.first_child < 0) {
      for (int t = node.begin; t < node.end; ++t) {
        Q += qt[t];
        D += qt[t] * (P_.row(t).transpose() - node.centre);
      }
    } else {
      for (int c = node.first_child; c < node.first_child + node.children; ++c) {
        const auto cs = static_cast<std::size_t>(c);
        Q += charge[cs];
        D += dipole[cs] + charge[cs] * (nodes_[cs].centre - node.centre);
      }
    }
    charge[k] = Q;
    dipole[k] = D;
  }
  parallel_for(n, threads, [&](std::int64_t t) {
    const Eigen::Vector3d p = P_.row(t).transpose();
    const double own = s2_[t];
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    visit(
        p,
        [&](const Node& node, std::size_t k, double d2) {
          const Eigen::Vector3d x = p - node.centre;
          const double rho2 = d2 + own + node.s2;
          const double inv2 = 1.0 / rho2, inv3 = inv2 / std::sqrt(rho2);
          g += inv3 * (charge[k] * x - dipole[k] + 3.0 * inv2 * x.dot(dipole[k]) * x);
        },
        [&](const Node& node) {
          // Lanes past the leaf's end: at p, no charge, smoothing 1.
          Near gx{}, gy{}, gz{};
          for (int i = node.begin; i < node.end; i += kNearLanes) {
            const Near rx = p.x() - near_lanes(P_.col(0).data(), i, node.end, p.x());
            const Near ry = p.y() - near_lanes(P_.col(1).data(), i, node.end, p.y());
            const Near rz = p.z() - near_lanes(P_.col(2).data(), i, node.end, p.z());
            const Near rho2 =
                rx * rx + ry * ry + rz * rz + own + near_lanes(s2_.data(), i, node.end, 1.0);
            const Near f = near_lanes(qt.data(), i, node.end, 0.0) * inverse_cube(rho2);
            gx += f * rx, gy += f * ry, gz += f * rz;
          }
          g += Eigen::Vector3d(lane_sum(gx), lane_sum(gy), lane_sum(gz));
        });
    result(order_[static_cast<std::size_t>(t)], (kInvFourPi * g).eval());
  });
}

Eigen::VectorXd WindingTree::near_column_norms(const RowMatrixX3d& M, int threads) const {
  if (M.rows() != rows_)
    throw InvalidInput("WindingTree::near_column_norms: M does not have #V rows");
  const auto n = static_cast<Eigen::Index>(order_.size());
  Eigen::VectorXd out = Eigen::VectorXd::Zero(rows_);
  parallel_for(n, threads, [&](std::int64_t t) {
    const auto row = order_[static_cast<std::size_t>(t)];
    if (!M.row(row).allFinite()) return;
    const Eigen::Vector3d m = M.row(row).transpose(), p = P_.row(t).transpose();
    const double own = s2_[t];
    double sum = 0.0;
    visit(
        p, [](const Node&, std::size_t, double) {},
        [&](const Node& node) {
          for (int i = node.begin; i < node.end; ++i) {
            const Eigen::Vector3d r = p - P_.row(i).transpose();
            const double rho2 = r.squaredNorm() + own + s2_[i];
            if (rho2 == 0.0) continue;
            const double k = dipole_term(m.dot(r), rho2);
            sum += k * k;
          }
        });
    out[row] = kInvFourPi * kInvFourPi * sum;
  });
  return out;
}

}  // namespace focal::detail
