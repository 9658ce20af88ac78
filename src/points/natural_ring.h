#pragma once
// Internal: natural neighbours in the plane (natural_ring.cpp): a cloud point's 1-ring and the
// local Delaunay triangulation around it, for the cloud default's corrected step
// (curvature/corrected_step.h).

#include <Eigen/Core>
#include <array>
#include <vector>

#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"
#include "mesh/topology.h"

namespace focal::detail {

/// The natural neighbours of the origin among the 2D points `p`: the points whose Voronoi cells
/// (among the origin and p) share an edge with the origin's, i.e. its neighbours in their
/// Delaunay triangulation; indices into p, counter-clockwise, and which consecutive ones share a
/// vertex of the origin's cell (a Delaunay triangle with the origin). Found as the edges of the
/// origin's cell, the intersection of the half-planes x . q <= |q|^2 / 2 over the points q,
/// clipped from a square 4 times the farthest point's distance: where the cell reaches that
/// square (the origin on the hull of the points, as at the rim of an open surface or on a
/// lopsided neighbourhood) it is open and the ring has a gap there (adjacent_to_next 0). Points
/// at the origin are left out; edges of zero length (more than three cells at a vertex, as on a
/// lattice) are no contact.
struct PlanarRing {
  std::vector<int> ring;
  std::vector<char> adjacent_to_next;  ///< ring[k] and ring[k + 1 mod n] share a Voronoi vertex
};
PlanarRing natural_neighbours_of_origin(const std::vector<Eigen::Vector2d>& p);

/// The working memory of natural_neighbours_of_origin: one per thread, reused from point to
/// point, so that no call allocates once the vectors have grown.
struct RingScratch {
  std::vector<Eigen::Vector2d> vertex, clipped_vertex;  ///< the cell, and its next clipping
  std::vector<int> label, clipped_label;                ///< each vertex's outgoing edge's point
  std::vector<double> side;                             ///< the vertices' side of one bisector
  double farthest2 = 0.0;     ///< the largest squared distance of a cell vertex from the origin
  std::vector<int> contacts;  ///< the labels of edges of length > 0
  std::vector<Eigen::Vector2d> about;  ///< planar_fans: p about one centre
  PlanarRing ring;                     ///< planar_fans: one centre's ring
};

/// natural_neighbours_of_origin into `out` (its vectors reused), working in `scratch`.
void natural_neighbours_of_origin(const std::vector<Eigen::Vector2d>& p, RingScratch& scratch,
                                  PlanarRing& out);

/// The triangles of the Delaunay triangulation of the 2D points `p` that have a corner among
/// `centres` (indices into p): each centre's fan among the other points (its natural
/// neighbours, natural_neighbours_of_origin about it), counter-clockwise, each triangle once
/// (starting at its smallest corner, in ascending order).
std::vector<std::array<int, 3>> planar_fans(const std::vector<Eigen::Vector2d>& p,
                                            const std::vector<int>& centres);

/// planar_fans about the one centre `centre`, into `out` (its vector reused).
void planar_fan(const std::vector<Eigen::Vector2d>& p, int centre, RingScratch& scratch,
                std::vector<std::array<int, 3>>& out);

/// planar_fan's triangles from the centre's ring when the caller has it already: `ring`, the
/// natural neighbours of the origin among p - p[centre] (planar_fan about a centre at the origin
/// finds exactly that ring again).
void fan_of_ring(const PlanarRing& ring, int centre, std::vector<std::array<int, 3>>& out);

/// Every point's fan: the triangles (i, a, b) of its local triangulation (its neighbours j with
/// ok[j] and a normal in the hemisphere of N.row(i), projected onto the plane of N.row(i)) at i,
/// counter-clockwise about N.row(i); points without ok[i] get none. Listed under their centre
/// only (`own`), in point order: the same for any thread count.
struct NaturalFans {
  RowMatrixX3i F;   ///< all fans' triangles, point i's at rows own.begin(i) .. own.end(i)
  VertexFaces own;  ///< each point's fan (not the incidence of F)
};
NaturalFans natural_fans(PositionsRef V, const RowMatrixX3d& N, const std::vector<char>& ok,
                         const Neighbourhoods& neighbours, int threads);

}  // namespace focal::detail
