#include "focal/tiles/tiles.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <numeric>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "core/result_rows.h"
#include "core/spatial_order.h"
#include "focal/core/error.h"
#include "mesh/topology.h"

namespace focal {
namespace {

/// Sorts non-negative ids ascending: two passes of a counting sort on 16-bit digits, linear in
/// the ids of a tile (hundreds of thousands), which a comparison sort is not.
void sort_ids(std::vector<int>& ids) {
  constexpr int kDigitBits = 16;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigitBits;
  if (ids.size() < 4096) {
    std::sort(ids.begin(), ids.end());
    return;
  }
  std::vector<int> scratch(ids.size());
  std::vector<std::size_t> start(kBuckets + 1);
  for (int shift : {0, kDigitBits}) {
    std::fill(start.begin(), start.end(), 0);
    for (int id : ids) ++start[((static_cast<std::uint32_t>(id) >> shift) & (kBuckets - 1)) + 1];
    for (std::size_t b = 1; b <= kBuckets; ++b) start[b] += start[b - 1];
    for (int id : ids)
      scratch[start[(static_cast<std::uint32_t>(id) >> shift) & (kBuckets - 1)]++] = id;
    ids.swap(scratch);
  }
}

/// The tile's vertices (those reached, sorted) and the rows of its owned ones (ascending).
void set_vertices(Tile& tile, std::vector<int> reached, const std::vector<int>& owned_ids) {
  tile.vertices = std::move(reached);
  sort_ids(tile.vertices);
  tile.owned.reserve(owned_ids.size());
  // Both ascending: one walk finds each owned vertex's row.
  std::size_t row = 0;
  for (int v : owned_ids) {
    while (tile.vertices[row] != v) ++row;
    tile.owned.push_back(static_cast<int>(row));
  }
}

/// Marks of one search, per vertex or face: `mark[i] == stamp` means i was reached by the search
/// of that stamp, so the marks are never cleared between tiles.
struct Marks {
  std::vector<int> vertex, face;
};

/// The tile owning `owned` (global ids, ascending): ring by ring, the faces of the vertices
/// found so far and those faces' corners, halo_rings times. Round r takes the faces of the
/// vertices r - 1 rings out, so the faces are those with a corner within halo_rings - 1 rings
/// and the vertices are those within halo_rings rings; each vertex and face is visited once.
Tile make_tile(std::vector<int> owned_ids, FacesRef F, const detail::VertexFaces& inc,
               int halo_rings, int stamp, Marks& marks) {
  std::vector<int> reached = owned_ids;
  for (int v : reached) marks.vertex[static_cast<std::size_t>(v)] = stamp;
  Tile tile;
  std::size_t ring_begin = 0;
  for (int ring = 1; ring <= halo_rings; ++ring) {
    const std::size_t ring_end = reached.size();
    for (std::size_t k = ring_begin; k < ring_end; ++k) {
      const int v = reached[k];
      for (int j = inc.begin(v); j < inc.end(v); ++j) {
        const int f = inc.faces[static_cast<std::size_t>(j)];
        int& face_mark = marks.face[static_cast<std::size_t>(f)];
        if (face_mark == stamp) continue;  // its corners are marked already
        face_mark = stamp;
        tile.faces.push_back(f);
        detail::for_each_distinct_corner(F, f, [&](int w) {
          int& m = marks.vertex[static_cast<std::size_t>(w)];
          if (m != stamp) {
            m = stamp;
            reached.push_back(w);
          }
        });
      }
    }
    ring_begin = ring_end;
  }
  sort_ids(tile.faces);
  set_vertices(tile, std::move(reached), owned_ids);
  return tile;
}

/// The cloud tile owning `owned_ids` (ascending): the points within `depth` links of them.
Tile make_cloud_tile(std::vector<int> owned_ids, const Neighbourhoods& neighbours, int depth,
                     int stamp, std::vector<int>& mark) {
  std::vector<int> reached = owned_ids;
  for (int v : reached) mark[static_cast<std::size_t>(v)] = stamp;
  std::size_t begin = 0;
  for (int step = 1; step <= depth; ++step) {
    const std::size_t end = reached.size();
    for (std::size_t k = begin; k < end; ++k) {
      for (const int* j = neighbours.begin(reached[k]); j != neighbours.end(reached[k]); ++j) {
        int& m = mark[static_cast<std::size_t>(*j)];
        if (m != stamp) {
          m = stamp;
          reached.push_back(*j);
        }
      }
    }
    begin = end;
  }
  Tile tile;
  set_vertices(tile, std::move(reached), owned_ids);
  return tile;
}

/// Consecutive runs of `step` vertices of `order`, each sorted, handed to make(t, owned, slot)
/// in parallel; `slot` is the worker's.
template <class Make>
void for_each_tile_of(const std::vector<int>& order, std::size_t step, int threads,
                      std::vector<Tile>& tiles, const Make& make) {
  tiles.resize((order.size() + step - 1) / step);
  detail::parallel_chunks(static_cast<std::int64_t>(tiles.size()), threads, [&](std::int64_t t) {
    const std::size_t first = static_cast<std::size_t>(t) * step;
    const std::size_t last = std::min(order.size(), first + step);
    std::vector<int> owned(order.begin() + static_cast<std::ptrdiff_t>(first),
                           order.begin() + static_cast<std::ptrdiff_t>(last));
    sort_ids(owned);
    tiles[static_cast<std::size_t>(t)] = make(static_cast<int>(t), std::move(owned));
  });
}

void check_ids(const std::vector<int>& ids, Eigen::Index size, const char* what) {
  for (int i : ids) {
    if (i < 0 || i >= size) {
      throw InvalidInput(std::string("extract_tile: ") + what + " " + std::to_string(i) +
                         " is out of range [0, " + std::to_string(size) + ")");
    }
  }
}

}  // namespace

Tiling partition_mesh(PositionsRef V, FacesRef F, int halo_rings, const TileOptions& options) {
  if (halo_rings < 1) throw InvalidInput("partition_mesh: halo_rings must be >= 1");
  if (options.tile_vertices < 1) throw InvalidInput("partition_mesh: tile_vertices must be >= 1");
  detail::check_face_indices(V.rows(), F, "partition_mesh");
  const detail::VertexFaces inc = detail::vertex_face_incidence(V.rows(), F, 0);
  const std::vector<int> order = detail::morton_order(V, 0);
  Tiling out;
  out.halo_rings = halo_rings;
  // Tiles in parallel, each thread with its own marks (a tile's stamp is its index, so marks
  // are never cleared): 8 bytes per vertex and face per thread, allocated on first use.
  std::vector<std::unique_ptr<Marks>> marks(static_cast<std::size_t>(detail::thread_count(0)));
  for_each_tile_of(order, static_cast<std::size_t>(options.tile_vertices), 0, out.tiles,
                   [&](int t, std::vector<int> owned) {
                     auto& m = marks[static_cast<std::size_t>(detail::worker_slot())];
                     if (!m) {
                       m = std::make_unique<Marks>(
                           Marks{std::vector<int>(order.size(), -1),
                                 std::vector<int>(static_cast<std::size_t>(F.rows()), -1)});
                     }
                     return make_tile(std::move(owned), F, inc, halo_rings, t, *m);
                   });
  return out;
}

TileMesh extract_tile(PositionsRef V, FacesRef F, std::optional<NormalsRef> N, const Tile& tile) {
  check_ids(tile.vertices, V.rows(), "vertex");
  check_ids(tile.faces, F.rows(), "face");
  TileMesh out;
  const auto n = static_cast<Eigen::Index>(tile.vertices.size());
  out.V.resize(n, 3);
  if (N) out.N.emplace(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    out.V.row(i) = V.row(tile.vertices[static_cast<std::size_t>(i)]);
    if (N) out.N->row(i) = N->row(tile.vertices[static_cast<std::size_t>(i)]);
  }
  // Global id -> tile row, written only at the tile's vertices: the untouched rest of the
  // table is never read (a lookup is checked against tile.vertices), so its pages stay unmapped.
  const auto local = std::make_unique_for_overwrite<int[]>(static_cast<std::size_t>(V.rows()));
  for (std::size_t i = 0; i < tile.vertices.size(); ++i) {
    local[static_cast<std::size_t>(tile.vertices[i])] = static_cast<int>(i);
  }
  out.F.resize(static_cast<Eigen::Index>(tile.faces.size()), 3);
  for (Eigen::Index f = 0; f < out.F.rows(); ++f) {
    const int face = tile.faces[static_cast<std::size_t>(f)];
    for (int c = 0; c < 3; ++c) {
      const int v = F(face, c);
      const int i = local[static_cast<std::size_t>(v)];
      if (i < 0 || i >= n || tile.vertices[static_cast<std::size_t>(i)] != v) {
        throw InvalidInput("extract_tile: face " + std::to_string(face) + " has corner " +
                           std::to_string(v) + ", which is not in the tile");
      }
      out.F(f, c) = i;
    }
  }
  return out;
}

TileEstimate estimate_tile(const TileMesh& tile, const MeshWideChoices& choices,
                           const EstimateOptions& options) {
  const std::optional<NormalsRef> N =
      tile.N ? std::optional<NormalsRef>(*tile.N) : std::optional<NormalsRef>();
  const PreparedMesh mesh(tile.V, tile.F, N, {.mean_edge_length = choices.mean_edge_length});
  Estimate e = estimate(mesh, options_for_part(options, choices));
  return {std::move(e.curvature), std::move(e.crease)};
}

std::vector<char> ids_in(std::span<const int> x, std::span<const int> ascending) {
  std::vector<char> out(x.size(), 0);
  if (ascending.empty() || x.empty()) return out;
  for (std::size_t k = 1; k < ascending.size(); ++k) {
    if (ascending[k] < ascending[k - 1]) {
      throw InvalidInput("ids_in: the set is not ascending at " + std::to_string(k));
    }
  }
  const int lo = ascending.front(), hi = ascending.back();
  if (lo < 0) throw InvalidInput("ids_in: ids must be >= 0, got " + std::to_string(lo));
  // One bit per id of the span [lo, hi]: the lookups are the cost (millions per halo round).
  const auto span = static_cast<std::size_t>(hi - lo) + 1;
  std::vector<std::uint64_t> bits((span + 63) / 64, 0);
  for (const int id : ascending) {
    const auto b = static_cast<std::size_t>(id - lo);
    bits[b / 64] |= std::uint64_t{1} << (b % 64);
  }
  detail::parallel_for(static_cast<std::int64_t>(x.size()), 0, [&](std::int64_t i) {
    const int v = x[static_cast<std::size_t>(i)];
    if (v < lo || v > hi) return;
    const auto b = static_cast<std::size_t>(v - lo);
    out[static_cast<std::size_t>(i)] = static_cast<char>((bits[b / 64] >> (b % 64)) & 1);
  });
  return out;
}

RecommendedStatistics tile_statistics(const TileMesh& tile, const std::vector<int>& ids,
                                      const std::vector<int>& owned,
                                      Eigen::Index whole_vertex_count, double mean_edge_length,
                                      const EstimateOptions& options) {
  if (options.estimator != Estimator::recommended) {
    throw InvalidInput("tile_statistics: measures the recommended estimator's choices only");
  }
  if (!tile.N ||
      (options.normals != NormalsSource::automatic && options.normals != NormalsSource::file)) {
    throw InvalidInput(
        "tile_statistics: needs the mesh's own normals (nx, ny, nz): without them the "
        "recommended estimate orients the faces of closed components over the whole mesh, "
        "which a tile cannot decide");
  }
  const PreparedMesh mesh(tile.V, tile.F, NormalsRef(*tile.N),
                          {.mean_edge_length = mean_edge_length});
  // The rows fixed as the whole mesh's are (filled, made unit: per row, from its faces).
  const PreparedNormals prepared = prepare_normals(mesh, options);
  const PreparedMesh fit = prepared.N ? mesh.with_normals(NormalsRef(*prepared.N)) : mesh;
  return recommended_statistics(fit, owned, ids, whole_vertex_count, options.recommended);
}

void scatter_rows(const TileEstimate& part, const std::vector<int>& rows,
                  const std::vector<int>& ids, TileEstimate& whole) {
  if (part.crease.size() != 0 && whole.crease.size() == 0) {
    whole.crease = VectorXu8::Zero(whole.curvature.k1.size());
  }
  for (const int r : rows) {
    const int id = ids[static_cast<std::size_t>(r)];
    detail::copy_row(part.curvature, r, whole.curvature, id);
    if (part.crease.size() != 0) whole.crease[id] = part.crease[r];
  }
}

TileEstimate estimate_tiled(const PreparedMesh& mesh, const EstimateOptions& options,
                            const TileOptions& tiles) {
  const MeshWideChoices choices = mesh_wide_choices(mesh, options);
  const FacesRef F = choices.F ? FacesRef(*choices.F) : mesh.F();
  const Tiling tiling =
      partition_mesh(mesh.V(), F, estimate_reach(options_for_part(options, choices)), tiles);
  TileEstimate out{detail::unwritten_result(mesh.vertex_count()), {}};
  for (const Tile& tile : tiling.tiles) {
    const TileEstimate part =
        estimate_tile(extract_tile(mesh.V(), F, mesh.normals(), tile), choices, options);
    scatter_rows(part, tile.owned, tile.vertices, out);
  }
  return out;
}

Tiling partition_cloud(PositionsRef V, const Neighbourhoods& neighbours, int halo_depth,
                       const TileOptions& options) {
  if (halo_depth < 0) throw InvalidInput("partition_cloud: halo_depth must be >= 0");
  if (options.tile_vertices < 1) throw InvalidInput("partition_cloud: tile_vertices must be >= 1");
  if (neighbours.vertex_count() != V.rows()) {
    throw InvalidInput("partition_cloud: the neighbourhoods are not V's");
  }
  const std::vector<int> order = detail::morton_order(V, 0);
  Tiling out;
  out.halo_rings = halo_depth;
  std::vector<std::unique_ptr<std::vector<int>>> marks(
      static_cast<std::size_t>(detail::thread_count(0)));
  for_each_tile_of(order, static_cast<std::size_t>(options.tile_vertices), 0, out.tiles,
                   [&](int t, std::vector<int> owned) {
                     auto& m = marks[static_cast<std::size_t>(detail::worker_slot())];
                     if (!m) m = std::make_unique<std::vector<int>>(order.size(), -1);
                     return make_cloud_tile(std::move(owned), neighbours, halo_depth, t, *m);
                   });
  return out;
}

TileCloud extract_cloud_tile(PositionsRef V, NormalsRef N, const std::vector<char>& outlier,
                             const Tile& tile) {
  check_ids(tile.vertices, V.rows(), "vertex");
  if (N.rows() != V.rows()) throw InvalidInput("extract_cloud_tile: N is not #V x 3");
  if (!outlier.empty() && outlier.size() != static_cast<std::size_t>(V.rows())) {
    throw InvalidInput("extract_cloud_tile: the outlier flags are not #V");
  }
  TileCloud out;
  const auto n = static_cast<Eigen::Index>(tile.vertices.size());
  out.V.resize(n, 3);
  out.N.resize(n, 3);
  if (!outlier.empty()) out.outlier.resize(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    const int id = tile.vertices[static_cast<std::size_t>(i)];
    out.V.row(i) = V.row(id);
    out.N.row(i) = N.row(id);
    if (!outlier.empty()) {
      out.outlier[static_cast<std::size_t>(i)] = outlier[static_cast<std::size_t>(id)];
    }
  }
  return out;
}

void require_tileable(const CloudOptions& options) {
  if (options.adaptive_radius > 0.0) {
    throw InvalidInput(
        "tiles: adaptive radius neighbourhoods are not tiled (a point's radius depends on its "
        "neighbours' neighbours, beyond a tile's halo); estimate the cloud whole");
  }
}

TileEstimate estimate_cloud_tile(const TileCloud& tile, const CloudWideChoices& choices,
                                 const CloudOptions& options) {
  require_tileable(options);
  if (tile.N.rows() != tile.V.rows()) throw InvalidInput("estimate_cloud_tile: N is not #V x 3");
  CloudCurvature plan;
  plan.N = tile.N;
  plan.spacing = choices.spacing;
  plan.k = choices.k;
  plan.corrected = choices.corrected;
  plan.neighbours = cloud_fit_neighbourhoods(tile.V, options, choices.k, tile.outlier);
  fit_cloud_curvature(tile.V, plan, options);
  return {std::move(plan.curvature), {}};
}

TileEstimate estimate_cloud_tiled(PositionsRef V, std::optional<NormalsRef> N,
                                  const CloudOptions& options, const TileOptions& tiles) {
  require_tileable(options);
  const CloudCurvature plan = plan_cloud_curvature(V, N, options);
  const Tiling tiling = partition_cloud(V, plan.neighbours, 1, tiles);
  const CloudWideChoices choices{plan.spacing, plan.k, plan.corrected};
  TileEstimate out{detail::unwritten_result(V.rows()), {}};
  for (const Tile& tile : tiling.tiles) {
    const TileEstimate part =
        estimate_cloud_tile(extract_cloud_tile(V, plan.N, plan.outlier, tile), choices, options);
    scatter_rows(part, tile.owned, tile.vertices, out);
  }
  return out;
}

}  // namespace focal
