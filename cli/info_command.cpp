#include <cmath>
#include <cstdio>
#include <memory>

#include "commands.h"
#include "estimator_flags.h"
#include "focal/io/mesh_io.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/orientation.h"
#include "focal/points/neighbours.h"

namespace focal::cli {
namespace {

struct InfoFlags {
  std::string path;
  ReadOptions read;
};

void print_cloud_info(const std::string& path, const Mesh& cloud) {
  const Neighbourhoods nearest = nearest_neighbours(cloud.V, 1);
  int non_finite = 0;
  for (Eigen::Index i = 0; i < cloud.V.rows(); ++i)
    non_finite += cloud.V.row(i).allFinite() ? 0 : 1;
  const Eigen::Index n = cloud.V.rows();
  std::printf("file:                 %s\n", path.c_str());
  std::printf("type:                 point cloud (no faces)\n");
  std::printf("points:               %lld (%d non-finite)\n", static_cast<long long>(n),
              non_finite);
  // Bounds of the finite points only, as mesh_statistics gives a mesh's.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!cloud.V.row(i).allFinite()) continue;
    lo = lo.cwiseMin(cloud.V.row(i).transpose()), hi = hi.cwiseMax(cloud.V.row(i).transpose());
  }
  if (non_finite == n) lo.setZero(), hi.setZero();
  std::printf("bounds:               [%g, %g, %g] - [%g, %g, %g]\n", lo.x(), lo.y(), lo.z(), hi.x(),
              hi.y(), hi.z());
  std::printf("mean spacing:         %g (mean distance to the nearest other point)\n",
              mean_spacing(cloud.V, nearest));
  std::printf("normals:              %s\n", cloud.has_normals() ? "present" : "none");
}

void print_info(const InfoFlags& f, const Log& log) {
  const std::string& path = f.path;
  Mesh mesh;
  {
    Stage stage(log, "read");
    mesh = read_mesh(path, f.read);
  }
  if (mesh.is_cloud()) return print_cloud_info(path, mesh);
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
  cmd->add_option("input", f->path,
                  "mesh or point cloud (.obj .ply .off .stl .xyz .xyzn .xyzrgb .pwn .pts .txt .csv "
                  ".pcd .las)")
      ->required();
  add_read_flags(*cmd, f->read);
  cmd->footer("Example:\n  focal info bunny.off");
  cmd->callback([f, &log] { print_info(*f, log); });
}

}  // namespace focal::cli
