// Irregular triangulations: Poisson-disk samples in space, Delaunay in a planar chart, edge
// flips in space.
#include <cmath>
#include <unordered_map>

#include "surfaces/planar_delaunay.h"
#include "surfaces/triangulation.h"

namespace focal::detail {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

/// Point sets with a minimum distance of at most r in space: a hash grid of cells of size 2r, so
/// that the ball of radius r around a point meets only 2 x 2 x 2 cells.
class PoissonGrid {
 public:
  PoissonGrid(double r, std::size_t expected_points) : r_(r) { cells_.reserve(expected_points); }

  /// Whether x is at least `distance` (<= r) from every point.
  [[nodiscard]] bool far_from_all(const Vector3d& x, double distance) const {
    const Vector3d scaled = x / (2.0 * r_);
    std::array<std::array<std::int64_t, 2>, 3> range{};
    for (int axis = 0; axis < 3; ++axis) {
      const double f = std::floor(scaled[axis]);
      const auto c = static_cast<std::int64_t>(f);
      range[axis] = {c, scaled[axis] - f < 0.5 ? c - 1 : c + 1};
    }
    for (const std::int64_t cx : range[0]) {
      for (const std::int64_t cy : range[1]) {
        for (const std::int64_t cz : range[2]) {
          const auto it = cells_.find(key(cx, cy, cz));
          if (it == cells_.end()) continue;
          for (const Vector3d& y : it->second) {
            if ((x - y).squaredNorm() < distance * distance) return false;
          }
        }
      }
    }
    return true;
  }

  void add(const Vector3d& x) {
    const Vector3d scaled = x / (2.0 * r_);
    cells_[key(static_cast<std::int64_t>(std::floor(scaled.x())),
               static_cast<std::int64_t>(std::floor(scaled.y())),
               static_cast<std::int64_t>(std::floor(scaled.z())))]
        .push_back(x);
  }

 private:
  static std::int64_t key(std::int64_t x, std::int64_t y, std::int64_t z) {
    constexpr std::int64_t kOffset = std::int64_t{1} << 20;
    return (x + kOffset) | ((y + kOffset) << 21) | ((z + kOffset) << 42);
  }

  double r_;
  std::unordered_map<std::int64_t, std::vector<Vector3d>> cells_;
};

/// One boundary curve c(t), t in [0, 1), of an open surface in the parameter plane.
struct BoundaryPiece {
  std::function<Vector2d(double)> curve;
  int min_count;  ///< fewest points on it (3 on a closed loop, so that it stays a loop)
};

/// The boundary curves: the disc's circle, the square's four sides (one by one, so that every
/// corner is a vertex), the two end circles of a surface periodic in u.
std::vector<BoundaryPiece> boundary_pieces(const ParameterDomain& d) {
  const double u0 = d.u_min, u1 = d.u_max, v0 = d.v_min, v1 = d.v_max;
  if (d.poles || (d.periodic_u && d.periodic_v)) return {};
  if (d.disc) {
    return {{[=](double t) -> Vector2d {
               return u1 * Vector2d(std::cos(2.0 * kPi * t), std::sin(2.0 * kPi * t));
             },
             6}};
  }
  if (d.periodic_u) {
    return {{[=](double t) { return Vector2d(u0 + t * (u1 - u0), v0); }, 3},
            {[=](double t) { return Vector2d(u0 + t * (u1 - u0), v1); }, 3}};
  }
  return {{[=](double t) { return Vector2d(u0 + t * (u1 - u0), v0); }, 1},
          {[=](double t) { return Vector2d(u1, v0 + t * (v1 - v0)); }, 1},
          {[=](double t) { return Vector2d(u1 - t * (u1 - u0), v1); }, 1},
          {[=](double t) { return Vector2d(u0, v1 - t * (v1 - v0)); }, 1}};
}

/// Cumulative arc length in space of a piece at t = k / kFine, k = 0..kFine.
constexpr int kFine = 2048;
std::vector<double> arc_length(const Parametrisation& s, const BoundaryPiece& piece) {
  std::vector<double> length(kFine + 1, 0.0);
  Vector3d previous = s.derivatives(piece.curve(0.0).x(), piece.curve(0.0).y()).x;
  for (int k = 1; k <= kFine; ++k) {
    const Vector2d uv = piece.curve(static_cast<double>(k) / kFine);
    const Vector3d x = s.derivatives(uv.x(), uv.y()).x;
    length[k] = length[k - 1] + (x - previous).norm();
    previous = x;
  }
  return length;
}

double boundary_length(const Parametrisation& s, const ParameterDomain& d) {
  double total = 0.0;
  for (const BoundaryPiece& piece : boundary_pieces(d)) total += arc_length(s, piece).back();
  return total;
}

/// Points of a piece at equal arc length, spacing at most r; its end c(1) is left to the next
/// piece.
void sample_piece(const Parametrisation& s, const BoundaryPiece& piece, double r,
                  std::vector<Vector2d>& out) {
  const std::vector<double> length = arc_length(s, piece);
  const int count = std::max(piece.min_count, static_cast<int>(std::ceil(length.back() / r)));
  int k = 0;
  for (int j = 0; j < count; ++j) {
    const double target = length.back() * j / count;
    while (length[k + 1] < target) ++k;
    const double span = length[k + 1] - length[k];
    const double f = span > 0.0 ? (target - length[k]) / span : 0.0;
    out.push_back(piece.curve((k + f) / kFine));
  }
}

/// Poles, and evenly spaced points on the boundary curves of open surfaces.
std::vector<Vector2d> fixed_points(const Parametrisation& s, const ParameterDomain& d, double r) {
  std::vector<Vector2d> out;
  if (d.poles) {
    out.emplace_back(d.u_min, 0.0);
    out.emplace_back(d.u_max, 0.0);
  }
  for (const BoundaryPiece& piece : boundary_pieces(d)) sample_piece(s, piece, r, out);
  return out;
}

/// Candidates per target vertex: enough to come close to a maximal sampling (no hole that
/// could take another point), which bounds the Delaunay circumradii by about r.
constexpr int kCandidatesPerVertex = 30;
/// Vertices a boundary of length L adds at spacing r, beyond kPacking * area / r^2: about
/// kBoundaryExcess * L / r (measured on the saddle: 0.55 to 0.59 for 100 to 2000 vertices).
constexpr double kBoundaryExcess = 0.55;

/// Minimum distance between samples for about `target` of them, from
/// target = kPacking area / r^2 + kBoundaryExcess L / r. On periodic surfaces at least
/// kLoopSamples fit around the shortest loop: with fewer, the Delaunay triangulation of the
/// replicated chart can join a point to its own copy, and no triangulation follows the surface.
double sample_spacing(const Parametrisation& s, const ParameterDomain& d, const DomainStats& stats,
                      int target) {
  constexpr double kLoopSamples = 5.0;
  const double b = kBoundaryExcess * boundary_length(s, d);
  const double r = (b + std::sqrt(b * b + 4.0 * target * kPacking * stats.area)) / (2.0 * target);
  const double loop = s.shortest_loop();
  return loop > 0.0 ? std::min(r, loop / kLoopSamples) : r;
}

/// The exclusion radius at u of a sampling graded by `grading` (density ratio u_max : u_min):
/// density exp(t ln g) at t = (u - u_min) / (u_max - u_min), so radius r0 g^(-t/2), with r0 such
/// that the count matches uniform spacing r (sum of 1/radius^2 over t as over a uniform area).
struct GradedRadius {
  double r0 = 0.0, log_grading = 0.0, u_min = 0.0, u_span = 1.0;
  GradedRadius(const ParameterDomain& d, double r, double grading)
      : r0(r), log_grading(std::log(grading)), u_min(d.u_min), u_span(d.u_max - d.u_min) {
    if (log_grading > 0.0) r0 = r * std::sqrt((grading - 1.0) / log_grading);
  }
  [[nodiscard]] double at(double u) const {
    return r0 * std::exp(-0.5 * log_grading * (u - u_min) / u_span);
  }
  [[nodiscard]] double smallest() const { return at(u_min + u_span); }
};

/// Fixed points, then random points of uniform density in area, each kept only when at least
/// radius.at(u) (in space) from all points kept so far.
std::vector<Vector2d> poisson_samples(const Parametrisation& s, const ParameterDomain& d,
                                      const DomainStats& stats, const GradedRadius& radius,
                                      int target, std::uint64_t seed) {
  const double r = radius.r0;
  std::vector<Vector2d> samples = fixed_points(s, d, radius.smallest());
  const auto expected = static_cast<std::int64_t>(std::ceil(kPacking * stats.area / (r * r)));
  PoissonGrid grid(r, static_cast<std::size_t>(expected));
  for (const Vector2d& uv : samples) grid.add(evaluate(s, d, uv).position);
  std::mt19937_64 rng(seed);
  // The grid maximum misses peaks between samples by O(h^2); 10% covers that.
  const double bound = 1.1 * stats.max_area_element;
  // Scaled by the count r gives: more than target where sample_spacing had to shrink r.
  // Graded: the dense end needs candidates in proportion to its density to be saturated.
  const auto grading = static_cast<std::int64_t>(std::ceil(std::exp(radius.log_grading)));
  const std::int64_t candidates =
      kCandidatesPerVertex * grading * std::max<std::int64_t>(target, expected);
  for (std::int64_t k = 0; k < candidates;) {
    const Vector2d uv(uniform(rng, d.u_min, d.u_max), uniform(rng, d.v_min, d.v_max));
    const double accept = uniform01(rng);
    if (!in_domain(d, uv)) continue;
    const Derivatives x = s.derivatives(uv.x(), uv.y());
    if (accept * bound >= x.xu.cross(x.xv).norm()) continue;
    ++k;
    if (!grid.far_from_all(x.x, radius.at(uv.x()))) continue;
    grid.add(x.x);
    samples.push_back(uv);
  }
  return samples;
}

/// Closed genus 0: Delaunay of the stereographic chart without the south pole (index 1), whose
/// hull edges are closed by a fan around that pole.
std::vector<Face> triangulate_polar(const Parametrisation& s, const std::vector<Vector2d>& uv) {
  std::vector<Vector2d> chart;
  std::vector<int> original;
  for (int i = 0; i < static_cast<int>(uv.size()); ++i) {
    if (i == 1) continue;
    chart.push_back(s.chart(uv[i].x(), uv[i].y()));
    original.push_back(i);
  }
  const detail::PlanarDelaunay dt = detail::planar_delaunay(chart);
  std::vector<Face> faces;
  for (const auto& t : dt.triangles) {
    faces.push_back({original[t[0]], original[t[1]], original[t[2]]});
  }
  for (const auto& e : dt.hull_edges) faces.push_back({original[e[0]], original[e[1]], 1});
  return faces;
}

/// Periodic directions: copies shifted by whole periods within `band` of the fundamental
/// domain are triangulated with the originals; of the two copies of a triangle across a seam
/// only the one whose centroid lies in the fundamental domain is kept, on original indices.
std::vector<Face> triangulate_periodic(const Parametrisation& s, const std::vector<Vector2d>& uv,
                                       double band) {
  const Vector2d period = s.chart_period();
  std::vector<Vector2d> chart;
  std::vector<int> original;
  const auto copies = [&](double p) { return p > 0.0 ? static_cast<int>(std::ceil(band / p)) : 0; };
  const int cx = copies(period.x()), cy = copies(period.y());
  const auto near_domain = [&](double x, double p) {
    return p == 0.0 || (x >= -band && x < p + band);
  };
  for (int sx = -cx; sx <= cx; ++sx) {
    for (int sy = -cy; sy <= cy; ++sy) {
      for (int i = 0; i < static_cast<int>(uv.size()); ++i) {
        const Vector2d c =
            s.chart(uv[i].x(), uv[i].y()) + Vector2d(sx * period.x(), sy * period.y());
        if ((sx != 0 || sy != 0) &&
            !(near_domain(c.x(), period.x()) && near_domain(c.y(), period.y()))) {
          continue;
        }
        chart.push_back(c);
        original.push_back(i);
      }
    }
  }
  const detail::PlanarDelaunay dt = detail::planar_delaunay(chart);
  const auto inside = [](double x, double p) { return p == 0.0 || (x >= 0.0 && x < p); };
  std::vector<Face> faces;
  for (const auto& t : dt.triangles) {
    const Vector2d centroid = (chart[t[0]] + chart[t[1]] + chart[t[2]]) / 3.0;
    if (!inside(centroid.x(), period.x()) || !inside(centroid.y(), period.y())) continue;
    faces.push_back({original[t[0]], original[t[1]], original[t[2]]});
  }
  return faces;
}

std::uint64_t edge_key(int a, int b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
         static_cast<std::uint32_t>(std::max(a, b));
}

/// Smallest interior angle of a triangle in space, in radians (0 when degenerate).
double min_angle(const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const std::array<Vector3d, 3> p{a, b, c};
  double smallest = kPi;
  for (int i = 0; i < 3; ++i) {
    const Vector3d e1 = p[(i + 1) % 3] - p[i], e2 = p[(i + 2) % 3] - p[i];
    smallest = std::min(smallest, std::atan2(e1.cross(e2).norm(), e1.dot(e2)));
  }
  return smallest;
}

/// Lawson flips in space: an interior edge is flipped when that raises the smaller of the two
/// triangles' minimum angles without making the faces disagree with the exact normals: the
/// worst face-normal . corner-normal must stay above cos 30 degrees or not drop (on a coarse
/// mesh a flip that only improves angles can cave the surface in). The sorted angle list rises
/// strictly with each flip, so this terminates; the planar Delaunay start leaves little to do.
void flip_to_max_min_angle(const std::vector<Vector3d>& x, const std::vector<Vector3d>& n,
                           std::vector<Face>& faces) {
  std::unordered_map<std::uint64_t, std::array<int, 2>> edge_faces;
  edge_faces.reserve(2 * faces.size());
  for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
    for (int i = 0; i < 3; ++i) {
      auto [it, added] = edge_faces.try_emplace(edge_key(faces[f][i], faces[f][(i + 1) % 3]),
                                                std::array<int, 2>{f, -1});
      if (!added) it->second[1] = f;
    }
  }
  const auto agreement = [&](int a, int b, int c) {
    const Vector3d normal = (x[b] - x[a]).cross(x[c] - x[a]).normalized();
    return std::min({normal.dot(n[a]), normal.dot(n[b]), normal.dot(n[c])});
  };
  constexpr double kGoodAgreement = 0.866;  // cos 30 degrees
  const auto replace = [&](int a, int b, int from, int to) {
    auto& pair = edge_faces.at(edge_key(a, b));
    (pair[0] == from ? pair[0] : pair[1]) = to;
  };
  for (bool changed = true; changed;) {
    changed = false;
    for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
      for (int i = 0; i < 3; ++i) {
        const int a = faces[f][i], b = faces[f][(i + 1) % 3], c = faces[f][(i + 2) % 3];
        const auto& pair = edge_faces.at(edge_key(a, b));
        const int g = pair[0] == f ? pair[1] : pair[0];
        if (g < 0) continue;
        const int d = faces[g][0] + faces[g][1] + faces[g][2] - a - b;
        if (d == c || edge_faces.contains(edge_key(c, d))) continue;
        const double before = std::min(min_angle(x[a], x[b], x[c]), min_angle(x[b], x[a], x[d]));
        const double after = std::min(min_angle(x[c], x[a], x[d]), min_angle(x[d], x[b], x[c]));
        if (after <= before + 1e-12) continue;
        const double agree_before = std::min(agreement(a, b, c), agreement(b, a, d));
        const double agree_after = std::min(agreement(c, a, d), agreement(d, b, c));
        if (agree_after < std::min(agree_before, kGoodAgreement)) continue;
        faces[f] = {c, a, d};
        faces[g] = {d, b, c};
        edge_faces.erase(edge_key(a, b));
        edge_faces.emplace(edge_key(c, d), std::array<int, 2>{f, g});
        replace(a, d, g, f);
        replace(b, c, f, g);
        changed = true;
      }
    }
  }
}

}  // namespace

Triangulated irregular_triangulation(const Parametrisation& s, const ParameterDomain& d,
                                     const DomainStats& stats, int target, std::uint64_t seed,
                                     double grading) {
  Triangulated t;
  const GradedRadius radius(d, sample_spacing(s, d, stats, target), grading);
  const double r = radius.r0;  // the largest spacing
  t.uv = poisson_samples(s, d, stats, radius, target, seed);
  if (d.poles) {
    t.faces = triangulate_polar(s, t.uv);
  } else if (d.periodic_u || d.periodic_v) {
    t.faces = triangulate_periodic(s, t.uv, 6.0 * r);
  } else {
    std::vector<Vector2d> chart;
    for (const Vector2d& uv : t.uv) chart.push_back(s.chart(uv.x(), uv.y()));
    for (const auto& f : detail::planar_delaunay(chart).triangles) t.faces.push_back(f);
  }
  std::vector<Vector3d> x, n;
  for (const Vector2d& uv : t.uv) {
    const SurfacePoint p = evaluate(s, d, uv);
    x.push_back(p.position);
    n.push_back(p.normal);
  }
  flip_to_max_min_angle(x, n, t.faces);
  return t;
}

}  // namespace focal::detail
