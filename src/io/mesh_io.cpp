// read_mesh and write_mesh: the format named by the file extension picks the reader or writer.

#include "focal/io/mesh_io.h"

#include <cmath>

#include "focal/core/error.h"
#include "io/file_bytes.h"
#include "io/format_readers.h"

namespace focal {

MeshFormat mesh_format_from_path(const std::filesystem::path& path) {
  const std::string ext = io_detail::to_lower(path.extension().string());
  if (ext == ".obj") return MeshFormat::obj;
  if (ext == ".ply") return MeshFormat::ply;
  if (ext == ".off") return MeshFormat::off;
  if (ext == ".stl") return MeshFormat::stl;
  if (ext == ".xyz" || ext == ".xyzn" || ext == ".xyzrgb" || ext == ".pwn" || ext == ".pts" ||
      ext == ".txt" || ext == ".csv")
    return MeshFormat::xyz;
  if (ext == ".pcd") return MeshFormat::pcd;
  if (ext == ".las" || ext == ".laz") return MeshFormat::las;
  io_detail::fail(path, "unknown mesh format '" + path.extension().string() +
                            "' (expected .obj, .ply, .off, .stl, or .xyz .xyzn .xyzrgb .pwn .pts "
                            ".txt .csv .pcd .las for point clouds)");
}

Mesh read_mesh(const std::filesystem::path& path, const ReadOptions& options) {
  switch (mesh_format_from_path(path)) {
    case MeshFormat::obj:
      return io_detail::read_obj(path, 0);
    case MeshFormat::ply:
      return io_detail::read_ply(path, 0);
    case MeshFormat::off:
      return io_detail::read_off(path, 0);
    case MeshFormat::stl: {
      if (!(options.weld_tolerance >= 0.0) || !std::isfinite(options.weld_tolerance)) {
        throw InvalidInput("read_mesh: weld_tolerance must be finite and >= 0");
      }
      Mesh mesh = io_detail::read_stl(path, 0);
      io_detail::weld_corners(mesh, options.weld_tolerance, options.weld, 0);
      return mesh;
    }
    case MeshFormat::xyz:
      return io_detail::read_xyz(path);
    case MeshFormat::pcd:
      return io_detail::read_pcd(path);
    case MeshFormat::las:
      return io_detail::read_las(path);
  }
  io_detail::fail(path, "unknown mesh format");
}

void write_mesh(const std::filesystem::path& path, const Mesh& mesh, const WriteOptions& options) {
  switch (mesh_format_from_path(path)) {
    case MeshFormat::ply:
      write_ply(path, mesh, {}, {.binary = true, .comments = {}, .precision = options.precision});
      return;
    case MeshFormat::obj:
      write_obj(path, mesh, options);
      return;
    case MeshFormat::off:
      write_off(path, mesh, options);
      return;
    case MeshFormat::xyz:
      write_xyz(path, mesh, options);
      return;
    case MeshFormat::pcd:
    case MeshFormat::las:
      io_detail::fail(path, "writing " + path.extension().string() +
                                " is not supported (use .ply, or .xyz / .xyzn)");
    case MeshFormat::stl:
      break;
  }
  // STL cannot hold shared vertices, so writing it would lose the vertex order the library
  // promises; the formats above keep it.
  io_detail::fail(path, "writing STL is not supported (use .ply, .obj or .off)");
}

}  // namespace focal
