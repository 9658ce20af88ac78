#include "surfaces/planar_delaunay.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "focal/core/error.h"

namespace focal::detail {
namespace {

using Eigen::Vector2d;

/// The vertex at infinity: the apex of every ghost triangle.
constexpr int kInfinite = -1;

struct Triangle {
  std::array<int, 3> v{};   ///< counter-clockwise; at most one is kInfinite
  std::array<int, 3> nb{};  ///< nb[i]: triangle across edge (v[i], v[i+1])
  bool alive = true;
};

int next(int i) { return i == 2 ? 0 : i + 1; }

/// Twice the signed area of (a, b, c): > 0 when counter-clockwise.
double orient(const Vector2d& a, const Vector2d& b, const Vector2d& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

/// > 0 when d lies strictly inside the circle through the counter-clockwise a, b, c.
double incircle(const Vector2d& a, const Vector2d& b, const Vector2d& c, const Vector2d& d) {
  const double adx = a.x() - d.x(), ady = a.y() - d.y();
  const double bdx = b.x() - d.x(), bdy = b.y() - d.y();
  const double cdx = c.x() - d.x(), cdy = c.y() - d.y();
  const double ad = adx * adx + ady * ady;
  const double bd = bdx * bdx + bdy * bdy;
  const double cd = cdx * cdx + cdy * cdy;
  return adx * (bdy * cd - bd * cdy) - ady * (bdx * cd - bd * cdx) + ad * (bdx * cdy - bdy * cdx);
}

/// A boundary edge (a, b) of a cavity: `inside` is the cavity triangle, `outside` its neighbour.
struct CavityEdge {
  int a, b, inside, outside;
};

class Triangulator {
 public:
  explicit Triangulator(const std::vector<Vector2d>& points) : p_(points) {}

  PlanarDelaunay run() {
    const std::vector<int> order = insertion_order();
    const std::array<int, 3> first = first_triangle(order);
    start(first);
    for (const int q : order) {
      if (q != first[0] && q != first[1] && q != first[2]) insert(q);
    }
    return result();
  }

 private:
  /// Rows of a coarse grid, alternately left-to-right and right-to-left, so that consecutive
  /// points are neighbours and the walk in locate() is short.
  std::vector<int> insertion_order() const {
    const int n = static_cast<int>(p_.size());
    Vector2d lo = p_[0], hi = p_[0];
    for (const auto& q : p_) {
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
    const int cells = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(n) / 4.0)));
    const Vector2d size = (hi - lo).cwiseMax(Vector2d::Constant(1e-300));
    std::vector<std::int64_t> key(n);
    for (int i = 0; i < n; ++i) {
      const Vector2d t = (p_[i] - lo).cwiseQuotient(size);
      const int row = std::min(cells - 1, static_cast<int>(t.y() * cells));
      const double x = (row % 2 == 0) ? t.x() : 1.0 - t.x();
      const int col = std::min(4 * cells - 1, static_cast<int>(x * 4 * cells));
      key[i] = static_cast<std::int64_t>(row) * 4 * cells + col;
    }
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int i, int j) { return key[i] < key[j]; });
    return order;
  }

  /// The first two points in `order` and the first point clearly off their line, CCW.
  std::array<int, 3> first_triangle(const std::vector<int>& order) const {
    const int a = order[0], b = order[1];
    const double scale = (p_[b] - p_[a]).squaredNorm();
    if (scale == 0.0) throw InvalidInput("planar_delaunay: duplicate point " + std::to_string(b));
    for (std::size_t k = 2; k < order.size(); ++k) {
      const int c = order[k];
      const double o = orient(p_[a], p_[b], p_[c]);
      // The sine of the angle at a must be clearly non-zero: a nearly flat first triangle is
      // legal but needlessly fragile.
      if (std::abs(o) > 1e-10 * std::sqrt(scale * (p_[c] - p_[a]).squaredNorm())) {
        return o > 0 ? std::array<int, 3>{a, b, c} : std::array<int, 3>{a, c, b};
      }
    }
    throw InvalidInput("planar_delaunay: all points are collinear");
  }

  /// One finite triangle and its three ghosts; adjacency by matching opposite edges.
  void start(const std::array<int, 3>& t) {
    tris_.push_back({t, {}, true});
    for (int i = 0; i < 3; ++i) tris_.push_back({{t[next(i)], t[i], kInfinite}, {}, true});
    for (int s = 0; s < 4; ++s) {
      for (int i = 0; i < 3; ++i) {
        for (int o = 0; o < 4; ++o) {
          for (int j = 0; j < 3; ++j) {
            if (o != s && tris_[o].v[j] == tris_[s].v[next(i)] &&
                tris_[o].v[next(j)] == tris_[s].v[i]) {
              tris_[s].nb[i] = o;
            }
          }
        }
      }
    }
    last_ = 0;
  }

  static int infinite_slot(const Triangle& t) {
    for (int i = 0; i < 3; ++i) {
      if (t.v[i] == kInfinite) return i;
    }
    return -1;
  }

  bool in_conflict(int t, int q) const {
    const Triangle& tri = tris_[t];
    const int inf = infinite_slot(tri);
    if (inf < 0) return incircle(p_[tri.v[0]], p_[tri.v[1]], p_[tri.v[2]], p_[q]) > 0.0;
    // Ghost (x, y, inf): its "circumcircle" is the open half-plane left of x -> y (outside the
    // hull) plus the open hull edge itself.
    const Vector2d& x = p_[tri.v[next(inf)]];
    const Vector2d& y = p_[tri.v[next(next(inf))]];
    const double o = orient(x, y, p_[q]);
    if (o != 0.0) return o > 0.0;
    return (p_[q] - x).dot(y - p_[q]) > 0.0;
  }

  /// A triangle in conflict with q: visibility walk from the last new triangle.
  int locate(int q) const {
    int t = last_;
    const int max_steps = 4 * static_cast<int>(tris_.size()) + 16;
    for (int step = 0; step < max_steps; ++step) {
      const Triangle& tri = tris_[t];
      const int inf = infinite_slot(tri);
      if (inf >= 0) {
        if (in_conflict(t, q)) return t;
        t = tri.nb[next(inf)];  // step inside across the finite edge
        continue;
      }
      // Rotating the first edge tried avoids the (rare) cycles of a fixed visiting order.
      int crossed = -1;
      for (int e = 0; e < 3 && crossed < 0; ++e) {
        const int i = (step + e) % 3;
        if (orient(p_[tri.v[i]], p_[tri.v[next(i)]], p_[q]) < 0.0) crossed = i;
      }
      if (crossed < 0) return t;
      t = tri.nb[crossed];
    }
    for (int s = 0; s < static_cast<int>(tris_.size()); ++s) {
      if (tris_[s].alive && in_conflict(s, q)) return s;
    }
    throw InvalidInput("planar_delaunay: point " + std::to_string(q) + " could not be located");
  }

  /// The connected set of triangles in conflict with q reachable from seed, skipping `excluded`.
  void grow_cavity(int seed, int q) {
    ++stamp_;
    cavity_.assign(1, seed);
    in_cavity_[seed] = stamp_;
    for (std::size_t k = 0; k < cavity_.size(); ++k) {
      for (const int n : tris_[cavity_[k]].nb) {
        if (in_cavity_[n] == stamp_ || excluded_[n] == exclusion_stamp_) continue;
        if (forced_[n] == exclusion_stamp_ || in_conflict(n, q)) {
          in_cavity_[n] = stamp_;
          cavity_.push_back(n);
        }
      }
    }
  }

  /// Boundary edges of the cavity; returns false (and shrinks or grows the cavity's rules) when
  /// rounding made q fail to see a boundary edge, i.e. the cavity is not star-shaped from q.
  bool collect_boundary(int seed, int q) {
    boundary_.clear();
    bool star_shaped = true;
    for (const int t : cavity_) {
      const Triangle& tri = tris_[t];
      for (int i = 0; i < 3; ++i) {
        const int n = tri.nb[i];
        if (in_cavity_[n] == stamp_) continue;
        const int a = tri.v[i], b = tri.v[next(i)];
        boundary_.push_back({a, b, t, n});
        if (a == kInfinite || b == kInfinite) continue;
        if (orient(p_[a], p_[b], p_[q]) > 0.0) continue;
        star_shaped = false;
        // q on an edge of the seed: the triangle beyond must go too. Otherwise drop the
        // cavity triangle whose edge q cannot see.
        if (t == seed) {
          forced_[n] = exclusion_stamp_;
        } else {
          excluded_[t] = exclusion_stamp_;
        }
      }
    }
    return star_shaped;
  }

  int new_triangle(const std::array<int, 3>& v) {
    if (!free_.empty()) {
      const int t = free_.back();
      free_.pop_back();
      tris_[t] = {v, {}, true};
      return t;
    }
    tris_.push_back({v, {}, true});
    in_cavity_.push_back(0);
    excluded_.push_back(0);
    forced_.push_back(0);
    return static_cast<int>(tris_.size()) - 1;
  }

  void insert(int q) {
    in_cavity_.resize(tris_.size(), 0);
    excluded_.resize(tris_.size(), 0);
    forced_.resize(tris_.size(), 0);
    const int seed = locate(q);
    for (const int v : tris_[seed].v) {
      if (v != kInfinite && p_[v] == p_[q]) {
        throw InvalidInput("planar_delaunay: point " + std::to_string(q) + " duplicates point " +
                           std::to_string(v));
      }
    }
    ++exclusion_stamp_;
    // Each failed round excludes or forces one more triangle, so this ends; the cap only guards
    // against a rounding pattern that would toggle forever.
    for (int round = 0;; ++round) {
      grow_cavity(seed, q);
      if (collect_boundary(seed, q)) break;
      if (round > 1000) {
        throw InvalidInput("planar_delaunay: degenerate configuration at point " +
                           std::to_string(q));
      }
    }

    for (const int t : cavity_) {
      tris_[t].alive = false;
      free_.push_back(t);
    }
    // Fan from q over the boundary; boundary edge (a, b) becomes triangle (a, b, q).
    std::vector<int> created(boundary_.size());
    for (std::size_t k = 0; k < boundary_.size(); ++k) {
      const CavityEdge& e = boundary_[k];
      const int t = new_triangle({e.a, e.b, q});
      created[k] = t;
      tris_[t].nb[0] = e.outside;
      // By vertices, not by the old index: freed indices are being reused right here.
      Triangle& outside = tris_[e.outside];
      for (int j = 0; j < 3; ++j) {
        if (outside.v[j] == e.b && outside.v[next(j)] == e.a) outside.nb[j] = t;
      }
    }
    // Edge (b, q) of one new triangle is edge (q, b) of the new triangle starting at b.
    for (std::size_t k = 0; k < boundary_.size(); ++k) {
      for (std::size_t m = 0; m < boundary_.size(); ++m) {
        if (boundary_[m].a == boundary_[k].b) {
          tris_[created[k]].nb[1] = created[m];
          tris_[created[m]].nb[2] = created[k];
        }
      }
    }
    last_ = created[0];
    for (const int t : created) {
      if (infinite_slot(tris_[t]) < 0) last_ = t;
    }
  }

  PlanarDelaunay result() const {
    PlanarDelaunay out;
    for (const Triangle& t : tris_) {
      if (!t.alive) continue;
      const int inf = infinite_slot(t);
      if (inf < 0) {
        out.triangles.push_back(t.v);
      } else {
        out.hull_edges.push_back({t.v[next(inf)], t.v[next(next(inf))]});
      }
    }
    return out;
  }

  const std::vector<Vector2d>& p_;
  std::vector<Triangle> tris_;
  std::vector<int> free_;
  int last_ = 0;
  // Scratch of insert(): per-triangle stamps avoid clearing marks for every insertion.
  std::vector<int> in_cavity_, excluded_, forced_;
  int stamp_ = 0, exclusion_stamp_ = 0;
  std::vector<int> cavity_;
  std::vector<CavityEdge> boundary_;
};

}  // namespace

PlanarDelaunay planar_delaunay(const std::vector<Eigen::Vector2d>& points) {
  if (points.size() < 3) {
    throw InvalidInput("planar_delaunay: need at least 3 points, got " +
                       std::to_string(points.size()));
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      throw InvalidInput("planar_delaunay: point " + std::to_string(i) + " is not finite");
    }
  }
  return Triangulator(points).run();
}

}  // namespace focal::detail
