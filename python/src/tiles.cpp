// focal._focal_ext's functions of focal/tiles/tiles.h, for python/focal/distributed.py: the plan
// of a tiled run (the whole mesh's choices and its tiles), a tile's arrays, a tile's estimate.
#include "focal/tiles/tiles.h"

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/vector.h>

#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "bindings.h"
#include "focal/core/edge_lengths.h"
#include "focal/curvature/estimate.h"
#include "focal/mesh/prepared.h"

namespace focal_python {
namespace {

using namespace nb::literals;
nb::dict choices_dict(const focal::MeshWideChoices& c) {
  nb::dict d;
  d["mean_edge_length"] = c.mean_edge_length;
  if (c.recommended) {
    d["noise"] = c.recommended->noise;
    d["position_noise"] = c.recommended->position_noise;
    d["file_disagreement"] = c.recommended->file_disagreement;
    d["side"] = c.recommended->side;
    d["file_roughness"] = c.recommended->file_roughness;
    d["height_share"] = c.recommended->height_share;
  }
  return d;
}

focal::MeshWideChoices choices_from(const nb::dict& d) {
  focal::MeshWideChoices c;
  c.mean_edge_length = nb::cast<double>(d["mean_edge_length"]);
  if (d.contains("noise")) {
    c.recommended =
        focal::RecommendedMeshWide{.noise = nb::cast<double>(d["noise"]),
                                   .position_noise = nb::cast<double>(d["position_noise"]),
                                   .file_disagreement = nb::cast<double>(d["file_disagreement"]),
                                   .side = nb::cast<double>(d["side"]),
                                   .file_roughness = nb::cast<double>(d["file_roughness"]),
                                   .height_share = nb::cast<double>(d["height_share"])};
  }
  return c;
}

/// The whole mesh's choices and its tiles (partition_mesh with the estimate's reach), with the
/// faces the tiles are cut from when the choices reoriented some.
nb::dict tile_plan(const DoubleRows& V, const IntRows& F, const std::optional<DoubleRows>& N,
                   const nb::dict& options, int tile_vertices) {
  const focal::EstimateOptions o = estimate_options(options);
  focal::MeshWideChoices choices;
  focal::Tiling tiling;
  {
    nb::gil_scoped_release release;
    const focal::ExecutionScope scope(o.execution);
    const focal::PreparedMesh mesh(view(V), view(F), normals_ref(N));
    choices = focal::mesh_wide_choices(mesh, o);
    const focal::FacesRef faces = choices.F ? focal::FacesRef(*choices.F) : mesh.F();
    tiling = focal::partition_mesh(mesh.V(), faces,
                                   focal::estimate_reach(focal::options_for_part(o, choices)),
                                   {.tile_vertices = tile_vertices});
  }
  nb::list tiles;
  for (const focal::Tile& t : tiling.tiles) {
    nb::dict d;
    d["vertices"] = ids_to_numpy(t.vertices);
    d["faces"] = ids_to_numpy(t.faces);
    d["owned"] = ids_to_numpy(t.owned);
    tiles.append(d);
  }
  nb::dict d;
  d["choices"] = choices_dict(choices);
  d["halo_rings"] = tiling.halo_rings;
  d["F"] = optional_to_numpy(std::move(choices.F));
  d["tiles"] = tiles;
  return d;
}

nb::dict extract_tile(const DoubleRows& V, const IntRows& F, const std::optional<DoubleRows>& N,
                      const Ids& vertices, const Ids& faces) {
  const focal::Tile tile{ids_from(vertices), ids_from(faces), {}};
  focal::TileMesh t;
  {
    nb::gil_scoped_release release;
    t = focal::extract_tile(view(V), view(F), normals_ref(N), tile);
  }
  nb::dict d;
  d["V"] = to_numpy(std::move(t.V));
  d["F"] = to_numpy(std::move(t.F));
  d["N"] = optional_to_numpy(std::move(t.N));
  return d;
}

/// A tile's arrays as the library's TileMesh (the normals copied, when given).
focal::TileMesh tile_of(const DoubleRows& V, const IntRows& F, const std::optional<DoubleRows>& N) {
  focal::TileMesh tile{view(V), view(F), std::nullopt};
  if (N) tile.N = focal::RowMatrixX3d(view(*N));
  return tile;
}

/// The estimate of every vertex of a tile, with the whole mesh's choices.
nb::dict estimate_tile(const DoubleRows& V, const IntRows& F, const std::optional<DoubleRows>& N,
                       const nb::dict& options, const nb::dict& choices) {
  const focal::EstimateOptions o = estimate_options(options);
  const focal::MeshWideChoices c = choices_from(choices);
  focal::TileEstimate r;
  {
    nb::gil_scoped_release release;
    const focal::ExecutionScope scope(o.execution);
    const focal::TileMesh tile = tile_of(V, F, N);
    r = focal::estimate_tile(tile, c, o);
  }
  nb::dict d = curvature_dict(std::move(r.curvature));
  d["crease"] = crease_or_none(std::move(r.crease));
  return d;
}

/// The recommended estimator's statistics of a tile's owned rows (focal::tile_statistics), for
/// the streamed plan (focal/stream.py): the per-row values of the medians and the counts.
nb::dict tile_statistics(const DoubleRows& V, const IntRows& F, const std::optional<DoubleRows>& N,
                         const Ids& ids, const Ids& owned, std::int64_t whole_vertex_count,
                         const nb::dict& options, double mean_edge_length) {
  const focal::EstimateOptions o = estimate_options(options);
  focal::RecommendedStatistics r;
  {
    nb::gil_scoped_release release;
    const focal::ExecutionScope scope(o.execution);
    const focal::TileMesh tile = tile_of(V, F, N);
    r = focal::tile_statistics(tile, ids_from(ids), ids_from(owned), whole_vertex_count,
                               mean_edge_length, o);
  }
  nb::dict d;
  d["jet_residual"] = to_numpy(std::move(r.jet_residual));
  d["angle_along"] = to_numpy(std::move(r.angle_along));
  d["angle_against"] = to_numpy(std::move(r.angle_against));
  d["file_roughness"] = to_numpy(std::move(r.file_roughness));
  d["height_share"] = to_numpy(std::move(r.height_share));
  d["along"] = r.along;
  d["against"] = r.against;
  d["sample"] = ids_to_numpy(r.sample);
  d["sample_noise"] = to_numpy(std::move(r.sample_noise));
  return d;
}

/// The whole mesh's choices from the medians and counts over all tiles' statistics
/// (focal::recommended_mesh_wide_from), as tile_plan's "choices".
nb::dict recommended_choices(const nb::dict& medians, double mean_edge_length) {
  focal::RecommendedMedians m;
  m.jet_residual = nb::cast<double>(medians["jet_residual"]);
  const auto noise = nb::cast<std::vector<double>>(medians["sample_noise"]);
  m.sample_noise = Eigen::Map<const Eigen::VectorXd>(noise.data(), std::ssize(noise));
  m.along = nb::cast<std::int64_t>(medians["along"]);
  m.against = nb::cast<std::int64_t>(medians["against"]);
  m.angle_along = nb::cast<double>(medians["angle_along"]);
  m.angle_against = nb::cast<double>(medians["angle_against"]);
  m.file_roughness = nb::cast<double>(medians["file_roughness"]);
  m.height_share = nb::cast<double>(medians["height_share"]);
  m.has_normals = nb::cast<bool>(medians["has_normals"]);
  focal::MeshWideChoices c;
  c.mean_edge_length = mean_edge_length;
  c.recommended = focal::recommended_mesh_wide_from(m, mean_edge_length);
  return choices_dict(c);
}

/// focal::ids_in of int32 ids of any shape (C order): a bool array of x's shape.
nb::ndarray<nb::numpy, bool> ids_in(
    const nb::ndarray<const std::int32_t, nb::c_contig, nb::device::cpu>& x, const Ids& ascending,
    int threads) {
  std::vector<char> in;
  {
    nb::gil_scoped_release release;
    const focal::ExecutionScope scope({.threads = threads});
    in = focal::ids_in(std::span<const int>(x.data(), x.size()),
                       std::span<const int>(ascending.data(), ascending.shape(0)));
  }
  auto* data = new bool[in.size()];
  for (std::size_t i = 0; i < in.size(); ++i) data[i] = in[i] != 0;
  nb::capsule owner(data, [](void* p) noexcept { delete[] static_cast<bool*>(p); });
  std::vector<std::size_t> shape(x.ndim());
  for (std::size_t d = 0; d < x.ndim(); ++d) shape[d] = x.shape(d);
  return nb::ndarray<nb::numpy, bool>(data, x.ndim(), shape.data(), owner);
}

/// mean_edge_length's partial sums of a run of whole blocks of faces (focal/core/mesh.h), for
/// the streaming reader (focal/stream.py): (sums, counts) per block of edge_length_block() faces.
nb::tuple edge_length_sums(const DoubleRows& V, const IntRows& F, int threads) {
  focal::EdgeLengthSums s;
  {
    nb::gil_scoped_release release;
    const focal::RowMatrixX3d no_normals;
    const focal::ExecutionScope scope({.threads = threads});
    focal::validate_mesh_arrays(view(V), view(F), no_normals, "edge_length_sums");
    s = focal::edge_length_sums(view(V), view(F));
  }
  const auto n = static_cast<Eigen::Index>(s.sums.size());
  return nb::make_tuple(
      to_numpy(Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(s.sums.data(), n))),
      to_numpy(Eigen::Matrix<std::int64_t, Eigen::Dynamic, 1>(
          Eigen::Map<const Eigen::Matrix<std::int64_t, Eigen::Dynamic, 1>>(s.counts.data(), n))));
}

}  // namespace

void bind_tiles(nb::module_& m) {
  m.def("tile_plan", &tile_plan, "V"_a.noconvert(), "F"_a.noconvert(), "N"_a.none().noconvert(),
        "options"_a, "tile_vertices"_a);
  m.def("extract_tile", &extract_tile, "V"_a.noconvert(), "F"_a.noconvert(),
        "N"_a.none().noconvert(), "vertices"_a.noconvert(), "faces"_a.noconvert());
  m.def("estimate_tile", &estimate_tile, "V"_a.noconvert(), "F"_a.noconvert(),
        "N"_a.none().noconvert(), "options"_a, "choices"_a);
  m.def("edge_length_sums", &edge_length_sums, "V"_a.noconvert(), "F"_a.noconvert(), "threads"_a);
  m.def("edge_length_block", [] { return focal::kEdgeLengthBlock; });
  m.def("tile_statistics", &tile_statistics, "V"_a.noconvert(), "F"_a.noconvert(),
        "N"_a.none().noconvert(), "ids"_a.noconvert(), "owned"_a.noconvert(),
        "whole_vertex_count"_a, "options"_a, "mean_edge_length"_a);
  m.def("recommended_choices", &recommended_choices, "medians"_a, "mean_edge_length"_a);
  m.def("ids_in", &ids_in, "x"_a.noconvert(), "ascending"_a.noconvert(), "threads"_a);
  m.def("statistics_reach", [] { return focal::kRecommendedStatisticsReach; });
  m.def(
      "estimate_reach",
      [](const nb::dict& options, const std::optional<nb::dict>& choices) {
        const focal::EstimateOptions o = estimate_options(options);
        if (!choices) return focal::estimate_reach(o);
        return focal::estimate_reach(focal::options_for_part(o, choices_from(*choices)));
      },
      "options"_a, "choices"_a = nb::none());
}

}  // namespace focal_python
