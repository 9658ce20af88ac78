#include "curvature/baselines/ball.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "focal/core/error.h"

namespace focal::baselines::ball {

double radius(const BallOptions& ball, double default_in_edges, double edge_length,
              const char* what) {
  const auto check = [what](double value, const char* name) {
    if (!std::isfinite(value) || value < 0.0) {
      throw InvalidInput(std::string(what) + ": " + name + " must be finite and >= 0, got " +
                         std::to_string(value));
    }
  };
  check(ball.radius, "ball radius");
  check(ball.radius_in_edges, "ball radius in edges");
  if (ball.radius > 0.0) return ball.radius;
  return (ball.radius_in_edges > 0.0 ? ball.radius_in_edges : default_in_edges) * edge_length;
}

void gather(PositionsRef V, const Neighbourhoods& one_ring,
            const focal::detail::VertexFaces& incidence, int centre, double r, Scratch& s,
            int max_rings) {
  if (s.stamp.size() != static_cast<std::size_t>(V.rows())) {
    s.stamp.assign(static_cast<std::size_t>(V.rows()), 0);
    s.visit = 0;
  }
  const std::uint64_t visit = ++s.visit;
  s.vertices.assign(1, centre);
  s.stamp[static_cast<std::size_t>(centre)] = visit;
  const double r2 = r * r;
  // Breadth first, the list grows; `ring_end` is where the current ring's vertices end.
  std::size_t ring_end = 1;
  int ring = 0;
  for (std::size_t k = 0; k < s.vertices.size(); ++k) {
    if (k == ring_end) {
      ring_end = s.vertices.size();
      ++ring;
    }
    if (ring >= max_rings) break;  // the vertices of ring max_rings are not expanded
    for (const int* j = one_ring.begin(s.vertices[k]); j != one_ring.end(s.vertices[k]); ++j) {
      if (s.stamp[static_cast<std::size_t>(*j)] == visit) continue;
      s.stamp[static_cast<std::size_t>(*j)] = visit;
      if ((V.row(*j) - V.row(centre)).squaredNorm() <= r2) s.vertices.push_back(*j);
    }
  }
  s.faces.clear();
  for (int v : s.vertices) {
    s.faces.insert(s.faces.end(), incidence.faces.begin() + incidence.begin(v),
                   incidence.faces.begin() + incidence.end(v));
  }
  std::sort(s.faces.begin(), s.faces.end());
  s.faces.erase(std::unique(s.faces.begin(), s.faces.end()), s.faces.end());
}

}  // namespace focal::baselines::ball
