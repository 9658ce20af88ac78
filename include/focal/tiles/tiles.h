#pragma once
/// \file tiles.h
/// A mesh cut into spatial tiles with halos, each estimated on its own (in another process or
/// on another machine: python/focal/distributed.py runs them on Dask) and giving its owned
/// vertices exactly the whole mesh's estimate, bit for bit. docs/SCALE.md.
///
/// Why the result is identical: a tile holds every face within `halo_rings` rings of its owned
/// vertices, with halo_rings = estimate_reach(options) (estimate.h: the rings an estimate reads,
/// derived from the estimator's steps), so each owned vertex sees the same neighbours, normals and
/// faces as in the whole mesh. The tile keeps the whole mesh's order: its vertices and faces are
/// sorted by global id, so every neighbour list, incidence list and sum runs in the same order.
/// What is decided from the whole mesh (the mean edge length, the recommended estimator's noise
/// and file-normal choices, the orientation of closed components) is measured once by
/// mesh_wide_choices and given to every tile.

#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "focal/core/fields.h"
#include "focal/core/mesh.h"
#include "focal/curvature/cloud_curvature.h"
#include "focal/curvature/estimate.h"
#include "focal/mesh/prepared.h"

namespace focal {

struct TileOptions {
  /// Owned vertices per tile, at most (a tile also holds its halo). >= 1.
  int tile_vertices = 1 << 20;
};

/// One tile: global ids, ascending.
struct Tile {
  std::vector<int> vertices;  ///< owned and halo vertices
  std::vector<int>
      faces;  ///< every face with a corner within halo_rings - 1 rings of an owned vertex
  std::vector<int> owned;  ///< positions in `vertices` of the owned ones
};

/// The tiles of a mesh: every vertex is owned by exactly one tile.
struct Tiling {
  std::vector<Tile> tiles;
  int halo_rings = 0;
};

/// Cuts a mesh into tiles of consecutive vertices in Morton (Z) order of their positions, within
/// the bounding box of the finite ones (vertices with NaN or infinite coordinates come last),
/// ties by index; each tile gets the faces and vertices within `halo_rings` rings of its owned
/// vertices. \param halo_rings >= 1: estimate_reach(options) for an estimate.
/// \throw InvalidInput when F indexes outside V, halo_rings < 1 or tile_vertices < 1.
[[nodiscard]] Tiling partition_mesh(PositionsRef V, FacesRef F, int halo_rings,
                                    const TileOptions& options = {});

/// A tile's arrays, renumbered 0 .. #vertices - 1 in the tile's (global) order.
struct TileMesh {
  RowMatrixX3d V;
  RowMatrixX3i F;
  std::optional<RowMatrixX3d> N;  ///< when the mesh has normals
};

/// The rows of `tile` of V, F and N. \throw InvalidInput when the tile's ids are out of range.
[[nodiscard]] TileMesh extract_tile(PositionsRef V, FacesRef F, std::optional<NormalsRef> N,
                                    const Tile& tile);

/// A tile's estimate, or the tiled whole's: the fields and the crease flags (Estimate::crease:
/// one per row for the recommended estimator, empty for the paper's).
struct TileEstimate {
  CurvatureResult curvature;
  VectorXu8 crease;
};

/// estimate() of a tile's arrays with the whole mesh's choices: `options` as given to the whole
/// mesh (options_for_part is applied here). Rows of every tile vertex; those of its owned
/// vertices are the whole mesh's.
[[nodiscard]] TileEstimate estimate_tile(const TileMesh& tile, const MeshWideChoices& choices,
                                         const EstimateOptions& options);

/// The recommended estimator's recommended_statistics of a tile's owned vertices (rows `owned`,
/// whole-mesh ids `ids`, one per tile vertex), on the tile's normals prepared as the estimate
/// prepares them (prepare_normals), with the whole mesh's mean edge length: the tile's share of
/// the whole mesh's RecommendedMeshWide, for a mesh that no process holds whole (the medians
/// over all tiles, recommended_mesh_wide_from). The tile needs a halo of
/// kRecommendedStatisticsReach rings. 	hrow InvalidInput when `options` is not the recommended
/// estimator on the mesh's own normals, or the tile has none: without them the whole mesh's
/// closed components are oriented (prepare_normals), which a tile cannot decide.
[[nodiscard]] RecommendedStatistics tile_statistics(
    const TileMesh& tile, const std::vector<int>& ids, const std::vector<int>& owned,
    Eigen::Index whole_vertex_count, double mean_edge_length, const EstimateOptions& options);

/// Whether each id of `x` is one of `ascending` (ids >= 0, ascending): the set operations of a
/// tile's halo rounds when the mesh is streamed from its file (python/focal/stream.py: which
/// face records have a corner on the ring's frontier, which faces and vertices are new). A
/// bitmap over the span of `ascending` (span / 8 bytes), looked up in parallel.
/// \throw InvalidInput when `ascending` is not ascending or holds a negative id.
[[nodiscard]] std::vector<char> ids_in(std::span<const int> x, std::span<const int> ascending);

/// The whole estimate, tile by tile in this process: the same bits as estimate(mesh, options)
/// .curvature and .crease, with the memory of the largest tile in place of the whole mesh's.
[[nodiscard]] TileEstimate estimate_tiled(const PreparedMesh& mesh,
                                          const EstimateOptions& options = {},
                                          const TileOptions& tiles = {});

/// Writes the rows `rows` of `part` into the rows `ids[rows]` of `whole` (fields sized #V; its
/// crease flags sized #V, zero, on the first part that has any).
void scatter_rows(const TileEstimate& part, const std::vector<int>& rows,
                  const std::vector<int>& ids, TileEstimate& whole);

// ---- Point clouds --------------------------------------------------------------------------
//
// A cloud's tiles hold their owned points and every point within `halo_depth` links of them in
// a neighbourhood graph; the estimate's is plan.neighbours of plan_cloud_curvature (the lists of
// the fit), where a depth of 1 suffices: a point's row of the fit reads its own and its
// neighbours' positions and normals only (fit_cloud_curvature), and a tile that holds a point's
// neighbours gives the point the same list (cloud_fit_neighbourhoods: ties by index, and a tile
// keeps the cloud's order). What the plan reads further (the outlier test's neighbours of
// neighbours, the noise and file-normal choices, which are medians over the cloud, the spacing,
// and normals oriented by a spanning tree of the whole cloud) is decided once, on the whole
// cloud, and given to the tiles as CloudWideChoices and per-point rows (normals, outlier flags).

/// Cuts a cloud into tiles of consecutive points in Morton order (as partition_mesh); each
/// tile's vertices are its owned points and those reached from them in at most `halo_depth`
/// steps along `neighbours` (#V lists); faces are empty. Tiling::halo_rings is halo_depth.
/// \throw InvalidInput when the lists are not V's, halo_depth < 0 or tile_vertices < 1.
[[nodiscard]] Tiling partition_cloud(PositionsRef V, const Neighbourhoods& neighbours,
                                     int halo_depth, const TileOptions& options = {});

/// What a cloud's tiles take from the whole cloud besides their points' rows
/// (plan_cloud_curvature).
struct CloudWideChoices {
  double spacing = 0.0;    ///< CloudCurvature::spacing: the scale of the class tolerances
  int k = 0;               ///< CloudCurvature::k: neighbours of the fit (ignored with a radius)
  bool corrected = false;  ///< CloudCurvature::corrected: the corrected step on the fit
};

/// A cloud tile's rows, in the tile's (global) order.
struct TileCloud {
  RowMatrixX3d V;
  RowMatrixX3d N;             ///< the plan's normals (CloudCurvature::N)
  std::vector<char> outlier;  ///< the plan's outlier flags, or empty
};

/// The rows of `tile` of V, the plan's normals and outlier flags (empty or #V).
/// \throw InvalidInput when the tile's ids are out of range or N is not #V x 3.
[[nodiscard]] TileCloud extract_cloud_tile(PositionsRef V, NormalsRef N,
                                           const std::vector<char>& outlier, const Tile& tile);

/// The fit of a cloud tile with the whole cloud's choices: rows of every tile point, those of
/// its owned points (with the halo of partition_cloud over plan.neighbours, depth 1) the whole
/// cloud's. `options` as given to the whole cloud. crease is empty.
[[nodiscard]] TileEstimate estimate_cloud_tile(const TileCloud& tile,
                                               const CloudWideChoices& choices,
                                               const CloudOptions& options);

/// Cloud options whose estimate can be tiled with the halo of estimate_cloud_tile. Adaptive
/// radii cannot (yet): a point's radius reads its neighbours' own neighbours, beyond the halo.
/// \throw InvalidInput for adaptive_radius > 0.
void require_tileable(const CloudOptions& options);

/// estimate_cloud_curvature(V, N, options).curvature, tile by tile: the plan on the whole cloud
/// (it holds the whole cloud's neighbourhoods and normals: with normals estimated, the normals
/// of the whole cloud), then the fit tile by tile, the same bits.
[[nodiscard]] TileEstimate estimate_cloud_tiled(PositionsRef V, std::optional<NormalsRef> N,
                                                const CloudOptions& options = {},
                                                const TileOptions& tiles = {});

// ---- Streamed tiles ------------------------------------------------------------------------
//
// A mesh that no process holds whole is tiled in passes over its vertices (PlyTriangleReader,
// python/focal/stream.py): the cells of a coarse Morton grid over the box of the finite vertices,
// taken in Morton order, are cut into runs of about tile_vertices vertices (a cell is never cut),
// so that a vertex's tile is a function of its position and nothing per vertex is kept. The
// tiles' halos are then gathered as partition_mesh gathers them, from files of the tiles' faces.

/// Bits per axis of the grid of streamed tiles: 2^21 cells, whose counts take 16 MB.
inline constexpr int kTileGridBits = 7;
/// Cells of the grid: 2^(3 x kTileGridBits) in Morton order, then one for non-finite positions.
inline constexpr std::int64_t kTileGridCells = (std::int64_t{1} << (3 * kTileGridBits)) + 1;

/// The box the grid spans: per axis the least and the greatest finite coordinate (lo > hi while
/// no row with all coordinates finite has been seen).
struct TileGridBox {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
};

/// `box` grown by the rows of P whose coordinates are all finite (one chunk of a pass).
[[nodiscard]] TileGridBox grow_tile_grid_box(const TileGridBox& box, PositionsRef P);

/// The grid cell of each row of P: each axis of `box` cut into 2^kTileGridBits equal parts (an
/// axis of zero extent: part 0; positions outside the box: the nearest part), the cell the Morton
/// code of the parts (x in bit 0, y in bit 1, z in bit 2 of each triple); a row with a non-finite
/// coordinate: the last cell, kTileGridCells - 1.
[[nodiscard]] std::vector<std::int32_t> tile_grid_cells(PositionsRef P, const TileGridBox& box);

/// The tiles of the grid's cells.
struct TileGrid {
  std::vector<std::int32_t> cell_tile;  ///< per cell (kTileGridCells): its tile, 0 when empty
  int tile_count = 0;
};

/// Cuts the cells, in Morton order, into tiles: a cell with vertices goes to the tile numbered
/// floor(vertices in the cells before it / tile_vertices), the tiles then renumbered densely in
/// that order (no tile is empty; a tile may hold more than tile_vertices when one cell does).
/// `counts`: vertices per cell (kTileGridCells).
/// \throw InvalidInput for counts of another size or negative, or tile_vertices < 1.
[[nodiscard]] TileGrid cut_tile_grid(std::span<const std::int64_t> counts, int tile_vertices);

/// The tile of each row of P: cell_tile[tile_grid_cells(P, box)].
/// \throw InvalidInput when cell_tile has not kTileGridCells entries.
[[nodiscard]] std::vector<std::int32_t> tile_grid_tiles(PositionsRef P, const TileGridBox& box,
                                                        std::span<const std::int32_t> cell_tile);

}  // namespace focal
