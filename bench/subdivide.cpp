// focal_subdivide IN OUT.ply LEVELS: midpoint subdivision (each triangle into four, a new vertex
// at every edge midpoint), to scale a real scan such as the bunny to benchmark sizes (x4
// vertices per level). The surface keeps its shape exactly (new faces are flat pieces of the
// old ones); normals are left out, so `focal curvature` estimates them from the faces as it
// does for the scan itself. Vertex v of the input stays vertex v.

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "focal/io/mesh_io.h"
#include "focal/mesh/neighbourhood.h"

namespace {

using focal::Mesh;
using focal::Neighbourhoods;

// Edge {a, b} with a < b is numbered by its position among the higher neighbours of a.
struct EdgeIndex {
  Neighbourhoods adjacency;
  Eigen::VectorXi first;  // #V + 1: the number of edges owned by lower vertices

  int of(int a, int b) const {
    if (a > b) std::swap(a, b);
    const int* up = std::upper_bound(adjacency.begin(a), adjacency.end(a), a);
    const int* at = std::lower_bound(up, adjacency.end(a), b);
    return first[a] + static_cast<int>(at - up);
  }
};

EdgeIndex index_edges(const Mesh& m) {
  EdgeIndex e{focal::vertex_adjacency(static_cast<int>(m.V.rows()), m.F), {}};
  e.first.resize(m.V.rows() + 1);
  e.first[0] = 0;
  for (int a = 0; a < m.V.rows(); ++a) {
    const int* up = std::upper_bound(e.adjacency.begin(a), e.adjacency.end(a), a);
    e.first[a + 1] = e.first[a] + static_cast<int>(e.adjacency.end(a) - up);
  }
  return e;
}

Mesh subdivide(const Mesh& m) {
  const EdgeIndex edges = index_edges(m);
  const auto n = static_cast<int>(m.V.rows());
  Mesh out;
  out.V.resize(n + edges.first[n], 3);
  out.V.topRows(n) = m.V;
  out.F.resize(4 * m.F.rows(), 3);
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    int mid[3];
    for (int c = 0; c < 3; ++c) {
      const int a = m.F(f, c), b = m.F(f, (c + 1) % 3);
      mid[c] = n + edges.of(a, b);
      out.V.row(mid[c]) = 0.5 * (m.V.row(a) + m.V.row(b));
    }
    out.F.row(4 * f + 0) << m.F(f, 0), mid[0], mid[2];
    out.F.row(4 * f + 1) << mid[0], m.F(f, 1), mid[1];
    out.F.row(4 * f + 2) << mid[2], mid[1], m.F(f, 2);
    out.F.row(4 * f + 3) << mid[0], mid[1], mid[2];
  }
  out.face_source = Eigen::VectorXi::LinSpaced(out.F.rows(), 0, static_cast<int>(out.F.rows()) - 1);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: focal_subdivide IN OUT.ply LEVELS\n");
    return 1;
  }
  try {
    Mesh mesh = focal::read_mesh(argv[1]);
    mesh.N.resize(0, 3);
    for (int level = std::atoi(argv[3]); level > 0; --level) mesh = subdivide(mesh);
    focal::write_ply(argv[2], mesh);
    std::printf("wrote %s: %lld vertices, %lld triangles\n", argv[2],
                static_cast<long long>(mesh.V.rows()), static_cast<long long>(mesh.F.rows()));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "Error: %s\n", e.what());
    return 2;
  }
  return 0;
}
