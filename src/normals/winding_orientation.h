#pragma once
// Internal: a global orientation of cloud normals by the generalised winding number
// (points/winding_number.h), for cloud_normals' CloudOrientation::global.
//
// On a closed surface sampled with consistent outward normals the winding number of the
// oriented points is 1/2 at every sample (the principal value; Gauss's theorem for the double
// layer), whatever the parts' thickness: a thin plate whose two sides point the same way has
// -1/2 on one of them. With the normals' lines known (PCA, oriented by the tree), each point
// takes a sign s_i (its normal s_i n_i, area a_i) and the signs are those of the solution of the
// damped least-squares problem
//   min_s |K s - 1/2|^2 + lambda |s - s0|^2,   K_ij = a_j n_j . (p_j - p_i) / (4 pi rho_ij^3)
// seeded from the tree's signs s0 = 1 (the damping keeps them where the field decides nothing,
// e.g. on an open flat sheet, where K s = 0 for any signs), by rounds of a few CGLS iterations
// (each a product with K and one with its transpose over the Barnes-Hut tree), each round
// seeded from the signs of the last. The same idea with free dipoles instead of signs is PGR
// (Lin et al. 2022). The least-squares signs leave patches that only turn as a whole, so then
// sweeps over segments of the neighbour graph (joined along consistent sheets, and by turns
// across thin parts too) turn those whose turning lowers |K s - 1/2|, checked on the residual
// itself. Deterministic: the tree's sums are, and the dot products and sweeps are serial.
#include <Eigen/Core>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"

namespace focal::detail {

/// Settings of orient_by_winding (defaults measured in docs/notes/points-log.md, "Global
/// orientation").
struct WindingOrientationOptions {
  double beta = 1.5;      ///< far-field criterion of the tree
  double damping = 0.05;  ///< lambda above
  /// CGLS iterations per round, at most: a round stops once an iteration turns no sign of its
  /// solution against the iteration before (only those signs are taken).
  int iterations = 5;
  int rounds = 1;  ///< rounds, each seeded from the signs of the last
  int sweeps = 6;  ///< sweeps over segments after the rounds, at most
  /// The signs are taken only where the field decides: the residual of the signs found at most
  /// closed_residual and at most closed_gain times the tree's. Measured (docs/notes/points-log.md,
  /// "Global orientation"): closed thin solids 0.13-0.34 and 0.10-0.33 of the tree's, CGAL's
  /// spheres.ply 0.26 and 0.27; open or noisy scans 0.46-0.91 (building, hippo1, hippo2, fin90,
  /// before_upsample, sphere_20k_normal) or 0.52-0.90 of the tree's (point_set_3, oni too).
  double closed_residual = 0.4;
  double closed_gain = 0.4;
  double smoothing = 0.5;  ///< smoothing length of each point, times sqrt of its area
  /// Where the field decides, rounds of per-point turns by the field's jump across the point
  /// (WindingTree::jump over its normal line, offsets jump_offset times sqrt of its area, but at
  /// most jump_gap times the distance to another sheet across the point), at most jump_rounds.
  /// The jets' sides (side_by_jumps) take the offsets without the gap's limit: with it, thin
  /// rings' jets came out worse (docs/notes/points-log.md, "Global orientation").
  double jump_offset = 0.5;
  double jump_gap = 0.35;
  int jump_rounds = 3;
};

/// What orient_by_winding did.
struct WindingOrientationReport {
  bool decided = false;          ///< the field decided (the options' closed_* tests passed)
  int flipped = 0;               ///< rows of N turned (0 unless decided)
  int jump_turned = 0;           ///< of those, turns by the jumps (counted per round)
  double residual_before = NAN;  ///< |K s0 - 1/2| / |1/2| over the finite points
  double residual_after = NAN;   ///< the same for the signs found
};

/// The area of each point's patch (#V): pi d^2 / m over its list in `neighbours` (sorted by
/// distance) restricted to the neighbours near its tangent plane (|n . e| <= |e| / 2, n its
/// row of N), d the distance of the farthest of those m; all its neighbours where m < 3;
/// 0 where its normal or position is not finite. Depends on the point's own list and rows only.
Eigen::VectorXd patch_areas(PositionsRef V, const Neighbourhoods& neighbours, NormalsRef N,
                            int threads);

/// Turns rows of N (oriented, e.g. by the tree) to the signs described above, then whole
/// segments of `graph` (neighbour lists, e.g. points/neighbours.h's) where that lowers the
/// residual further. `rename`: null, or graph's rows and entries are renamed to rows of V by it
/// (the lists of a permuted copy: cloud_jets.h). `area` as patch_areas (#V, V's rows). Rows with
/// a zero area or non-finite normal are left as they are.
WindingOrientationReport orient_by_winding(PositionsRef V, const Neighbourhoods& graph,
                                           const std::vector<int>* rename,
                                           const Eigen::VectorXd& area, RowMatrixX3d& N,
                                           int threads,
                                           const WindingOrientationOptions& options = {});

/// Turns rows of L (#V x 3: lines refined from N's, e.g. the jets fitted in the frames of N) to
/// the side that the field's jump across each point says (WindingTree::jump along the row, the
/// dipoles a_i n_i of N as orient_by_winding left them where its field decided; `area` as
/// patch_areas): a line's side decided by the solid, not by the side of the normal it was
/// refined from, which a line refined through more than 90 degrees loses. Rows without a dipole
/// or a finite line are left as they are. Returns the rows turned.
int side_by_jumps(PositionsRef V, const Eigen::VectorXd& area, NormalsRef N, RowMatrixX3d& L,
                  int threads, const WindingOrientationOptions& options = {});

}  // namespace focal::detail
