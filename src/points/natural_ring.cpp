#include "points/natural_ring.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>

#include "core/parallel.h"
#include "kernels/local_shape.h"

namespace focal::detail {
namespace {

/// The box label: an edge of the starting square, not of any point's half-plane.
constexpr int kBox = -1;

/// Whether the bisector of the origin and p surely misses the cell, by its farthest vertex
/// alone: |v| |p| < |p|^2 / 2 for every vertex v, with a margin (1e-6, far above the rounding of
/// the sides) so that clip's own test, vertex by vertex, would find every side <= 0 too. Most
/// points of a neighbourhood close no edge of the cell once the nearest have cut it.
bool surely_misses(const RingScratch& s, double p2) {
  return 4.0 * s.farthest2 * (1.0 + 1e-6) < p2;
}

/// The largest squared distance of the cell's vertices from the origin.
double farthest2_of(const std::vector<Eigen::Vector2d>& vertex) {
  double out = 0.0;
  for (const Eigen::Vector2d& v : vertex) out = std::max(out, v.squaredNorm());
  return out;
}

/// Cuts the cell held in `s` (s.vertex, and s.label: vertex k's edge to k + 1) by the
/// half-plane x . p <= |p|^2 / 2 (the side of the origin of the bisector of the origin and p);
/// the new edge is labelled `j`. Sutherland-Hodgman on one plane, each vertex's side evaluated
/// once: the early-out and the cut share them.
void clip(RingScratch& s, const Eigen::Vector2d& p, int j) {
  const double p2 = p.squaredNorm();
  if (surely_misses(s, p2)) return;
  const double offset = 0.5 * p2;
  const std::size_t m = s.vertex.size();
  s.side.resize(m);
  bool cuts = false;
  for (std::size_t e = 0; e < m; ++e) {
    s.side[e] = s.vertex[e].dot(p) - offset;
    cuts = cuts || !(s.side[e] <= 0.0);
  }
  // A point whose bisector misses the cell leaves it as it is: nothing to copy.
  if (!cuts) return;
  s.clipped_vertex.clear();
  s.clipped_label.clear();
  for (std::size_t e = 0; e < m; ++e) {
    const std::size_t next = e + 1 == m ? 0 : e + 1;
    const Eigen::Vector2d& a = s.vertex[e];
    const double fa = s.side[e], fb = s.side[next];
    if (fa <= 0.0) {
      s.clipped_vertex.push_back(a);
      s.clipped_label.push_back(s.label[e]);
    }
    if ((fa <= 0.0) != (fb <= 0.0)) {
      s.clipped_vertex.push_back(a + (fa / (fa - fb)) * (s.vertex[next] - a));
      // Leaving the half-plane, the edge from the new vertex runs along the bisector; entering
      // it, along e.
      s.clipped_label.push_back(fa <= 0.0 ? j : s.label[e]);
    }
  }
  std::swap(s.vertex, s.clipped_vertex);
  std::swap(s.label, s.clipped_label);
  s.farthest2 = farthest2_of(s.vertex);
}

/// The triangles (centre, a, b) of consecutive adjacent ring points a, b, appended to `out`,
/// each starting at its smallest corner.
void append_triangles(const PlanarRing& ring, int centre, std::vector<std::array<int, 3>>& out) {
  const std::size_t m = ring.ring.size();
  for (std::size_t k = 0; k < m; ++k) {
    if (!ring.adjacent_to_next[k]) continue;
    std::array<int, 3> t{centre, ring.ring[k], ring.ring[(k + 1) % m]};
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    out.push_back(t);
  }
}

/// The triangles of `centre`'s fan among p (its natural neighbours about it), appended to
/// `out`, each starting at its smallest corner.
void append_fan(const std::vector<Eigen::Vector2d>& p, int centre, RingScratch& scratch,
                std::vector<std::array<int, 3>>& out) {
  scratch.about.resize(p.size());
  const Eigen::Vector2d origin = p[static_cast<std::size_t>(centre)];
  for (std::size_t q = 0; q < p.size(); ++q) scratch.about[q] = p[q] - origin;
  // The ring lives in scratch too: moved out for the call, so that its buffers are reused.
  PlanarRing ring = std::move(scratch.ring);
  natural_neighbours_of_origin(scratch.about, scratch, ring);
  append_triangles(ring, centre, out);
  scratch.ring = std::move(ring);
}

/// Each triangle once, in ascending order.
void sort_unique(std::vector<std::array<int, 3>>& triangles) {
  std::sort(triangles.begin(), triangles.end());
  triangles.erase(std::unique(triangles.begin(), triangles.end()), triangles.end());
}

}  // namespace

PlanarRing natural_neighbours_of_origin(const std::vector<Eigen::Vector2d>& p) {
  RingScratch scratch;
  PlanarRing out;
  natural_neighbours_of_origin(p, scratch, out);
  return out;
}

void natural_neighbours_of_origin(const std::vector<Eigen::Vector2d>& p, RingScratch& scratch,
                                  PlanarRing& out) {
  out.ring.clear();
  out.adjacent_to_next.clear();
  double reach = 0.0;
  for (const auto& q : p) reach = std::max(reach, q.norm());
  if (!(reach > 0.0) || !std::isfinite(reach)) return;
  // The cell of the origin lies within half the farthest point's distance in every direction
  // that point closes; 4 times it leaves room for cells closed by nearer points at a slant.
  const double r = 4.0 * reach;
  scratch.vertex.assign({{-r, -r}, {r, -r}, {r, r}, {-r, r}});
  scratch.label.assign({kBox, kBox, kBox, kBox});
  scratch.farthest2 = farthest2_of(scratch.vertex);
  for (std::size_t j = 0; j < p.size(); ++j) {
    if (p[j].norm() > 1e-12 * reach) clip(scratch, p[j], static_cast<int>(j));
  }
  // Edges of length zero (a cell vertex where more than three cells meet, as on a lattice) are
  // no contact: left out, so that their label's neighbours become consecutive.
  const std::size_t m = scratch.vertex.size();
  std::vector<int>& labels = scratch.contacts;
  labels.clear();
  for (std::size_t e = 0; e < m; ++e) {
    if ((scratch.vertex[(e + 1) % m] - scratch.vertex[e]).norm() > 1e-12 * reach) {
      labels.push_back(scratch.label[e]);
    }
  }
  // Start after a box edge, if there is one, so that the open ring's ends are the list's ends.
  std::size_t start = 0;
  for (std::size_t e = 0; e < labels.size(); ++e) {
    if (labels[e] == kBox) start = e + 1;
  }
  for (std::size_t k = 0; k < labels.size(); ++k) {
    const int label = labels[(start + k) % labels.size()];
    const int next = labels[(start + k + 1) % labels.size()];
    if (label == kBox) continue;
    out.ring.push_back(label);
    out.adjacent_to_next.push_back(next != kBox && next != label ? 1 : 0);
  }
}

std::vector<std::array<int, 3>> planar_fans(const std::vector<Eigen::Vector2d>& p,
                                            const std::vector<int>& centres) {
  std::vector<std::array<int, 3>> out;
  RingScratch scratch;
  for (const int c : centres) append_fan(p, c, scratch, out);
  sort_unique(out);
  return out;
}

void planar_fan(const std::vector<Eigen::Vector2d>& p, int centre, RingScratch& scratch,
                std::vector<std::array<int, 3>>& out) {
  out.clear();
  append_fan(p, centre, scratch, out);
  sort_unique(out);
}

void fan_of_ring(const PlanarRing& ring, int centre, std::vector<std::array<int, 3>>& out) {
  out.clear();
  append_triangles(ring, centre, out);
  sort_unique(out);
}

NaturalFans natural_fans(PositionsRef V, const RowMatrixX3d& N, const std::vector<char>& ok,
                         const Neighbourhoods& neighbours, int threads) {
  const Eigen::Index n = V.rows();
  // One list of triangles per block of points (their counts per point beside it): a list per
  // point would cost more than its 6 or so triangles at 1M points (the default's peak memory).
  constexpr std::int64_t kBlock = 256;
  std::vector<std::vector<std::array<int, 3>>> lists(
      static_cast<std::size_t>((n + kBlock - 1) / kBlock));
  NaturalFans out;
  out.own.offsets.assign(static_cast<std::size_t>(n) + 1, 0);
  parallel_for_blocks(n, kBlock, threads, [&](std::int64_t begin, std::int64_t end) {
    std::vector<Eigen::Vector2d> p;
    std::vector<int> index;
    RingScratch scratch;
    PlanarRing ring;
    auto& list = lists[static_cast<std::size_t>(begin / kBlock)];
    for (std::int64_t i = begin; i < end; ++i) {
      if (!ok[static_cast<std::size_t>(i)]) continue;
      const Eigen::Vector3d normal = N.row(i).transpose();
      const kernels::Frame<double> f =
          kernels::frame_of(kernels::Vec3<double>{normal.x(), normal.y(), normal.z()});
      const Eigen::Vector3d x{f.x.x, f.x.y, f.x.z}, y{f.y.x, f.y.y, f.y.z};
      // Counter-clockwise in (x, y) is counter-clockwise about the normal when x cross y is it.
      const bool flip = x.cross(y).dot(normal) < 0.0;
      p.clear();
      index.clear();
      const int v = static_cast<int>(i);
      for (const int* j = neighbours.begin(v); j != neighbours.end(v); ++j) {
        if (!ok[static_cast<std::size_t>(*j)] || !(N.row(*j).dot(N.row(i)) > 0.0)) continue;
        const Eigen::Vector3d e = (V.row(*j) - V.row(i)).transpose();
        p.emplace_back(e.dot(x), e.dot(y));
        index.push_back(*j);
      }
      natural_neighbours_of_origin(p, scratch, ring);
      const std::size_t m = ring.ring.size(), before = list.size();
      for (std::size_t k = 0; k < m; ++k) {
        if (!ring.adjacent_to_next[k]) continue;
        const int a = index[static_cast<std::size_t>(ring.ring[k])];
        const int b = index[static_cast<std::size_t>(ring.ring[(k + 1) % m])];
        list.push_back(flip ? std::array<int, 3>{v, b, a} : std::array<int, 3>{v, a, b});
      }
      out.own.offsets[static_cast<std::size_t>(i) + 1] = static_cast<int>(list.size() - before);
    }
    // The growth's spare capacity (up to half of all the lists) would be held until F is filled,
    // at the default's peak of memory.
    list.shrink_to_fit();
  });
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto v = static_cast<std::size_t>(i);
    out.own.offsets[v + 1] += out.own.offsets[v];
  }
  const int total = out.own.offsets.back();
  out.F.resize(total, 3);
  out.own.faces.resize(static_cast<std::size_t>(total));
  parallel_for(static_cast<std::int64_t>(lists.size()), threads, [&](std::int64_t b) {
    int row = out.own.offsets[static_cast<std::size_t>(b * kBlock)];
    auto& list = lists[static_cast<std::size_t>(b)];
    for (const auto& t : list) {
      out.F.row(row) << t[0], t[1], t[2];
      out.own.faces[static_cast<std::size_t>(row)] = row;
      ++row;
    }
    std::vector<std::array<int, 3>>().swap(list);  // freed as F fills
  });
  return out;
}

}  // namespace focal::detail
