#pragma once
// Internal: spikes found from positions alone (position_spikes.cpp), for the recommended
// estimator without trusted normals and for any pass that must not let one wild vertex into
// its neighbours' fits (smoothing, normals from positions).

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"
#include "mesh/topology.h"

namespace focal::detail {

/// The screen's deviation (spike_screen, ring radii) beyond which a vertex is judged by the
/// leave-one-out fit. Measured (docs/notes/estimator-log.md, "Spikes without normals"): at most
/// 0.094 on clean meshes (8 surfaces, regular and irregular, 850 to 16000 vertices, strips,
/// graded), 0.33 on the capped cylinder's rims, 0.76 at a cube's corners; spikes of 2 mean edges
/// 0.68 (20:1 strips) to 2.8.
constexpr double kSpikeScreen = 0.6;

/// Height off the leave-one-out quadric (in ring radii) beyond which a screened vertex is a
/// spike: the limit of the spike repair on trusted normals (spike_repair.h). Clean meshes'
/// leave-one-out heights measure at most 0.174 (the 850-vertex helix tube).
constexpr double kPositionSpikeOffset = 0.75;

/// How many times the quadric's RMS misfit a spike's height must exceed: a spike sits off a
/// smooth surface, a corner or a crease off a surface that no quadric fits. Measured
/// (docs/notes/estimator-log.md, "Spikes without normals"): a cube's corners 1.6 (height 0.71,
/// misfit 0.46, in the first fit; they leave too few points for the second); spikes of 2 mean
/// edges at least 14.5 (the 850-vertex helix tube), 40 to 10^5 elsewhere.
constexpr double kSpikeOverMisfit = 4.0;

/// Rings that a repaired position (position_spikes) reads: its 2-ring's positions and whether
/// each of them is screened (the screen offsets of its 1-ring, each reading a 1-ring and the
/// reference normal's faces: 2 rings more), with Max's normals as the reference.
constexpr int kPositionSpikeRings = 4;

/// Spikes of a mesh and where they belong.
struct PositionSpikes {
  std::vector<int> vertices;              ///< ascending
  std::vector<Eigen::Vector3d> repaired;  ///< per spike: its position moved onto the surface
};

/// The screen of position_spikes (stage 1 below) at every vertex: `deviation` s_i minus the mean
/// of its neighbours' s_j (NaN where s_i is not defined or no neighbour has one), `radius` r_i.
struct SpikeScreen {
  Eigen::VectorXd deviation;
  Eigen::VectorXd radius;
};

SpikeScreen spike_screen(PositionsRef V, const Neighbourhoods& one_ring,
                         const RowMatrixX3d& reference, int threads);

/// The unit sum of the cross products of vertex i's faces (twice their vector area): at an
/// interior vertex the normal of its 1-ring's polygon, which p_i does not move or tilt (Max's
/// normal can: a vertex moved sideways folds its faces). NaN where the sum is zero.
Eigen::Vector3d ring_polygon_normal(PositionsRef V, FacesRef F, const VertexFaces& faces, int i);

/// Stage 2 of position_spikes at vertex i: how far (in units of `radius`, signed along
/// `reference`, a normal at i) p_i lies off the quadric height fitted over the plane of
/// `reference` to its 2-ring without i and without other candidates (`deviation`: the screen's;
/// j is left out where |deviation_j| exceeds kSpikeScreen and half of |deviation_i|, so that a
/// spike's neighbours, which its offset screens by about a third of its own, stay in), fitted
/// again without the points more than half of kPositionSpikeOffset off the first fit (a spike
/// beside a larger one). `on_surface` is where the line from p_i along the quadric's normal under
/// it meets the quadric (a spike moved along the surface's normal goes back where it was, also
/// where `reference` is tilted), or, with `closed_ring` (ring_is_closed) and where that point is
/// more than one ring radius from the 1-ring's centroid (a vertex moved sideways), the quadric's
/// point over the centroid; `height` is the distance from p_i to it. NaN where `reference` is
/// not finite, the 2-ring's lists hold more than kMaxNeighbourhoodSize entries (the cost per
/// vertex stays bounded beside the hub of a large fan), fewer than 10 points remain or the fit is
/// ill-posed.
struct OffSurface {
  double height = NAN;
  Eigen::Vector3d on_surface = Eigen::Vector3d::Constant(NAN);
  double misfit = NAN;  ///< the RMS height residual of the quadric's points, in `radius` units
};

OffSurface off_surface(PositionsRef V, const Neighbourhoods& one_ring,
                       const Eigen::VectorXd& deviation, int i, double radius,
                       const Eigen::Vector3d& reference, bool closed_ring);

/// Whether every edge at vertex i has two faces (its 1-ring closes around it).
bool ring_is_closed(FacesRef F, const Neighbourhoods& one_ring, const VertexFaces& faces, int i);

/// Vertices that sit off the surface their neighbours describe, from positions alone, and the
/// positions that put them back on it.
///
/// Two stages, so that a clean mesh pays for one pass over the 1-rings only:
/// 1. Screen (every vertex): s_i = (p_i - c_i) . n_i / r_i with c_i the centroid of the 1-ring
///    (without p_i), r_i its RMS distance from c_i, n_i = `reference.row(i)` (unit, any
///    orientation consistent between neighbours; Max's or area-weighted face normals: at a spike
///    along the normal its faces form a cone whose axis is the normal, so n_i barely moves). A
///    vertex whose s_i differs from the mean over its neighbours by more than kSpikeScreen is a
///    candidate (a spike of t ring radii measures about t (1 + 1 / valence)).
/// 2. Leave-one-out fit (candidates only, off_surface): a quadric height z(x, y) fitted by least
///    squares to the 2-ring without the vertex and without other candidates (another spike
///    nearby), over the plane of n_i or of ring_polygon_normal, whichever quadric fits its points
///    better (a vertex moved sideways tilts n_i, a spike beside it the polygon); the vertex is a
///    spike where its distance from the quadric exceeds kPositionSpikeOffset ring radii and
///    kSpikeOverMisfit times the quadric's RMS misfit (a corner or a crease is off a surface that
///    no quadric fits). Vertices with fewer than 10 such points are not judged (a third of the
///    boundary vertices of random samplings, measured).
/// The repaired position of a spike is off_surface's `on_surface`. Deterministic (the same
/// vertices and bits for any thread count).
/// \pre V #V x 3 finite, `one_ring` and `faces` of the same mesh (F its faces), `reference`
///      #V x 3 (NaN rows allowed: such vertices are not screened).
PositionSpikes position_spikes(PositionsRef V, FacesRef F, const Neighbourhoods& one_ring,
                               const VertexFaces& faces, const RowMatrixX3d& reference,
                               int threads);

}  // namespace focal::detail
