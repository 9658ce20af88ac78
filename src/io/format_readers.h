#pragma once
/// \file format_readers.h
/// The per-format readers that read_mesh() dispatches to, the same readers on a file's contents
/// already in memory (what the fuzz targets and the tests call), and STL's corner welding.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

#include "focal/core/mesh.h"

namespace focal::io_detail {

/// STL welding (ReadOptions): `mesh` as the STL parsers return it, one vertex per corner in file
/// order; replaces V by the welded vertices (first-appearance order), remaps F and fills
/// Mesh::corner_vertex. tolerance 0: exactly equal coordinates (-0 == 0; non-finite corners stay
/// apart); > 0: a corner joins the first vertex within that distance. weld false: identity.
/// The exact weld runs on `threads` threads (0: the default); the result does not depend on it.
/// \throw InvalidInput for a negative or non-finite tolerance.
void weld_corners(Mesh& mesh, double tolerance, bool weld, int threads);
/// The exact weld's matching: for every corner of V, the first corner with exactly its position
/// (-0 == 0; itself for a first and for a non-finite corner). `hashes_first`: corners are matched
/// by 64-bit hashes alone and the matches then checked, positions compared throughout only if a
/// check fails (what weld_corners does); false: positions compared throughout. The same answer
/// either way and for any `threads`; the choice is exposed for tests.
[[nodiscard]] std::vector<std::int32_t> first_equal_corners(const RowMatrixX3d& V, int threads,
                                                            bool hashes_first);

// The per-format readers, dispatched by read_mesh().
/// `threads` as parallel_for's (0: the current ExecutionScope's; the mesh does not depend on it).
[[nodiscard]] Mesh read_obj(const std::filesystem::path& path, int threads);
[[nodiscard]] Mesh read_ply(const std::filesystem::path& path, int threads);
[[nodiscard]] Mesh read_off(const std::filesystem::path& path, int threads);
/// Point-cloud text (xyz.cpp); Mesh::F has 0 rows.
[[nodiscard]] Mesh read_xyz(const std::filesystem::path& path);
/// PCL's .pcd (pcd.cpp): ascii, binary or binary_compressed; Mesh::F has 0 rows.
[[nodiscard]] Mesh read_pcd(const std::filesystem::path& path);
/// ASPRS LAS (las.cpp): the positions of every point record; Mesh::F has 0 rows, no normals.
[[nodiscard]] Mesh read_las(const std::filesystem::path& path);
[[nodiscard]] Mesh read_stl(const std::filesystem::path& path, int threads);

// The same readers on the contents of a file already in memory (read_X(path) is
// parse_X(path, read_whole_file(path))); `path` only names the file in messages. The fuzz targets
// in fuzz/ call these directly. \throw IoError as the readers.
[[nodiscard]] Mesh parse_obj(const std::filesystem::path& path, std::string_view data);
/// parse_obj reading runs of `chunk_bytes` (line_aligned_cuts) on `threads` threads (0: the
/// default); the Mesh, or the error, is the serial reader's for any thread count and run size.
[[nodiscard]] Mesh parse_obj(const std::filesystem::path& path, std::string_view data, int threads,
                             std::size_t chunk_bytes);
/// The parallel read of that parse_obj alone: nothing where parse_obj falls back to the serial
/// read (one run or one thread; a run holding an error, a control byte or a relative index).
/// Lets tests see that the parallel read ran.
[[nodiscard]] std::optional<Mesh> parse_obj_in_chunks(const std::filesystem::path& path,
                                                      std::string_view data, int threads,
                                                      std::size_t chunk_bytes);
[[nodiscard]] Mesh parse_ply(const std::filesystem::path& path, std::string_view data);
/// Point-cloud text; the extension of `path` says what six columns hold (xyz.cpp).
[[nodiscard]] Mesh parse_xyz(const std::filesystem::path& path, std::string_view data);
[[nodiscard]] Mesh parse_pcd(const std::filesystem::path& path, std::string_view data);
[[nodiscard]] Mesh parse_las(const std::filesystem::path& path, std::string_view data);
/// parse_ply with its parallel passes on `threads` threads (0: the default).
[[nodiscard]] Mesh parse_ply(const std::filesystem::path& path, std::string_view data, int threads);
/// That parse_ply with an ascii body read as parse_obj reads a file: runs of `chunk_bytes`, the
/// serial reader's Mesh or error whatever the thread count.
[[nodiscard]] Mesh parse_ply(const std::filesystem::path& path, std::string_view data, int threads,
                             std::size_t chunk_bytes);
/// Its parallel ascii read alone: nothing where it falls back to the serial read (and for binary
/// files). For tests.
[[nodiscard]] std::optional<Mesh> parse_ply_in_chunks(const std::filesystem::path& path,
                                                      std::string_view data, int threads,
                                                      std::size_t chunk_bytes);
[[nodiscard]] Mesh parse_off(const std::filesystem::path& path, std::string_view data);
/// parse_off reading the body (the vertex and face lines) as parse_obj reads a file: runs of
/// `chunk_bytes` on `threads` threads, the serial reader's Mesh or error whatever the count.
[[nodiscard]] Mesh parse_off(const std::filesystem::path& path, std::string_view data, int threads,
                             std::size_t chunk_bytes);
/// Its parallel read alone: nothing where it falls back to the serial read. For tests.
[[nodiscard]] std::optional<Mesh> parse_off_in_chunks(const std::filesystem::path& path,
                                                      std::string_view data, int threads,
                                                      std::size_t chunk_bytes);
[[nodiscard]] Mesh parse_stl(const std::filesystem::path& path, std::string_view data);
/// parse_stl with binary facets read on `threads` threads and an ascii text read in runs of about
/// `chunk_bytes` cut where facets open: the serial reader's Mesh or error for any thread count
/// and run size.
[[nodiscard]] Mesh parse_stl(const std::filesystem::path& path, std::string_view data, int threads,
                             std::size_t chunk_bytes);
/// Its parallel ascii read alone: nothing where it falls back to the serial read (and for binary
/// files). For tests.
[[nodiscard]] std::optional<Mesh> parse_stl_in_chunks(const std::filesystem::path& path,
                                                      std::string_view data, int threads,
                                                      std::size_t chunk_bytes);

}  // namespace focal::io_detail
