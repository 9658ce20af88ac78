#include <cstdio>
#include <memory>

#include "commands.h"
#include "estimator_flags.h"
#include "focal/io/mesh_io.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/normals.h"

namespace focal::cli {
namespace {

struct InfoFlags {
  std::string path;
  ReadOptions read;
};

void print_info(const InfoFlags& f, const Log& log) {
  const std::string& path = f.path;
  Mesh mesh;
  {
    Stage stage(log, "read");
    mesh = read_mesh(path, f.read);
  }
  const MeshStatistics s = mesh_statistics(mesh.V, mesh.F);
  const OrientationReport orientation = orientation_report(mesh.V, mesh.F);
  std::printf("file:                 %s\n", path.c_str());
  std::printf("vertices:             %d\n", s.vertex_count);
  if (mesh.corner_vertex.size() > 0) {
    std::printf("STL corners:          %lld (welded into the vertices above)\n",
                static_cast<long long>(mesh.corner_vertex.size()));
  }
  std::printf("triangles:            %d (from %d input faces)\n", s.face_count,
              mesh.face_source.size() > 0 ? mesh.face_source.maxCoeff() + 1 : 0);
  std::printf("edges:                %d (boundary %d, non-manifold %d)\n", s.edge_count,
              s.boundary_edge_count, s.non_manifold_edge_count);
  std::printf("non-manifold vertices: %d\n", s.non_manifold_vertex_count);
  std::printf("unreferenced vertices: %d\n", s.unreferenced_vertex_count);
  std::printf("degenerate triangles: %d, duplicate triangles: %d\n", s.degenerate_face_count,
              s.duplicate_face_count);
  std::printf("components:           %d (%d inward)\n", s.component_count,
              orientation.inward_count());
  std::printf("bounds:               [%g, %g, %g] - [%g, %g, %g]\n", s.min_corner.x(),
              s.min_corner.y(), s.min_corner.z(), s.max_corner.x(), s.max_corner.y(),
              s.max_corner.z());
  std::printf("mean edge length:     %g\n", s.mean_edge_length);
  std::printf("vertex normals:       %s\n", mesh.has_normals() ? "present" : "none");
}

}  // namespace

void add_info_command(CLI::App& app, const Log& log) {
  auto* cmd = app.add_subcommand("info", "Counts, bounds and connectivity statistics of a mesh");
  auto f = std::make_shared<InfoFlags>();
  cmd->add_option("input", f->path, "mesh file (.obj .ply .off .stl)")->required();
  add_read_flags(*cmd, f->read);
  cmd->footer("Example:\n  focal info bunny.off");
  cmd->callback([f, &log] { print_info(*f, log); });
}

}  // namespace focal::cli
