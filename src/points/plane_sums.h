#pragma once
// Internal: the sums of a least-squares plane through a point's neighbours, shared by the kNN
// query's measures (points/neighbours.cpp) and the outlier tests (points/outlier_tests.cpp).

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "points/measured_neighbours.h"

namespace focal::detail {

/// The sums of a least-squares plane through points q given as offsets from the point whose
/// offset from the plane is wanted (offsets keep the plane accurate far from the origin): one
/// arithmetic for plane_offset over V's rows and for the kNN query over the tree's copies (the
/// same doubles), so both give the same bits.
struct PlaneSums {
  Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
  Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();
  double reach = 0.0;
  int count = 0;

  void add(const Eigen::RowVector3d& q) { add(q, q.norm()); }
  /// add(q), with q.norm() computed by the caller (the kNN query needs it too).
  void add(const Eigen::RowVector3d& q, double norm) {
    sum += q;
    // moment += q^T q, element by element: each element is the same one product and one sum
    // (and q_r q_c = q_c q_r), without the temporary that Eigen stores in halves and reloads
    // whole (a failed store forwarding per point and neighbour).
    for (int r = 0; r < 3; ++r) {
      for (int c = r; c < 3; ++c) moment(r, c) += q[r] * q[c];
    }
    reach += norm;
    ++count;
  }
  /// The origin's distance to the plane and the points' RMS distance to it; NaN when fewer than
  /// 3 points or the plane is undefined.
  [[nodiscard]] detail::PlaneOffset offset() const {
    if (count < 3) return {};
    Eigen::Matrix3d full = moment;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < r; ++c) full(r, c) = full(c, r);
    }
    const Eigen::RowVector3d centroid = sum / count;
    const Eigen::Matrix3d covariance = full / count - centroid.transpose() * centroid;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(covariance);
    const Eigen::RowVector3d normal = eig.eigenvectors().col(0).transpose();
    if (!normal.allFinite()) return {};
    // A floor far below any sampling's scale: on exactly flat neighbours (spread 0) only a
    // distance above rounding counts.
    return {std::abs(centroid.dot(normal)),
            std::max(std::sqrt(std::max(eig.eigenvalues()[0], 0.0)), 1e-9 * reach / count)};
  }
};

}  // namespace focal::detail
