#pragma once
// Internal: what the library reads of a PreparedMesh beyond its public accessors (prepared.cpp).

#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "core/parallel.h"
#include "focal/core/mesh.h"
#include "focal/mesh/check.h"
#include "focal/mesh/prepared.h"
#include "mesh/topology.h"

namespace focal::detail {

/// Unit copies of the rows of N; `valid[i]` is false where a row is zero or not finite.
/// Rows are independent, so any thread count gives the same result.
inline RowMatrixX3d unit_rows(NormalsRef N, std::vector<char>& valid, int threads = 0) {
  RowMatrixX3d unit(N.rows(), 3);
  valid.resize(static_cast<std::size_t>(N.rows()));
  parallel_for(N.rows(), threads, [&](std::int64_t i) {
    const double len = N.row(i).norm();
    valid[static_cast<std::size_t>(i)] = std::isfinite(len) && len > 0.0;
    unit.row(i) = N.row(i) / len;
  });
  return unit;
}

/// The normals of a PreparedMesh made unit (unit_rows).
struct UnitNormals {
  RowMatrixX3d N;        ///< #V x 3, NaN or infinite rows where `ok` is false
  std::vector<char> ok;  ///< #V: the row was finite and not zero
};

struct PreparedAccess {
  /// A PreparedMesh whose validation messages name `what` (the function that prepares it).
  static PreparedMesh make(PositionsRef V, FacesRef F, std::optional<NormalsRef> N,
                           const PrepareOptions& options, const char* what);
  /// The vertex-face incidence, built on first call and kept.
  static std::shared_ptr<const VertexFaces> incidence(const PreparedMesh& mesh);
  /// Frees the incidence (for a caller that knows it is no longer needed and wants the memory
  /// back); it is built again if asked for.
  static void release_incidence(const PreparedMesh& mesh);
  /// The kept 1-ring if one_ring() was called, else one built for the caller and not kept.
  static std::shared_ptr<const Neighbourhoods> one_ring(const PreparedMesh& mesh);
  /// Hands a 1-ring built by another pass (check_mesh's topology pass) to the next one_ring()
  /// call, which takes it (it is not kept after that, as one_ring()'s own is not).
  static void offer_one_ring(const PreparedMesh& mesh, Neighbourhoods&& ring);
  /// The mesh's normals made unit, on first call. \throw InvalidInput without normals.
  static const UnitNormals& unit_normals(const PreparedMesh& mesh);
  /// The findings kept for this mesh, computed by `compute` on first call.
  static const MeshFindings& findings(const PreparedMesh& mesh,
                                      const std::function<MeshFindings()>& compute);
  /// Whether findings have been computed for this mesh.
  static bool has_findings(const PreparedMesh& mesh);
};

inline std::shared_ptr<const VertexFaces> incidence(const PreparedMesh& mesh) {
  return PreparedAccess::incidence(mesh);
}
inline std::shared_ptr<const Neighbourhoods> one_ring(const PreparedMesh& mesh) {
  return PreparedAccess::one_ring(mesh);
}
inline const UnitNormals& unit_normals(const PreparedMesh& mesh) {
  return PreparedAccess::unit_normals(mesh);
}

}  // namespace focal::detail
