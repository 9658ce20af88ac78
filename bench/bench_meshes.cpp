#include "bench_meshes.h"

#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>

#include "focal/io/mesh_io.h"
#include "focal/surfaces/surfaces.h"

namespace focal::bench {

namespace {

std::filesystem::path cache_dir() {
  const char* dir = std::getenv("FOCAL_BENCH_DATA");
  return dir != nullptr ? dir : "build/bench-data";
}

}  // namespace

const Mesh& torus(int vertices) {
  static std::map<int, Mesh> meshes;
  if (auto it = meshes.find(vertices); it != meshes.end()) return it->second;
  const auto path = cache_dir() / ("torus-" + std::to_string(vertices) + ".ply");
  Mesh mesh;
  if (std::filesystem::exists(path)) {
    mesh = read_mesh(path);
  } else {
    SurfaceOptions o;
    o.kind = SurfaceKind::torus;
    o.target_vertices = vertices;
    mesh = make_surface(o).mesh;
    std::filesystem::create_directories(cache_dir());
    write_ply(path, mesh);
  }
  return meshes.emplace(vertices, std::move(mesh)).first->second;
}

const Mesh* bunny() {
  static const Mesh* cached = []() -> const Mesh* {
    const auto path = cache_dir() / "bunny.off";
    if (!std::filesystem::exists(path)) {
      // The scan run_bench.sh uses: Debian's libcgal-demo ships it inside a tarball.
      std::filesystem::create_directories(cache_dir());
      const std::string extract =
          "tar -xzf /usr/share/doc/libcgal-dev/data.tar.gz -O data/meshes/bunny00.off > '" +
          path.string() + "' 2>/dev/null";
      if (std::system(extract.c_str()) != 0) {
        std::filesystem::remove(path);
        return nullptr;
      }
    }
    static Mesh mesh = read_mesh(path);
    return &mesh;
  }();
  return cached;
}

}  // namespace focal::bench
