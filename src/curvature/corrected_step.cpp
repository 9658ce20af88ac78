#include "curvature/corrected_step.h"

#include <Eigen/Geometry>
#include <cmath>

#include "core/fields_detail.h"
#include "core/parallel.h"
#include "curvature/baselines/lachaud_2020_detail.h"
#include "mesh/prepared_detail.h"

namespace focal::detail {
namespace {

/// stencil_asymmetry of vertex i alone.
double vertex_asymmetry(PositionsRef V, const RowMatrixX3d& N, const Neighbourhoods& ring, int i) {
  const Eigen::Vector3d n = N.row(i).transpose();
  if (!n.allFinite() || ring.begin(i) == ring.end(i)) return NAN;
  double total = 0.0;
  int count = 0;
  for (const int* j = ring.begin(i); j != ring.end(i); ++j, ++count) {
    const Eigen::Vector3d e = (V.row(*j) - V.row(i)).transpose();
    double best = INFINITY;  // a 1-ring of one vertex has no opposite: infinite, not symmetric
    for (const int* k = ring.begin(i); k != ring.end(i); ++k) {
      if (k == j) continue;
      Eigen::Vector3d d = e + (V.row(*k) - V.row(i)).transpose();
      d -= n * n.dot(d);  // the normal part is the curvature's (|e|^2 k), not the sampling's
      best = std::min(best, d.norm());
    }
    total += best / e.norm();
  }
  return total / count;
}

/// The mean length of the edges at vertex i: the ball's scale follows the local sampling (a
/// graded mesh's balls hold as many faces at its dense end as at its sparse end).
double local_edge_length(PositionsRef V, const Neighbourhoods& ring, int i) {
  double sum = 0.0;
  int count = 0;
  for (const int* j = ring.begin(i); j != ring.end(i); ++j, ++count) {
    sum += (V.row(*j) - V.row(i)).norm();
  }
  return sum / count;  // i has neighbours: its asymmetry was finite
}

}  // namespace

Eigen::VectorXd stencil_asymmetry(PositionsRef V, const RowMatrixX3d& N,
                                  const Neighbourhoods& one_ring, int threads) {
  Eigen::VectorXd own(V.rows()), out(V.rows());
  parallel_for(V.rows(), threads, [&](std::int64_t i) {
    own[i] = vertex_asymmetry(V, N, one_ring, static_cast<int>(i));
  });
  // The closed 1-ring's mean: a symmetric grid stays symmetric around a few odd vertices (a
  // pole, a seam), a random sampling has no symmetric region.
  parallel_for(V.rows(), threads, [&](std::int64_t i) {
    double sum = own[i];
    int count = 1;
    const int v = static_cast<int>(i);
    for (const int* j = one_ring.begin(v); j != one_ring.end(v); ++j, ++count) sum += own[*j];
    out[i] = sum / count;
  });
  return out;
}

CorrectedRows corrected_rows(const PreparedMesh& fitted, const Neighbourhoods& one_ring,
                             const CurvatureOptions& options, const std::vector<char>& keep,
                             double exact_residual, const CurvatureResult& fit) {
  return corrected_rows(
      fitted, one_ring, options, keep, exact_residual, fit,
      stencil_asymmetry(fitted.V(), unit_normals(fitted).N, one_ring, options.threads));
}

CorrectedRows corrected_rows(const PreparedMesh& fitted, const Neighbourhoods& one_ring,
                             const CurvatureOptions& options, const std::vector<char>& keep,
                             double exact_residual, const CurvatureResult& fit,
                             Eigen::VectorXd asymmetry) {
  const UnitNormals& unit = unit_normals(fitted);
  // Each vertex's radius from its own asymmetry: written in place, no second array.
  Eigen::VectorXd& radius = asymmetry;
  parallel_for(fitted.vertex_count(), options.threads, [&](std::int64_t i) {
    const bool replaceable = !(fit.residual[i] <= exact_residual) &&
                             (keep.empty() || !keep[static_cast<std::size_t>(i)]);
    // Radius 0, no measure: symmetric stencils (and NaN asymmetry: no normal, no neighbour).
    const bool irregular = asymmetry[i] >= kSymmetricStencil;
    radius[i] = replaceable && irregular
                    ? kCorrectedBall * local_edge_length(fitted.V(), one_ring, static_cast<int>(i))
                    : 0.0;
  });
  // No ball (a symmetric stencil everywhere, as on a regular grid): no measures and no
  // whole-mesh result of them (96 B a face and 97 B a vertex, the peak of a run at 1M).
  if (!(radius.array() > 0.0).any()) {
    return {{}, std::vector<char>(static_cast<std::size_t>(fitted.vertex_count()), 0)};
  }
  CorrectedRows out{
      baselines::detail::corrected_curvature(fitted, unit.N, radius, kCorrectedBallRings, options),
      std::vector<char>(static_cast<std::size_t>(fitted.vertex_count()), 0)};
  parallel_for(fitted.vertex_count(), options.threads, [&](std::int64_t i) {
    out.replace[static_cast<std::size_t>(i)] = radius[i] > 0.0 && std::isfinite(out.values.H[i]);
  });
  return out;
}

void apply_corrected_rows(const CorrectedRows& rows, int threads, CurvatureResult& fit) {
  parallel_for(static_cast<std::int64_t>(rows.replace.size()), threads, [&](std::int64_t i) {
    if (rows.replace[static_cast<std::size_t>(i)]) copy_row(rows.values, i, fit, i);
  });
}

void prefer_corrected_measures(const PreparedMesh& fitted, const Neighbourhoods& one_ring,
                               const CurvatureOptions& options, const std::vector<char>& keep,
                               double exact_residual, CurvatureResult& fit) {
  apply_corrected_rows(corrected_rows(fitted, one_ring, options, keep, exact_residual, fit),
                       options.threads, fit);
}

}  // namespace focal::detail
