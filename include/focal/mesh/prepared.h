#pragma once
/// \file prepared.h
/// A mesh checked once, and what the estimators share built once: the object to pass when more
/// than one function runs on the same mesh (the check, normals, jets, the estimators, focal
/// meshes), so that each skips the validation and reuses what an earlier one built.
///
/// What it holds, each built on first use and then kept for the object's lifetime: the
/// vertex-face incidence (behind the 1-ring, face-weighted normals, the check and the
/// per-triangle estimator), the mean edge length, the given normals made unit with a per-row
/// validity flag, and check_mesh's findings. The 1-ring is kept once one_ring() has been called;
/// until then the estimators build the neighbourhoods they need and drop them when done (they
/// are as large as the incidence, and a run often needs them once). Copies of a PreparedMesh, and
/// with_normals(), share what is built for V and F. Nothing built changes a result: every function
/// gives the same bits with a PreparedMesh as with its arrays, for any thread count.
/// Its const functions may be called from several threads at once: each thing is built once,
/// under a lock, with the ExecutionScope (focal/core/execution.h) of the call that needs it.
///
/// V, F and N are viewed, not copied: they must outlive the PreparedMesh (and its copies) and
/// stay unchanged. Pass arrays in the layout of the views (row-major `n x 3` doubles, int32
/// faces); anything else is converted into a temporary that dies with the constructor call.

#include <memory>
#include <optional>

#include "focal/core/mesh.h"
#include "focal/mesh/neighbourhood.h"

namespace focal {

struct PrepareOptions {
  /// The mean edge length to use instead of measuring it (0: measured): a tile of a larger mesh
  /// (focal/tiles/tiles.h) takes the whole mesh's, so that the scale of its classes, Gaussian
  /// weights and noise estimate is the whole mesh's. Must be finite and >= 0.
  double mean_edge_length = 0.0;
};

namespace detail {
struct PreparedAccess;
}

class PreparedMesh {
 public:
  /// Validates the arrays once. \param V #V x 3 positions (NaN and infinities allowed: the
  /// estimators flag the vertices they touch). \param F #F x 3 triangles. \param N #V x 3
  /// normals as given (need not be unit), or std::nullopt when there are none.
  /// \throw InvalidInput when F indexes outside V, N does not have #V rows, or
  /// mean_edge_length is negative or not finite.
  PreparedMesh(PositionsRef V, FacesRef F, std::optional<NormalsRef> N = std::nullopt,
               const PrepareOptions& options = {});
  /// The arrays of `mesh` (its normals when it has them), which must outlive the object.
  explicit PreparedMesh(const Mesh& mesh, const PrepareOptions& options = {});
  /// A mesh would be destroyed at the end of the full expression, leaving the views dangling.
  explicit PreparedMesh(Mesh&& mesh, const PrepareOptions& options = {}) = delete;

  [[nodiscard]] const PositionsRef& V() const;
  [[nodiscard]] const FacesRef& F() const;
  [[nodiscard]] bool has_normals() const;
  /// The normals as given. \throw InvalidInput when there are none.
  [[nodiscard]] const NormalsRef& N() const;
  /// The normals as given, or std::nullopt.
  [[nodiscard]] std::optional<NormalsRef> normals() const;
  [[nodiscard]] Eigen::Index vertex_count() const;
  [[nodiscard]] Eigen::Index face_count() const;

  /// The 1-ring (vertex_adjacency), built on first call and kept.
  [[nodiscard]] const Neighbourhoods& one_ring() const;
  /// focal::mean_edge_length of V and F, computed on first call (or PrepareOptions::
  /// mean_edge_length when given).
  [[nodiscard]] double mean_edge_length() const;

  /// The same V and F, sharing what has been built for them, with other normals (or none).
  /// \throw InvalidInput when N does not have #V rows.
  [[nodiscard]] PreparedMesh with_normals(std::optional<NormalsRef> N) const;

 private:
  struct Geometry;  ///< V, F and what is built from them alone
  struct Local;     ///< N and what is built with it (unit normals, findings)
  PreparedMesh(std::shared_ptr<Geometry> geometry, std::optional<NormalsRef> N);

  std::shared_ptr<Geometry> geometry_;
  std::shared_ptr<Local> local_;
  friend struct detail::PreparedAccess;
};

}  // namespace focal
