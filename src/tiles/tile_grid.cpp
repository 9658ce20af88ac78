// The grid of streamed tiles (tiles.h, "Streamed tiles"): a vertex's tile from its position alone.

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "focal/core/error.h"
#include "focal/tiles/tiles.h"

namespace focal {
namespace {

constexpr std::int64_t kSide = std::int64_t{1} << kTileGridBits;

/// The kTileGridBits bits of x spread to every third position.
std::int64_t spread_bits(std::int64_t x) {
  std::int64_t out = 0;
  for (int b = 0; b < kTileGridBits; ++b) out |= ((x >> b) & 1) << (3 * b);
  return out;
}

std::int32_t cell_of(const Eigen::Vector3d& p, const TileGridBox& box) {
  if (!p.allFinite()) return static_cast<std::int32_t>(kTileGridCells - 1);
  std::int64_t code = 0;
  for (int a = 0; a < 3; ++a) {
    const double extent = box.hi[a] > box.lo[a] ? box.hi[a] - box.lo[a] : 1.0;
    const double t = std::clamp((p[a] - box.lo[a]) / extent, 0.0, 1.0);
    const std::int64_t part = std::min(static_cast<std::int64_t>(t * kSide), kSide - 1);
    code |= spread_bits(part) << a;
  }
  return static_cast<std::int32_t>(code);
}

}  // namespace

TileGridBox grow_tile_grid_box(const TileGridBox& box, PositionsRef P) {
  TileGridBox out = box;
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Eigen::Vector3d p = P.row(i).transpose();
    if (!p.allFinite()) continue;
    out.lo = out.lo.cwiseMin(p);
    out.hi = out.hi.cwiseMax(p);
  }
  return out;
}

std::vector<std::int32_t> tile_grid_cells(PositionsRef P, const TileGridBox& box) {
  std::vector<std::int32_t> out(static_cast<std::size_t>(P.rows()));
  detail::parallel_for(P.rows(), 0, [&](std::int64_t i) {
    out[static_cast<std::size_t>(i)] = cell_of(P.row(i).transpose(), box);
  });
  return out;
}

TileGrid cut_tile_grid(std::span<const std::int64_t> counts, int tile_vertices) {
  if (static_cast<std::int64_t>(counts.size()) != kTileGridCells) {
    throw InvalidInput("cut_tile_grid: " + std::to_string(counts.size()) + " counts, expected " +
                       std::to_string(kTileGridCells));
  }
  if (tile_vertices < 1) throw InvalidInput("cut_tile_grid: tile_vertices must be >= 1");
  TileGrid out;
  out.cell_tile.assign(counts.size(), 0);
  std::int64_t before = 0;  // vertices in the cells before this one
  std::int64_t last_run = -1;
  for (std::size_t c = 0; c < counts.size(); ++c) {
    if (counts[c] < 0) throw InvalidInput("cut_tile_grid: a negative count");
    if (counts[c] == 0) continue;
    const std::int64_t run = before / tile_vertices;
    if (run != last_run) {
      last_run = run;
      ++out.tile_count;
    }
    out.cell_tile[c] = out.tile_count - 1;
    before += counts[c];
  }
  return out;
}

std::vector<std::int32_t> tile_grid_tiles(PositionsRef P, const TileGridBox& box,
                                          std::span<const std::int32_t> cell_tile) {
  if (static_cast<std::int64_t>(cell_tile.size()) != kTileGridCells) {
    throw InvalidInput("tile_grid_tiles: " + std::to_string(cell_tile.size()) +
                       " cells, expected " + std::to_string(kTileGridCells));
  }
  std::vector<std::int32_t> out = tile_grid_cells(P, box);
  for (std::int32_t& t : out) t = cell_tile[static_cast<std::size_t>(t)];
  return out;
}

}  // namespace focal
