#pragma once
// Internal: cloud_normals with the jets' residuals, for the cloud estimator's plan (the noise of
// the positions, as the recommended estimator measures it on meshes).

#include "core/spatial_order.h"
#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/normals/cloud_normals.h"
#include "focal/normals/jets.h"

namespace focal::detail {

/// orient_normals_mst, its neighbour graph built on `threads` (the tree itself is serial).
/// `copy_of`: null, or V, neighbours and N are a permuted copy of a cloud (copy row j is cloud
/// row copy_of->permutation.order[j]; curvature/cloud_curvature.cpp): the tree is then grown over
/// the cloud in its own order (its positions, its graph renamed from the copy's lists, N taken
/// back for it), whose ties it breaks by row, so that the copy's normals are turned exactly as
/// the cloud's would be.
/// `global`: orient_normals_global after the tree (on the cloud in its own order too, each
/// point's area from its list in `neighbours`).
/// `decided` (when not null): whether the global orientation ran and its field decided.
int orient_normals_mst(PositionsRef V, const Neighbourhoods& neighbours, RowMatrixX3d& N,
                       int threads, const CloudCopy* copy_of = nullptr, bool global = false,
                       bool* decided = nullptr);

/// orient_normals_mst's `global` step alone on N oriented by the tree: each point's area from
/// its list in `neighbours`, the winding number on the cloud in its own order. `copy_of` and
/// `decided` as orient_normals_mst.
void orient_after_tree(PositionsRef V, const Neighbourhoods& neighbours, RowMatrixX3d& N,
                       int threads, const CloudCopy* copy_of = nullptr, bool* decided = nullptr);

/// cloud_normals, with the jets' residuals and degrees (empty for CloudNormalMethod::pca).
/// `copy_of` as orient_normals_mst; each jet's points are then summed in the cloud's order
/// (jet_normals_from), as they are on the cloud itself. `start` (when not null, and for
/// CloudNormalMethod::jet): set to the oriented PCA normals the jets started from.
/// \throw as cloud_normals.
JetNormals cloud_jets(PositionsRef V, const Neighbourhoods& neighbours,
                      const CloudNormalOptions& options, const CloudCopy* copy_of = nullptr,
                      RowMatrixX3d* start = nullptr);

/// Turns jets = cloud_jets(V, neighbours, mst, copy_of, &start), for `options` but with the
/// orientation CloudOrientation::mst, into those of cloud_jets(V, neighbours, options, copy_of)
/// with CloudOrientation::global: the global step on the tree's start normals, then the jets'
/// sides by its field where it decided (a jet's line does not depend on its start's sign, bit
/// for bit, as cloud_jets_sided says; the field's jump sets every side). For a plan that may
/// only need the jets' residuals: the winding number runs only on the fit that is kept.
void orient_jets_globally(PositionsRef V, const Neighbourhoods& neighbours,
                          const CloudNormalOptions& options, RowMatrixX3d start, JetNormals& jets,
                          const CloudCopy* copy_of = nullptr);

/// cloud_jets with each starting (PCA) normal turned to the side of its row of `side` instead
/// of oriented by orient_normals_mst (serial, the plan's one serial step), for a plan that may
/// only need the jets' residuals and lines: a jet is fitted in the frame of its own start normal,
/// and a start normal of the other sign gives the same residual and the opposite normal, bit for
/// bit (docs/notes/points-log.md, "The default's cost"). With a viewpoint, cloud_jets itself.
/// `copy_of` as orient_normals_mst (the jets' points summed in the cloud's order:
/// jet_normals_from).
JetNormals cloud_jets_sided(PositionsRef V, const Neighbourhoods& neighbours,
                            const CloudNormalOptions& options, NormalsRef side,
                            const CloudCopy* copy_of = nullptr);

/// Turns the normals of cloud_jets_sided(V, neighbours, options, side) into those of
/// cloud_jets(V, neighbours, options): runs the orientation it left out and flips the jets
/// whose start normal it turned the other way. `copy_of` as orient_normals_mst.
void orient_sided_jets(PositionsRef V, const Neighbourhoods& neighbours,
                       const CloudNormalOptions& options, NormalsRef side, JetNormals& jets,
                       const CloudCopy* copy_of = nullptr);

}  // namespace focal::detail
