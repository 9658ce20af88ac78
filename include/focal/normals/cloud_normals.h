#pragma once
/// \file cloud_normals.h
/// Normals of point clouds from positions and neighbourhoods (points/neighbours.h), and their
/// consistent orientation.
///
/// - pca_normals: the direction of least variance of each point and its neighbours (Hoppe et al.,
///   "Surface reconstruction from unorganized points", SIGGRAPH 1992): a line, not a side.
/// - orient_normals_mst: one side for all, by a minimum spanning tree over the symmetrised
///   neighbour graph with weights 1 - |n_i . n_j| (Hoppe et al. 1992; CGAL mst_orient_normals):
///   the tree is grown from the point of largest z of each connected component, whose normal is
///   turned to +z (outward there on a closed surface), and each point takes the side of its
///   parent. Prim's algorithm with ties broken by index: deterministic. Then the extreme points
///   vote on each component's side, so that no single seed decides it: for each of the six axis
///   directions d the 1% of the component's points farthest along d (at least 1, at most 50; ties
///   by index) add n . d (outward normals point away at the extremes of a closed surface), and
///   the component takes the side of the vote when |sum| > 0.5 x the sum of |n . d| (a clear
///   majority); otherwise (open, symmetric surfaces such as a saddle vote about 0) the same
///   number of highest points vote on +z (the sum of their n_z), not the highest alone.
/// - orient_normals_global: the tree's signs turned where the generalised winding number of the
///   oriented points says so (Barill et al. 2018; a Barnes-Hut octree): on a closed surface with
///   consistent outward normals it is 1/2 at every sample, also across parts a few spacings
///   thin, where the tree's rule (n_i . n_j > 0) joins the two sides; the signs are the
///   least-squares fit of that, damped towards the tree's, then whole patches turned where that
///   fits better; taken only where the field says the cloud is closed (else the tree's stay).
/// - orient_towards_viewpoint: each normal turned to face a viewpoint (scanner position).
/// - cloud_normals: all of it, then jet normals (normals/jets.h) over the same neighbourhoods,
///   which keep each PCA normal's side and are second-order accurate (PCA is first-order on
///   uneven neighbourhoods).
///
/// Rows without a normal (fewer than 2 finite neighbours, non-finite position) are NaN.
/// Results are gathered per point: identical for any thread count.
#include <optional>

#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"

namespace focal {

/// #V x 3 unit normals by PCA over each point and its neighbours; the sign is arbitrary.
/// \throw InvalidInput when the neighbourhoods do not have #V points.
[[nodiscard]] RowMatrixX3d pca_normals(PositionsRef V, const Neighbourhoods& neighbours);

/// Flips rows of N (in place) to one consistent side per connected component of the neighbour
/// graph, as described above. NaN rows are left as they are and break the graph.
/// Returns the number of components oriented. \throw InvalidInput when shapes differ.
int orient_normals_mst(PositionsRef V, const Neighbourhoods& neighbours, RowMatrixX3d& N);

/// Flips rows of N (in place, oriented by orient_normals_mst) to the signs whose winding number
/// is nearest 1/2 at every point (see above; normals/winding_orientation.h), the neighbourhoods
/// giving each point's area, where the field decides: where the signs found leave w far from
/// 1/2 (an open or very noisy cloud) or hardly nearer than the tree's, N is left as it is.
/// Returns the number of rows flipped. NaN rows are left as they are.
/// \throw InvalidInput when shapes differ.
int orient_normals_global(PositionsRef V, const Neighbourhoods& neighbours, RowMatrixX3d& N);

/// Flips rows of N (in place) so that each faces `viewpoint`: (viewpoint - V_i) . N_i >= 0.
/// \throw InvalidInput when shapes differ or the viewpoint is not finite.
void orient_towards_viewpoint(PositionsRef V, const Eigen::Vector3d& viewpoint, RowMatrixX3d& N);

enum class CloudNormalMethod {
  pca,  ///< PCA only
  jet,  ///< PCA for the side, then a jet of `jet_degree` in the PCA frame (default)
};

/// How estimated normals get their side.
enum class CloudOrientation {
  mst,        ///< orient_normals_mst (or the viewpoint, when one is given)
  global,     ///< orient_normals_mst, then orient_normals_global: closed surfaces, thin parts
  viewpoint,  ///< orient_towards_viewpoint; CloudNormalOptions::viewpoint must be given
};

struct CloudNormalOptions {
  CloudNormalMethod method = CloudNormalMethod::jet;
  /// 1 to 4: degree of the height polynomial of the jet normals. 3: over 16 neighbours, H errors
  /// of the fit on them were those of exact normals within 5% on 6 of the 8 analytic clouds
  /// (degree 2: up to 40% larger; docs/POINTS.md).
  int jet_degree = 3;
  /// The scanner's position: normals face it when given (with orientation mst or viewpoint).
  std::optional<Eigen::Vector3d> viewpoint{};
  /// How normals get their side; global with a viewpoint, or viewpoint without one, throw.
  CloudOrientation orientation = CloudOrientation::mst;
};

/// Estimated and oriented normals of a cloud over the given neighbourhoods.
/// \throw InvalidInput when the neighbourhoods do not have #V points or an option is out of
/// range.
[[nodiscard]] RowMatrixX3d cloud_normals(PositionsRef V, const Neighbourhoods& neighbours,
                                         const CloudNormalOptions& options = {});

}  // namespace focal
