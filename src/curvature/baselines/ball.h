#pragma once
// The ball neighbourhood B(x_i, r) of the ball-based baselines (LRTC20, YLHP06).

#include <climits>
#include <cstdint>
#include <vector>

#include "core/parallel.h"
#include "focal/core/mesh.h"
#include "focal/curvature/baselines.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/prepared.h"
#include "mesh/prepared_access.h"
#include "mesh/topology.h"

namespace focal::baselines::ball {

/// The radius of `ball` on a mesh of mean edge length `edge_length`, `default_in_edges` edge
/// lengths where the options give neither a radius nor a radius in edges.
/// \throw InvalidInput (naming `what`) when a radius is negative or not finite.
double radius(const BallOptions& ball, double default_in_edges, double edge_length,
              const char* what);

/// What one thread reuses from vertex to vertex.
struct Scratch {
  std::vector<int> vertices;         ///< inside the ball, connected to the centre inside it
  std::vector<int> faces;            ///< incident to those vertices, sorted, each once
  std::vector<std::uint64_t> stamp;  ///< per mesh vertex: the visit that last reached it
  std::uint64_t visit = 0;
};

/// Fills s.vertices and s.faces for the ball of radius r around vertex `centre`: the vertices
/// reached from it along edges without leaving the ball, at most `max_rings` edges away, and
/// their incident faces (a face cut by the sphere with no corner inside is left out: its part
/// inside is O(h^3 / r) in area). The ring cap bounds what a vertex reads in rings (tiles).
void gather(PositionsRef V, const Neighbourhoods& one_ring,
            const focal::detail::VertexFaces& incidence, int centre, double r, Scratch& s,
            int max_rings = INT_MAX);

/// Calls visit(i, faces) for every vertex i of `mesh`, on the pool's threads, with the faces of
/// its ball of radius radius_of(i) (gather, at most `max_rings` edges from i); each thread
/// reuses its scratch.
template <class Radius, class Visit>
void for_each_ball(const PreparedMesh& mesh, Radius radius_of, int max_rings, int threads,
                   Visit visit) {
  const auto incidence = focal::detail::incidence(mesh);
  const auto one_ring = focal::detail::one_ring(mesh);
  focal::detail::parallel_for(mesh.vertex_count(), threads, [&](std::int64_t i) {
    thread_local Scratch scratch;
    gather(mesh.V(), *one_ring, *incidence, static_cast<int>(i), radius_of(i), scratch, max_rings);
    visit(i, scratch.faces);
  });
}

/// The same with one radius r for every vertex and no ring cap.
template <class Visit>
void for_each_ball(const PreparedMesh& mesh, double r, int threads, Visit visit) {
  for_each_ball(mesh, [r](std::int64_t) { return r; }, INT_MAX, threads, visit);
}

}  // namespace focal::baselines::ball
