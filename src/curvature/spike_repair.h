#pragma once
// Internal: the recommended estimator's spike repair on trusted normals (spike_repair.cpp).

#include <Eigen/Core>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"

namespace focal::detail {

/// How far each vertex lies off the surface that its 1-ring and the normals describe, along its
/// own normal, in lengths of its own edges (their mean length in the plane of
/// n_i, which a move along n_i does not stretch), signed along N.row(i): the median over
/// its neighbours j of (p_i - p_j) . (n_i + n_j) / (1 + n_i . n_j). On a smooth surface with exact
/// normals the curvature's parts of (p_i - p_j) . n_j and (p_j - p_i) . n_i cancel to third order
/// (both are -k |e|^2 / 2 + O(|e|^3)), so the offset is O(h^2) in edge lengths; a vertex moved by
/// t along its normal measures t. N rows unit. Neighbours without a finite normal or whose
/// normal is more than 120 degrees from n_i are left out; NaN where n_i is not finite or fewer
/// than half of the neighbours are left (a wild own normal). With `own_normal` false, the
/// median of (p_i - p_j) . n_j instead: the distance from the neighbours' tangent planes alone,
/// O(h) in edge lengths on a smooth surface, and small at a vertex whose normal alone is wrong.
Eigen::VectorXd normal_offsets(PositionsRef V, const RowMatrixX3d& N, const Neighbourhoods& ring,
                               int threads, bool own_normal = true);

/// Offset (normal_offsets, local edge lengths) beyond which a vertex is a spike candidate.
/// Spikes of the evaluation are 2 mean edges; clean meshes measure below 0.01, 10% vertex noise
/// about 0.1 to 0.3 (docs/notes/estimator-log.md, "Spikes").
constexpr double kSpikeOffset = 0.75;

/// Spikes: vertices whose offset (`offset`, normal_offsets) and distance from the neighbours'
/// planes (normal_offsets without the own normal, measured here at candidates only) both exceed kSpikeOffset while at most
/// one of their neighbours' offsets exceeds half of it. A spike is one vertex off a smooth
/// surface (or two, side by side: 3% of the evaluation's 0.5% spikes); an outlier normal leaves
/// the vertex on its neighbours' planes; noise moves whole neighbourhoods; a line of vertices
/// off the surface (two such neighbours) is a feature, not a spike. The capped cylinder's rims
/// with exact normals measure offsets of 0.43 and distances of 0.31 at most.
std::vector<int> find_spikes(PositionsRef V, const RowMatrixX3d& N, const Neighbourhoods& ring,
                             const Eigen::VectorXd& offset);

/// Rings a repaired position reads (its 1-ring's offsets, each of which reads a 1-ring).
constexpr int kSpikeRepairRings = 2;

/// V with each spike moved back along its normal by its offset: the position its neighbours'
/// planes and normals agree on, to O(h^3).
RowMatrixX3d repaired_positions(PositionsRef V, const RowMatrixX3d& N, const Neighbourhoods& ring,
                                const Eigen::VectorXd& offset, const std::vector<int>& spikes);

}  // namespace focal::detail
