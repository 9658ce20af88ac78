// focal._focal_ext's streamed input, for python/focal/stream.py: a binary PLY triangle mesh read by
// record ranges and sets (focal::PlyTriangleReader, focal/io/mesh_io.h) and the grid that gives
// a vertex its tile from its position (focal/tiles/tiles.h, "Streamed tiles").
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "focal/io/mesh_io.h"
#include "focal/tiles/tiles.h"

namespace focal_python {
namespace {

using namespace nb::literals;
using focal::PlyTriangleReader;
using Box = std::array<double, 3>;

std::span<const int> ids_view(const Ids& ids) {
  return {ids.data(), static_cast<std::size_t>(ids.shape(0))};
}

focal::TileGridBox box_of(const Box& lo, const Box& hi) {
  focal::TileGridBox box;
  box.lo = Eigen::Vector3d(lo[0], lo[1], lo[2]);
  box.hi = Eigen::Vector3d(hi[0], hi[1], hi[2]);
  return box;
}

nb::object int32_array(const std::vector<std::int32_t>& v) { return ids_to_numpy(v); }

/// A read of the reader with the GIL released, its matrix handed to NumPy.
template <class Read>
auto released(const Read& read) {
  decltype(read()) out;
  {
    nb::gil_scoped_release release;
    out = read();
  }
  return to_numpy(std::move(out));
}

}  // namespace

void bind_streaming(nb::module_& m) {
  nb::class_<PlyTriangleReader>(m, "PlyTriangleReader")
      .def(
          "__init__",
          [](PlyTriangleReader* self, const std::string& path) {
            new (self) PlyTriangleReader(path);
          },
          "path"_a)
      .def_prop_ro("path", [](const PlyTriangleReader& r) { return r.path().string(); })
      .def_prop_ro("vertex_count", &PlyTriangleReader::vertex_count)
      .def_prop_ro("face_count", &PlyTriangleReader::face_count)
      .def_prop_ro("has_normals", &PlyTriangleReader::has_normals)
      .def(
          "positions",
          [](const PlyTriangleReader& r, std::int64_t begin, std::int64_t end) {
            return released([&] { return r.positions(begin, end); });
          },
          "begin"_a, "end"_a)
      .def(
          "positions",
          [](const PlyTriangleReader& r, const Ids& ids) {
            return released([&] { return r.positions(ids_view(ids)); });
          },
          "ids"_a.noconvert())
      .def(
          "normals",
          [](const PlyTriangleReader& r, std::int64_t begin, std::int64_t end) {
            return released([&] { return r.normals(begin, end); });
          },
          "begin"_a, "end"_a)
      .def(
          "normals",
          [](const PlyTriangleReader& r, const Ids& ids) {
            return released([&] { return r.normals(ids_view(ids)); });
          },
          "ids"_a.noconvert())
      .def(
          "faces",
          [](const PlyTriangleReader& r, std::int64_t begin, std::int64_t end) {
            return released([&] { return r.faces(begin, end); });
          },
          "begin"_a, "end"_a);

  m.def("tile_grid_cell_count", [] { return focal::kTileGridCells; });
  m.def(
      "tile_grid_box",
      [](const DoubleRows& P, const Box& lo, const Box& hi) {
        focal::TileGridBox box;
        {
          nb::gil_scoped_release release;
          box = focal::grow_tile_grid_box(box_of(lo, hi), view(P));
        }
        return std::make_pair(Box{box.lo[0], box.lo[1], box.lo[2]},
                              Box{box.hi[0], box.hi[1], box.hi[2]});
      },
      "P"_a.noconvert(), "lo"_a, "hi"_a);
  m.def(
      "tile_grid_cells",
      [](const DoubleRows& P, const Box& lo, const Box& hi, int threads) {
        std::vector<std::int32_t> cells;
        {
          nb::gil_scoped_release release;
          const focal::ExecutionScope scope({.threads = threads});
          cells = focal::tile_grid_cells(view(P), box_of(lo, hi));
        }
        return int32_array(cells);
      },
      "P"_a.noconvert(), "lo"_a, "hi"_a, "threads"_a);
  m.def(
      "cut_tile_grid",
      [](const nb::ndarray<const std::int64_t, nb::ndim<1>, nb::c_contig, nb::device::cpu>& counts,
         int tile_vertices) {
        const focal::TileGrid grid = focal::cut_tile_grid(
            std::span<const std::int64_t>(counts.data(), counts.shape(0)), tile_vertices);
        return std::make_pair(int32_array(grid.cell_tile), grid.tile_count);
      },
      "counts"_a.noconvert(), "tile_vertices"_a);
  m.def(
      "tile_grid_tiles",
      [](const DoubleRows& P, const Box& lo, const Box& hi, const Ids& cell_tile, int threads) {
        std::vector<std::int32_t> tiles;
        {
          nb::gil_scoped_release release;
          const focal::ExecutionScope scope({.threads = threads});
          tiles = focal::tile_grid_tiles(view(P), box_of(lo, hi), ids_view(cell_tile));
        }
        return int32_array(tiles);
      },
      "P"_a.noconvert(), "lo"_a, "hi"_a, "cell_tile"_a.noconvert(), "threads"_a);
}

}  // namespace focal_python
