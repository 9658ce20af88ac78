#include "mesh/position_spikes.h"

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

#include "core/parallel.h"

namespace focal::detail {
namespace {

/// The screen of position_spikes at vertex i: s_i, with r_i (the 1-ring's RMS distance from its
/// centroid, which p_i does not move) into `radius`; NaN without a usable ring or normal.
double ring_offset(PositionsRef V, const Neighbourhoods& ring, const RowMatrixX3d& reference, int i,
                   double& radius) {
  radius = NAN;
  const int* begin = ring.begin(i);
  const int* end = ring.end(i);
  const auto count = static_cast<double>(end - begin);
  const Eigen::Vector3d n = reference.row(i).transpose();
  if (end - begin < 3 || !n.allFinite()) return NAN;
  // Relative to p_i: the moments of a small ring far from the origin keep their digits.
  const Eigen::Vector3d p = V.row(i).transpose();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double squares = 0.0;
  for (const int* j = begin; j != end; ++j) {
    const Eigen::Vector3d d = V.row(*j).transpose() - p;
    sum += d;
    squares += d.squaredNorm();
  }
  const Eigen::Vector3d c = sum / count;  // the centroid, from p_i
  const double spread = squares / count - c.squaredNorm();
  if (!(spread > 0.0)) return NAN;
  radius = std::sqrt(spread);
  return -c.dot(n) / radius;
}

/// Points of a leave-one-out fit at least: a quadric's 6 coefficients with a margin.
constexpr std::size_t kMinPoints = 10;

/// Residual (ring radii) beyond which a point is left out of the second fit: half the spike
/// limit; clean meshes' leave-one-out heights measure at most 0.18.
constexpr double kOutlierResidual = 0.5 * kPositionSpikeOffset;

/// A height z = c0 + c1 u + c2 v + c3 u^2 + c4 u v + c5 v^2 and its RMS misfit.
struct Quadric {
  Eigen::Matrix<double, 6, 1> c;
  double misfit;
  [[nodiscard]] double at(double u, double v) const {
    return c[0] + c[1] * u + c[2] * v + c[3] * u * u + c[4] * u * v + c[5] * v * v;
  }
  [[nodiscard]] double du(double u, double v) const { return c[1] + 2.0 * c[3] * u + c[4] * v; }
  [[nodiscard]] double dv(double u, double v) const { return c[2] + c[4] * u + 2.0 * c[5] * v; }
};

/// The least-squares quadric of the points (u, v, z); none below kMinPoints or rank 6.
std::optional<Quadric> fit_quadric(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < kMinPoints) return std::nullopt;
  Eigen::Matrix<double, Eigen::Dynamic, 6> A(static_cast<Eigen::Index>(points.size()), 6);
  Eigen::VectorXd z(static_cast<Eigen::Index>(points.size()));
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Eigen::Vector3d& x = points[k];
    A.row(static_cast<Eigen::Index>(k)) << 1.0, x.x(), x.y(), x.x() * x.x(), x.x() * x.y(),
        x.y() * x.y();
    z[static_cast<Eigen::Index>(k)] = x.z();
  }
  const Eigen::ColPivHouseholderQR<Eigen::Matrix<double, Eigen::Dynamic, 6>> qr(A);
  if (qr.rank() < 6) return std::nullopt;
  Quadric out;
  out.c = qr.solve(z);
  out.misfit = std::sqrt((A * out.c - z).squaredNorm() / static_cast<double>(points.size()));
  return out;
}

}  // namespace

Eigen::Vector3d ring_polygon_normal(PositionsRef V, FacesRef F, const VertexFaces& faces, int i) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int a = faces.begin(i); a < faces.end(i); ++a) {
    const int f = faces.faces[static_cast<std::size_t>(a)];
    const Eigen::Vector3d p = V.row(F(f, 0)).transpose();
    sum += (V.row(F(f, 1)).transpose() - p).cross(V.row(F(f, 2)).transpose() - p);
  }
  return sum.normalized();
}

bool ring_is_closed(FacesRef F, const Neighbourhoods& ring, const VertexFaces& faces, int i) {
  for (const int* j = ring.begin(i); j != ring.end(i); ++j) {
    int shared = 0;
    for (int a = faces.begin(i); a < faces.end(i); ++a) {
      const int f = faces.faces[static_cast<std::size_t>(a)];
      shared += F(f, 0) == *j || F(f, 1) == *j || F(f, 2) == *j;
    }
    if (shared != 2) return false;
  }
  return true;
}

OffSurface off_surface(PositionsRef V, const Neighbourhoods& ring, const Eigen::VectorXd& deviation,
                       int i, double radius, const Eigen::Vector3d& reference, bool closed_ring) {
  // A 2-ring with more than kMaxNeighbourhoodSize entries (a vertex beside the hub of a large
  // fan) is not judged: the cost stays bounded per vertex, as for the k-rings.
  std::size_t entries = 0;
  for (const int* j = ring.begin(i); j != ring.end(i); ++j) {
    entries += 1 + static_cast<std::size_t>(ring.end(*j) - ring.begin(*j));
  }
  if (entries > static_cast<std::size_t>(kMaxNeighbourhoodSize)) return {};
  std::vector<int> points;
  points.reserve(entries);
  for (const int* j = ring.begin(i); j != ring.end(i); ++j) {
    points.push_back(*j);
    for (const int* k = ring.begin(*j); k != ring.end(*j); ++k) points.push_back(*k);
  }
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end()), points.end());
  // Other spikes nearby stay out; the neighbours of a spike, which its own offset screens too
  // (by about a third of it), stay in.
  const double own = std::isfinite(deviation[i]) ? std::abs(deviation[i]) : 0.0;
  std::erase_if(points, [&](int j) {
    return j == i || (std::abs(deviation[j]) > kSpikeScreen && std::abs(deviation[j]) >= 0.5 * own);
  });
  const Eigen::Vector3d n = reference.normalized();
  if (!n.allFinite() || points.size() < kMinPoints || !(radius > 0.0)) return {};
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const int j : points) centre += V.row(j).transpose();
  centre /= static_cast<double>(points.size());
  const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
  // Coordinates in ring radii, so that the quadric's monomials are of order one.
  std::vector<Eigen::Vector3d> local;
  for (const int j : points) {
    const Eigen::Vector3d d = (V.row(j).transpose() - centre) / radius;
    local.emplace_back(d.dot(t1), d.dot(t2), d.dot(n));
  }
  std::optional<Quadric> q = fit_quadric(local);
  // A spike the screen missed among the points (one beside a larger spike): left out, once.
  if (q) {
    std::erase_if(local, [&](const Eigen::Vector3d& x) {
      return std::abs(x.z() - q->at(x.x(), x.y())) > kOutlierResidual;
    });
    if (local.size() < points.size()) q = fit_quadric(local);
  }
  if (!q) return {};
  // Back along the quadric's normal under p: a spike moved along the surface's normal returns
  // where it was, also where the frame is tilted from that normal (the reference normal of a
  // vertex beside another spike); Newton's steps on the line's crossing with the quadric.
  const Eigen::Vector3d d0 = (V.row(i).transpose() - centre) / radius;
  const Eigen::Vector3d x(d0.dot(t1), d0.dot(t2), d0.dot(n));
  const Eigen::Vector3d m =
      Eigen::Vector3d(-q->du(x.x(), x.y()), -q->dv(x.x(), x.y()), 1.0).normalized();
  double t = -(x.z() - q->at(x.x(), x.y())) * m.z();
  constexpr int kNewtonSteps = 6;
  for (int k = 0; k < kNewtonSteps; ++k) {
    const Eigen::Vector3d y = x + t * m;
    const double h = y.z() - q->at(y.x(), y.y());
    const double slope = m.z() - q->du(y.x(), y.y()) * m.x() - q->dv(y.x(), y.y()) * m.y();
    if (!(std::abs(slope) > 1e-6)) break;
    t -= h / slope;
  }
  Eigen::Vector3d foot = x + t * m;
  // A vertex that left its closed ring (moved along a wrong direction, folding its faces) goes
  // back onto the quadric at its 1-ring's centroid (a boundary vertex is off its ring's centroid
  // by the ring's one-sidedness).
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const int* j = ring.begin(i); j != ring.end(i); ++j) {
    const Eigen::Vector3d d = (V.row(*j).transpose() - centre) / radius;
    c += Eigen::Vector2d(d.dot(t1), d.dot(t2));
  }
  c /= static_cast<double>(ring.end(i) - ring.begin(i));
  const Eigen::Vector2d drift = foot.head<2>() - c;
  if (closed_ring && drift.norm() > 1.0) foot = Eigen::Vector3d(c.x(), c.y(), q->at(c.x(), c.y()));
  if (!foot.allFinite()) return {};
  const double height = std::copysign((x - foot).norm(), x.z() - q->at(x.x(), x.y()));
  return {height, centre + radius * (foot.x() * t1 + foot.y() * t2 + foot.z() * n), q->misfit};
}

SpikeScreen spike_screen(PositionsRef V, const Neighbourhoods& one_ring,
                         const RowMatrixX3d& reference, int threads) {
  const Eigen::Index n = V.rows();
  Eigen::VectorXd s(n);
  SpikeScreen out{Eigen::VectorXd(n), Eigen::VectorXd(n)};
  parallel_for(n, threads, [&](std::int64_t i) {
    s[i] = ring_offset(V, one_ring, reference, static_cast<int>(i), out.radius[i]);
  });
  parallel_for(n, threads, [&](std::int64_t i) {
    out.deviation[i] = NAN;
    if (!std::isfinite(s[i])) return;
    const int v = static_cast<int>(i);
    double sum = 0.0;
    int count = 0;
    for (const int* j = one_ring.begin(v); j != one_ring.end(v); ++j) {
      if (std::isfinite(s[*j])) sum += s[*j], ++count;
    }
    if (count > 0) out.deviation[i] = s[i] - sum / count;
  });
  return out;
}

PositionSpikes position_spikes(PositionsRef V, FacesRef F, const Neighbourhoods& one_ring,
                               const VertexFaces& faces, const RowMatrixX3d& reference,
                               int threads) {
  const Eigen::Index n = V.rows();
  const SpikeScreen screen = spike_screen(V, one_ring, reference, threads);
  PositionSpikes out;
  for (Eigen::Index i = 0; i < n; ++i) {
    // The few candidates one by one, in order: the same bits for any thread count.
    if (!(std::abs(screen.deviation[i]) > kSpikeScreen)) continue;
    const int v = static_cast<int>(i);
    if (one_ring.end(v) - one_ring.begin(v) > kMaxNeighbourhoodSize) continue;  // see off_surface
    const bool closed = ring_is_closed(F, one_ring, faces, v);
    // The frame of the judgement: the reference normal or the 1-ring polygon's, whichever
    // quadric fits its points better. A vertex moved sideways folds its faces and tilts the
    // reference (Max's normal: measured 125 degrees off), not the polygon; a spike beside this
    // one tilts the polygon (up to 75 degrees on strips), not the reference.
    const OffSurface by_reference = off_surface(V, one_ring, screen.deviation, v, screen.radius[i],
                                                reference.row(i).transpose(), closed);
    const OffSurface by_polygon = off_surface(V, one_ring, screen.deviation, v, screen.radius[i],
                                              ring_polygon_normal(V, F, faces, v), closed);
    const OffSurface& off =
        by_polygon.misfit < by_reference.misfit || !std::isfinite(by_reference.misfit)
            ? by_polygon
            : by_reference;
    const double height = std::abs(off.height);
    if (height > kPositionSpikeOffset && height > kSpikeOverMisfit * off.misfit) {
      out.vertices.push_back(v);
      out.repaired.push_back(off.on_surface);
    }
  }
  return out;
}

}  // namespace focal::detail
