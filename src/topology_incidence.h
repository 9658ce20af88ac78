#pragma once
// Internal, header-only: the vertex->face incidence that normals.cpp, neighbourhood.cpp and
// mesh_statistics.cpp gather over. Every per-vertex loop built on it reads the faces of its own
// vertex in ascending face order and writes only that vertex's slot, so results are identical for
// any thread count (no scatter-adds, no atomics, no hash maps per edge).
//
// Edge conventions shared by those files: an edge {a, b} is a pair of distinct vertices that are
// corners of a common face; its incident faces are the faces having both as corners (each face
// once, also one with a repeated index such as (a, a, b)). A face traverses the edge a -> b when b
// follows a counter-clockwise; a face with a repeated index traverses it both ways, i.e. has no
// direction along it.

#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "focal/error.h"
#include "focal/mesh.h"
#include "parallel.h"

namespace focal::detail {

/// Largest number of entries a CSR array with 32-bit offsets (Eigen::VectorXi) can hold.
inline constexpr std::int64_t kMaxCsrEntries = std::numeric_limits<int>::max();

/// Throws InvalidInput unless vertex_count >= 0 and every index of F lies in [0, vertex_count).
/// For callers that have a vertex count but no positions (validate_mesh_arrays needs V).
inline void check_face_indices(std::int64_t vertex_count, FacesRef F, const char* what) {
  if (vertex_count < 0) {
    throw InvalidInput(std::string(what) + ": vertex count " + std::to_string(vertex_count) +
                       " is negative");
  }
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const std::int64_t idx = F(f, c);
      if (idx < 0 || idx >= vertex_count) {
        throw InvalidInput(std::string(what) + ": face " + std::to_string(f) +
                           " refers to vertex " + std::to_string(idx) + ", but there are " +
                           std::to_string(vertex_count) + " vertices");
      }
    }
  }
}

/// True when face f has a repeated vertex index (it spans no triangle).
inline bool has_repeated_index(FacesRef F, Eigen::Index f) {
  return F(f, 0) == F(f, 1) || F(f, 1) == F(f, 2) || F(f, 0) == F(f, 2);
}

/// Relative area threshold: a triangle is degenerate when |cross| <= kDegenerateArea * L^2 with L
/// its longest edge. |cross| / L^2 is scale invariant (about twice the sine of the smallest angle
/// for thin triangles), and 1e-14 sits a few dozen ulps above what rounding leaves of an exactly
/// flat triangle, so only numerically collinear corners are caught, at any scale.
inline constexpr double kDegenerateArea = 1e-14;

/// Whether the triangle (a, b, c) has numerically zero area (see kDegenerateArea).
inline bool is_degenerate_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                   const Eigen::Vector3d& c) {
  const double longest_sq =
      std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return (b - a).cross(c - a).norm() <= kDegenerateArea * longest_sq;
}

/// Faces containing each vertex in CSR form: `faces[offsets[v] .. offsets[v+1])`, ascending, each
/// face once even when it repeats the vertex.
struct VertexFaces {
  std::vector<int> offsets;  ///< #V + 1
  std::vector<int> faces;

  [[nodiscard]] int begin(std::int64_t v) const { return offsets[static_cast<std::size_t>(v)]; }
  [[nodiscard]] int end(std::int64_t v) const { return offsets[static_cast<std::size_t>(v) + 1]; }
  [[nodiscard]] int size(std::int64_t v) const { return end(v) - begin(v); }
};

/// Builds the incidence by a counting sort over the faces (two linear passes, no comparisons).
/// F must already be validated against vertex_count.
/// \throw InvalidInput when 3 #F exceeds 32-bit offsets.
inline VertexFaces vertex_face_incidence(std::int64_t vertex_count, FacesRef F) {
  if (3 * static_cast<std::int64_t>(F.rows()) > kMaxCsrEntries) {
    throw InvalidInput("too many faces (" + std::to_string(F.rows()) +
                       ") for 32-bit neighbourhood offsets");
  }
  VertexFaces inc;
  inc.offsets.assign(static_cast<std::size_t>(vertex_count) + 1, 0);
  // Visits the distinct corners of face f, so that (a, a, b) is listed once under a.
  const auto for_each_distinct_corner = [&F](Eigen::Index f, auto&& fn) {
    const int a = F(f, 0), b = F(f, 1), c = F(f, 2);
    fn(a);
    if (b != a) fn(b);
    if (c != a && c != b) fn(c);
  };
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for_each_distinct_corner(f, [&](int v) { ++inc.offsets[static_cast<std::size_t>(v) + 1]; });
  }
  for (std::size_t v = 0; v < static_cast<std::size_t>(vertex_count); ++v) {
    inc.offsets[v + 1] += inc.offsets[v];
  }
  inc.faces.resize(static_cast<std::size_t>(inc.offsets.back()));
  std::vector<int> cursor(inc.offsets.begin(), inc.offsets.end() - 1);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for_each_distinct_corner(f, [&](int v) {
      inc.faces[static_cast<std::size_t>(cursor[static_cast<std::size_t>(v)]++)] =
          static_cast<int>(f);
    });
  }
  return inc;
}

/// One incident face of an edge seen from one endpoint v: the other endpoint, the face's position
/// in v's incidence list, and its direction (+1: v -> other, -1: other -> v, 0: both ways).
struct EdgeSide {
  int other;
  int local_face;
  int direction;
};

/// Fills `sides` with one entry per (edge at v, incident face), sorted by (other, local_face), so
/// that the faces of each edge at v are consecutive.
inline void collect_edge_sides(FacesRef F, const VertexFaces& inc, std::int64_t v,
                               std::vector<EdgeSide>& sides) {
  sides.clear();
  for (int j = inc.begin(v); j < inc.end(v); ++j) {
    const int f = inc.faces[static_cast<std::size_t>(j)];
    const int local = j - inc.begin(v);
    for (int c = 0; c < 3; ++c) {
      const int p = F(f, c), q = F(f, (c + 1) % 3);
      if (p == q) continue;
      if (p == v) sides.push_back({q, local, +1});
      if (q == v) sides.push_back({p, local, -1});
    }
  }
  std::sort(sides.begin(), sides.end(), [](const EdgeSide& a, const EdgeSide& b) {
    return a.other != b.other ? a.other < b.other : a.local_face < b.local_face;
  });
  // A face with a repeated index lists the same edge twice with opposite directions: merge.
  std::size_t m = 0;
  for (std::size_t i = 0; i < sides.size(); ++i) {
    if (m > 0 && sides[m - 1].other == sides[i].other &&
        sides[m - 1].local_face == sides[i].local_face) {
      sides[m - 1].direction += sides[i].direction;
    } else {
      sides[m++] = sides[i];
    }
  }
  sides.resize(m);
}

/// Calls fn(other, first, last) for each edge {v, other} in the sorted output of
/// collect_edge_sides; [first, last) are its incident faces.
template <class Fn>
void for_each_edge(const std::vector<EdgeSide>& sides, Fn&& fn) {
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i + 1;
    while (j < sides.size() && sides[j].other == sides[i].other) ++j;
    fn(sides[i].other, sides.data() + i, sides.data() + j);
    i = j;
  }
}

/// Whether an edge with incident faces [first, last) is interior (two faces) and traversed in
/// opposite directions by them.
inline bool is_consistent_interior_edge(const EdgeSide* first, const EdgeSide* last) {
  return last - first == 2 && first[0].direction != 0 && first[0].direction == -first[1].direction;
}

/// One scratch object per thread of detail::parallel_for(n, 0, ...): both size the team with
/// thread_count(0), so omp_get_thread_num() indexes a slot of its own.
template <class T>
class PerThread {
 public:
  PerThread() : slots_(static_cast<std::size_t>(thread_count(0))) {}
  T& local() { return slots_[static_cast<std::size_t>(omp_get_thread_num())]; }

 private:
  std::vector<T> slots_;
};

/// Union-find root with path halving.
inline int find_root(std::vector<int>& parent, int x) {
  while (parent[static_cast<std::size_t>(x)] != x) {
    parent[static_cast<std::size_t>(x)] =
        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
    x = parent[static_cast<std::size_t>(x)];
  }
  return x;
}

/// Joins the sets of a and b, keeping the smaller root (any rule would do; this one is simple).
inline void unite(std::vector<int>& parent, int a, int b) {
  a = find_root(parent, a);
  b = find_root(parent, b);
  if (a < b) {
    parent[static_cast<std::size_t>(b)] = a;
  } else if (b < a) {
    parent[static_cast<std::size_t>(a)] = b;
  }
}

/// Connected components of faces, where faces sharing a vertex are connected.
struct FaceComponents {
  std::vector<int> face_component;    ///< #F, numbered in order of each component's first face
  std::vector<int> vertex_component;  ///< #V, -1 for vertices in no face
  int count = 0;
};

/// Union-find over vertices (serial: a near-linear pass that costs a few ms per million faces).
/// F must already be validated against vertex_count.
inline FaceComponents face_components(std::int64_t vertex_count, FacesRef F) {
  std::vector<int> parent(static_cast<std::size_t>(vertex_count));
  for (std::size_t v = 0; v < parent.size(); ++v) parent[v] = static_cast<int>(v);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    unite(parent, F(f, 0), F(f, 1));
    unite(parent, F(f, 0), F(f, 2));
  }
  FaceComponents result;
  result.face_component.resize(static_cast<std::size_t>(F.rows()));
  std::vector<int> label(static_cast<std::size_t>(vertex_count), -1);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    int& l = label[static_cast<std::size_t>(find_root(parent, F(f, 0)))];
    if (l < 0) l = result.count++;
    result.face_component[static_cast<std::size_t>(f)] = l;
  }
  // An unreferenced vertex is its own, never labelled root, hence -1.
  result.vertex_component.resize(static_cast<std::size_t>(vertex_count));
  for (std::size_t v = 0; v < parent.size(); ++v) {
    result.vertex_component[v] =
        label[static_cast<std::size_t>(find_root(parent, static_cast<int>(v)))];
  }
  return result;
}

}  // namespace focal::detail
