#include "curvature/corrected_step.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "core/parallel.h"
#include "core/result_rows.h"
#include "curvature/baselines/corrected_curvature.h"
#include "curvature/normal_rays_detail.h"
#include "mesh/prepared_access.h"
#include "points/natural_ring.h"

namespace focal::detail {
namespace {

/// |P (a + b)| for the offsets a, b of two neighbours from the vertex (P the projection onto the
/// plane of the unit normal n): how far they are from opposing each other. The normal part is
/// the curvature's (|e|^2 k), not the sampling's. Symmetric bit for bit (a + b is b + a).
[[gnu::always_inline]] inline double opposition(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                const Eigen::Vector3d& n) {
  Eigen::Vector3d d = a + b;
  d -= n * n.dot(d);
  return d.norm();
}

/// 1-rings up to this size take each pair's opposition once (vertex_asymmetry); larger ones
/// (fan centres) compute it for each order of the pair, with no arrays of their size.
constexpr int kPairsOnce = 32;

/// stencil_asymmetry of vertex i alone. Each neighbour's term takes the least opposition with
/// another: a minimum, whatever the order its candidates come in (oppositions are norms, never
/// -0; a NaN one is passed over by std::min in any order).
double vertex_asymmetry(PositionsRef V, const RowMatrixX3d& N, const Neighbourhoods& ring, int i) {
  const Eigen::Vector3d n = N.row(i).transpose();
  if (!n.allFinite() || ring.begin(i) == ring.end(i)) return NAN;
  const int* first = ring.begin(i);
  const auto count = static_cast<int>(ring.end(i) - first);
  const auto offset = [&](int a) {
    return Eigen::Vector3d((V.row(first[a]) - V.row(i)).transpose());
  };
  double total = 0.0;
  if (count > kPairsOnce) {
    for (int a = 0; a < count; ++a) {
      const Eigen::Vector3d e = offset(a);
      double best = INFINITY;  // a 1-ring of one vertex has no opposite: infinite, not symmetric
      for (int b = 0; b < count; ++b) {
        if (b != a) best = std::min(best, opposition(e, offset(b), n));
      }
      total += best / e.norm();
    }
    return total / count;
  }
  std::array<Eigen::Vector3d, kPairsOnce> e;
  std::array<double, kPairsOnce> best;
  for (int a = 0; a < count; ++a) {
    e[static_cast<std::size_t>(a)] = offset(a);
    best[static_cast<std::size_t>(a)] = INFINITY;
  }
  for (std::size_t a = 0; a < static_cast<std::size_t>(count); ++a) {
    for (std::size_t b = a + 1; b < static_cast<std::size_t>(count); ++b) {
      const double o = opposition(e[a], e[b], n);
      best[a] = std::min(best[a], o);
      best[b] = std::min(best[b], o);
    }
  }
  for (std::size_t a = 0; a < static_cast<std::size_t>(count); ++a) total += best[a] / e[a].norm();
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

/// What one thread of cloud_corrected_measures reuses from point to point.
struct LocalScratch {
  std::vector<Eigen::Vector2d> plane;  ///< the point (origin) and its neighbours, projected
  std::vector<int> index;              ///< their rows of V
  std::vector<int> reached;            ///< local indices within the ball, breadth first
  std::vector<char> seen;
  /// Each local point's fan (planar_fans about it alone), computed once: the walk through the
  /// ball and the ball's triangles both need it.
  std::vector<std::vector<std::array<int, 3>>> fan;
  std::vector<char> has_fan;
  std::vector<std::array<int, 3>> local_faces;
  std::vector<std::array<int, 3>> faces;
  PlanarRing ring;    ///< the point's natural neighbours
  RingScratch cells;  ///< the Voronoi cells' working memory

  const std::vector<std::array<int, 3>>& fan_of(int c) {
    const auto v = static_cast<std::size_t>(c);
    if (!has_fan[v]) {
      planar_fan(plane, c, cells, fan[v]);  // into the fan's own vector, kept from point to point
      has_fan[v] = 1;
    }
    return fan[v];
  }
};

/// cloud_corrected_measures at point i (see there).
void cloud_corrected_point(PositionsRef V, const RowMatrixX3d& N, const std::vector<char>& ok,
                           const Neighbourhoods& neighbours, const ClassTolerances& tol, int i,
                           LocalScratch& s, CurvatureResult& fit) {
  const TangentFrame frame = frame_of(N.row(i).transpose());
  s.plane.assign(1, Eigen::Vector2d::Zero());
  s.index.assign(1, i);
  for (const int* j = neighbours.begin(i); j != neighbours.end(i); ++j) {
    if (!ok[static_cast<std::size_t>(*j)] || !(N.row(*j).dot(N.row(i)) > 0.0)) continue;
    const Eigen::Vector3d e = (V.row(*j) - V.row(i)).transpose();
    s.plane.emplace_back(e.dot(frame.x), e.dot(frame.y));
    s.index.push_back(*j);
  }
  const auto distance = [&](int local) {
    return (V.row(s.index[static_cast<std::size_t>(local)]) - V.row(i)).norm();
  };
  natural_neighbours_of_origin(s.plane, s.cells, s.ring);
  if (s.ring.ring.empty()) return;
  double sum = 0.0;
  for (const int q : s.ring.ring) sum += distance(q);
  const double r = kCorrectedBall * sum / static_cast<double>(s.ring.ring.size());
  // The points within the ball reached along the local triangulation's edges, as ball::gather.
  s.reached.assign(1, 0);
  s.seen.assign(s.plane.size(), 0);
  s.seen[0] = 1;
  s.fan.resize(s.plane.size());
  s.has_fan.assign(s.plane.size(), 0);
  // The point's own fan from its ring: planar_fan about it (at the origin) would clip its cell
  // again: one of the 6 or so cells a point's ball needed (100K torus).
  fan_of_ring(s.ring, 0, s.fan[0]);
  s.has_fan[0] = 1;
  std::size_t ring_end = 1;
  int rings = 0;
  for (std::size_t k = 0; k < s.reached.size(); ++k) {
    if (k == ring_end) {
      ring_end = s.reached.size();
      ++rings;
    }
    if (rings >= kCorrectedBallRings) break;
    const int c = s.reached[k];
    for (const auto& t : s.fan_of(c)) {
      for (const int q : t) {
        if (s.seen[static_cast<std::size_t>(q)]) continue;
        s.seen[static_cast<std::size_t>(q)] = 1;
        if (distance(q) <= r) s.reached.push_back(q);
      }
    }
  }
  // The ball's triangles, each once, as planar_fans(s.plane, s.reached) lists them.
  s.local_faces.clear();
  for (const int c : s.reached) {
    const auto& fan = s.fan_of(c);
    s.local_faces.insert(s.local_faces.end(), fan.begin(), fan.end());
  }
  std::sort(s.local_faces.begin(), s.local_faces.end());
  s.local_faces.erase(std::unique(s.local_faces.begin(), s.local_faces.end()), s.local_faces.end());
  s.faces.clear();
  for (const auto& t : s.local_faces) {
    s.faces.push_back({s.index[static_cast<std::size_t>(t[0])],
                       s.index[static_cast<std::size_t>(t[1])],
                       s.index[static_cast<std::size_t>(t[2])]});
  }
  baselines::detail::corrected_curvature_of_faces(V, N, s.faces, i, r, tol, fit);
}

}  // namespace

void cloud_corrected_measures(PositionsRef V, const RowMatrixX3d& N, const std::vector<char>& ok,
                              const Neighbourhoods& neighbours, const std::vector<char>& skip,
                              const CurvatureOptions& options, double scale,
                              const std::vector<int>& order, CurvatureResult& fit) {
  if (!order.empty() && order.size() != static_cast<std::size_t>(V.rows())) {
    throw InvalidInput("cloud_corrected_measures: the order does not have #V rows");
  }
  const ClassTolerances tol = class_tolerances(options, scale);
  parallel_for_blocks(V.rows(), 64, 0, [&](std::int64_t begin, std::int64_t end) {
    LocalScratch scratch;
    for (std::int64_t k = begin; k < end; ++k) {
      const std::int64_t i = order.empty() ? k : order[static_cast<std::size_t>(k)];
      const auto v = static_cast<std::size_t>(i);
      if (!ok[v] || (!skip.empty() && skip[v]) || fit.residual[i] <= kExactFitResidual) continue;
      cloud_corrected_point(V, N, ok, neighbours, tol, static_cast<int>(i), scratch, fit);
    }
  });
}

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
  return corrected_rows(fitted, one_ring, options, keep, exact_residual, fit,
                        stencil_asymmetry(fitted.V(), unit_normals(fitted).N, one_ring, 0));
}

CorrectedRows corrected_rows(const PreparedMesh& fitted, const Neighbourhoods& one_ring,
                             const CurvatureOptions& options, const std::vector<char>& keep,
                             double exact_residual, const CurvatureResult& fit,
                             Eigen::VectorXd asymmetry) {
  const UnitNormals& unit = unit_normals(fitted);
  // Each vertex's radius from its own asymmetry: written in place, no second array.
  Eigen::VectorXd& radius = asymmetry;
  parallel_for(fitted.vertex_count(), 0, [&](std::int64_t i) {
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
  parallel_for(fitted.vertex_count(), 0, [&](std::int64_t i) {
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
  apply_corrected_rows(corrected_rows(fitted, one_ring, options, keep, exact_residual, fit), 0,
                       fit);
}

}  // namespace focal::detail
