#pragma once
// Internal: the generalised winding number of oriented points and its transpose, by a Barnes-Hut
// octree (Barill et al., "Fast winding numbers for soups and clouds", SIGGRAPH 2018), for the
// global orientation of cloud normals (normals/global_orientation.h).
//
// Each point j is a dipole m_j (its normal times its area, times a sign). The winding number at
// point i of all the dipoles is
//   w_i = sum_j m_j . (p_j - p_i) / (4 pi rho_ij^3),  rho_ij^2 = |p_j - p_i|^2 + (s_i^2 + s_j^2) /
//   2
// with s_j a smoothing length per point (the term j = i is 0): 1 inside a closed surface sampled
// with outward normals, 0 outside and 1/2 on it (the principal value). Its transpose, the field
// of charges q_i at the points,
//   g_j = sum_i q_i (p_j - p_i) / (4 pi rho_ij^3),
// gives (K^T q)_j = m_j . g_j for the matrix K whose product with unit signs is w. The same
// symmetric smoothing in both makes the near field of one the exact transpose of the other's.
//
// A cell of the octree (at most kLeafPoints points) whose points lie within R of its centre c
// is taken as a whole for a point q with |q - c| > beta R: by its moments about c to second order
// (the sum of m_j and of m_j (p_j - c)^T; the sum of q_i and of q_i (p_i - c)), smoothed by the
// mean of its points' smoothing (a cell of one point is that point's exact term). Each point's sum
// runs over the cells in the tree's fixed order, one point per parallel task: the same bits for any
// thread count.
#include <Eigen/Core>
#include <array>
#include <utility>
#include <vector>

#include "focal/core/mesh.h"

namespace focal::detail {

class WindingTree {
 public:
  /// The tree over the finite rows of V (non-finite rows are no source and get 0).
  /// `smoothing`: #V smoothing lengths s_j (>= 0). `beta` > 1: the far-field criterion.
  WindingTree(PositionsRef V, const Eigen::VectorXd& smoothing, double beta);

  /// w_i at every point of V for dipoles M (#V x 3), each row times its entry of `sign` (#V)
  /// when that is not empty.
  [[nodiscard]] Eigen::VectorXd winding(const RowMatrixX3d& M, const Eigen::VectorXd& sign,
                                        int threads) const;

  /// w(p_i - e_i) - w(p_i + e_i) at every point p_i of V for offsets E (#V x 3), dipoles M
  /// times `sign` as in winding(), the term of point i's own dipole left out, each offset point
  /// smoothed as p_i: the field's jump across the surface along e_i, about 1 where e_i (shorter
  /// than the distance to any other sheet) points out of a closed surface sampled with outward
  /// dipoles, about -1 where it points in. 0 where E's row is zero or not finite.
  [[nodiscard]] Eigen::VectorXd jump(const RowMatrixX3d& E, const RowMatrixX3d& M,
                                     const Eigen::VectorXd& sign, int threads) const;

  /// jump() with the offsets made in the pass instead of held: e_i = length_i / |l_i| l_i along
  /// row i of `lines` (#V x 3; `length` #V), zero where M's row or the line is zero or the line
  /// is not finite.
  [[nodiscard]] Eigen::VectorXd jump_along(const RowMatrixX3d& lines, const Eigen::VectorXd& length,
                                           const RowMatrixX3d& M, const Eigen::VectorXd& sign,
                                           int threads) const;

  /// g_j (#V x 3) at every point of V for charges q (#V).
  [[nodiscard]] RowMatrixX3d field(const Eigen::VectorXd& q, int threads) const;

  /// A_j . g_j (#V) at every point of V for charges q: (K^T q)_j for dipoles A (#V x 3).
  [[nodiscard]] Eigen::VectorXd transpose(const RowMatrixX3d& A, const Eigen::VectorXd& q,
                                          int threads) const;

  /// sum_i (m_j . (p_j - p_i) / (4 pi rho_ij^3))^2 at every point j over the points i of the
  /// cells near it (those not taken as a whole): the squared norm of column j of K where its
  /// terms, falling as 1 / distance^4, are largest.
  [[nodiscard]] Eigen::VectorXd near_column_norms(const RowMatrixX3d& M, int threads) const;

  /// Points per leaf at most.
  static constexpr int kLeafPoints = 16;

 private:
  struct Node {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    double radius = 0.0;     ///< of the ball about centre that holds the node's points
    int begin = 0, end = 0;  ///< its points: order_[begin, end)
    int first_child = -1;    ///< children first_child ... first_child + children - 1; -1: leaf
    int children = 0;
    double s2 = 0.0;     ///< the mean of its points' half squared smoothing lengths
    double open2 = 0.0;  ///< beta^2 radius^2: taken as a whole beyond this squared distance
  };
  /// The dipoles in tree order (rows times their sign, zero where not finite) and their
  /// moments about each node's centre.
  struct Moments {
    Eigen::MatrixX3d M;  ///< column-major: each coordinate contiguous for the near sums' lanes
    /// Per node, the far term's coefficients: sum m_j (x, y, z), the trace of
    /// T = sum m_j (p_j - c)^T, and the six of x^T T x for any x: T_xx, T_yy, T_zz, T_xy + T_yx,
    /// T_xz + T_zx, T_yz + T_zy.
    std::vector<std::array<double, 10>> far;
  };
  [[nodiscard]] Moments moments(const RowMatrixX3d& M, const Eigen::VectorXd& sign) const;
  /// Sets d.far of node k and those below it from d.M; returns the node's sum of m_j and
  /// sum m_j (p_j - c)^T about its centre c.
  std::pair<Eigen::Vector3d, Eigen::Matrix3d> far_moments(int k, Moments& d) const;
  /// jump() with point row's offset offset(row).
  template <class Offset>
  [[nodiscard]] Eigen::VectorXd jumps(const RowMatrixX3d& M, const Eigen::VectorXd& sign,
                                      int threads, Offset&& offset) const;
  /// 4 pi w at q, smoothed by `own` (half its squared smoothing length), of the dipoles `d`.
  [[nodiscard]] double winding_sum(const Eigen::Vector3d& q, double own, const Moments& d) const;
  /// Splits `node` (its rows in order_, its cube's corner `low` and side `size`) into octants.
  void build(PositionsRef V, int node, const Eigen::Vector3d& low, double size, int depth);
  /// The cells for a point q, in the tree's fixed order: far(node, index, |q - centre|^2) for
  /// each cell taken as a whole, near(leaf) for each leaf that is not.
  template <class Far, class Near>
  void visit(const Eigen::Vector3d& q, Far&& far, Near&& near) const;
  /// Calls out(row, g) with the field g of charges q at every finite row of V.
  template <class Out>
  void each_field(const Eigen::VectorXd& q, int threads, Out&& out) const;

  Eigen::MatrixX3d P_;       ///< the finite points in tree order (column-major, as Moments::M)
  Eigen::VectorXd s2_;       ///< half their squared smoothing lengths, in tree order
  std::vector<int> order_;   ///< tree position -> row of V
  std::vector<Node> nodes_;  ///< nodes_[0] the root; children after their parent
  Eigen::Index rows_ = 0;
  double beta2_ = 4.0;
};

}  // namespace focal::detail
