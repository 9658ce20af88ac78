#include "focal/mesh/prepared.h"

#include <cmath>
#include <mutex>
#include <string>
#include <utility>

#include "focal/core/error.h"
#include "mesh/neighbourhood_detail.h"
#include "mesh/prepared_access.h"
#include "mesh/topology.h"

namespace focal {

// What is built from V and F alone, shared by copies and with_normals(). The lock guards the
// building (each build is itself parallel); what is built never changes afterwards.
struct PreparedMesh::Geometry {
  PositionsRef V;
  FacesRef F;
  std::recursive_mutex mutex;
  std::shared_ptr<const detail::VertexFaces> incidence;
  std::shared_ptr<const Neighbourhoods> one_ring;      ///< kept once one_ring() was called
  std::shared_ptr<const Neighbourhoods> offered_ring;  ///< offer_one_ring's, until first asked for
  std::optional<double> mean_edge_length;

  Geometry(PositionsRef v, FacesRef f) : V(std::move(v)), F(std::move(f)) {}
};

// The normals of one PreparedMesh and what is built with them.
struct PreparedMesh::Local {
  std::optional<NormalsRef> N;
  std::mutex mutex;
  std::optional<detail::UnitNormals> unit;
  std::optional<MeshFindings> findings;

  explicit Local(std::optional<NormalsRef> n) : N(std::move(n)) {}
};

namespace {

void check_normal_rows(Eigen::Index vertex_count, const std::optional<NormalsRef>& N,
                       const char* what) {
  if (N && N->rows() != vertex_count) {
    throw InvalidInput(std::string(what) + ": " + std::to_string(N->rows()) + " normals for " +
                       std::to_string(vertex_count) +
                       " vertices (normals need one row per vertex; pass std::nullopt when "
                       "there are none)");
  }
}

}  // namespace

PreparedMesh::PreparedMesh(PositionsRef V, FacesRef F, std::optional<NormalsRef> N,
                           const PrepareOptions& options)
    : PreparedMesh(detail::PreparedAccess::make(V, F, std::move(N), options, "PreparedMesh")) {}

PreparedMesh::PreparedMesh(const Mesh& mesh, const PrepareOptions& options)
    : PreparedMesh(mesh.V, mesh.F, mesh.normals(), options) {}

PreparedMesh::PreparedMesh(std::shared_ptr<Geometry> geometry, std::optional<NormalsRef> N)
    : geometry_(std::move(geometry)), local_(std::make_shared<Local>(std::move(N))) {}

const PositionsRef& PreparedMesh::V() const { return geometry_->V; }
const FacesRef& PreparedMesh::F() const { return geometry_->F; }
bool PreparedMesh::has_normals() const { return local_->N.has_value(); }
Eigen::Index PreparedMesh::vertex_count() const { return geometry_->V.rows(); }
Eigen::Index PreparedMesh::face_count() const { return geometry_->F.rows(); }

const NormalsRef& PreparedMesh::N() const {
  if (!local_->N) throw InvalidInput("PreparedMesh::N: the mesh has no normals");
  return *local_->N;
}

std::optional<NormalsRef> PreparedMesh::normals() const { return local_->N; }

const Neighbourhoods& PreparedMesh::one_ring() const {
  Geometry& g = *geometry_;
  const std::lock_guard lock(g.mutex);
  if (!g.one_ring) g.one_ring = detail::PreparedAccess::one_ring(*this);
  return *g.one_ring;
}

double PreparedMesh::mean_edge_length() const {
  Geometry& g = *geometry_;
  const std::lock_guard lock(g.mutex);
  if (!g.mean_edge_length) g.mean_edge_length = focal::mean_edge_length(g.V, g.F);
  return *g.mean_edge_length;
}

PreparedMesh PreparedMesh::with_normals(std::optional<NormalsRef> N) const {
  check_normal_rows(vertex_count(), N, "PreparedMesh::with_normals");
  return {geometry_, std::move(N)};
}

namespace detail {

PreparedMesh PreparedAccess::make(PositionsRef V, FacesRef F, std::optional<NormalsRef> N,
                                  const PrepareOptions& options, const char* what) {
  if (!(options.mean_edge_length >= 0.0 && std::isfinite(options.mean_edge_length))) {
    throw InvalidInput(std::string(what) + ": mean_edge_length must be finite and >= 0");
  }
  check_normal_rows(V.rows(), N, what);
  validate_mesh_arrays(V, F, RowMatrixX3d(0, 3), what);
  auto geometry = std::make_shared<PreparedMesh::Geometry>(V, F);
  if (options.mean_edge_length > 0.0) geometry->mean_edge_length = options.mean_edge_length;
  return {std::move(geometry), std::move(N)};
}

std::shared_ptr<const VertexFaces> PreparedAccess::incidence(const PreparedMesh& mesh) {
  PreparedMesh::Geometry& g = *mesh.geometry_;
  const std::lock_guard lock(g.mutex);
  if (!g.incidence) {
    g.incidence = std::make_shared<const VertexFaces>(vertex_face_incidence(g.V.rows(), g.F, 0));
  }
  return g.incidence;
}

void PreparedAccess::release_incidence(const PreparedMesh& mesh) {
  PreparedMesh::Geometry& g = *mesh.geometry_;
  const std::lock_guard lock(g.mutex);
  g.incidence.reset();
}

std::shared_ptr<const Neighbourhoods> PreparedAccess::one_ring(const PreparedMesh& mesh) {
  PreparedMesh::Geometry& g = *mesh.geometry_;
  const std::lock_guard lock(g.mutex);
  if (g.one_ring) return g.one_ring;
  if (g.offered_ring) return std::exchange(g.offered_ring, nullptr);
  return std::make_shared<const Neighbourhoods>(vertex_adjacency_from(*incidence(mesh), g.F, 0));
}

void PreparedAccess::offer_one_ring(const PreparedMesh& mesh, Neighbourhoods&& ring) {
  PreparedMesh::Geometry& g = *mesh.geometry_;
  const std::lock_guard lock(g.mutex);
  if (!g.one_ring) g.offered_ring = std::make_shared<const Neighbourhoods>(std::move(ring));
}

const UnitNormals& PreparedAccess::unit_normals(const PreparedMesh& mesh) {
  PreparedMesh::Local& l = *mesh.local_;
  const std::lock_guard lock(l.mutex);
  if (!l.unit) {
    UnitNormals u;
    u.N = unit_rows(mesh.N(), u.ok);
    l.unit = std::move(u);
  }
  return *l.unit;
}

const MeshFindings& PreparedAccess::findings(const PreparedMesh& mesh,
                                             const std::function<MeshFindings()>& compute) {
  PreparedMesh::Local& l = *mesh.local_;
  const std::lock_guard lock(l.mutex);
  if (!l.findings) l.findings = compute();
  return *l.findings;
}

bool PreparedAccess::has_findings(const PreparedMesh& mesh) {
  PreparedMesh::Local& l = *mesh.local_;
  const std::lock_guard lock(l.mutex);
  return l.findings.has_value();
}

}  // namespace detail
}  // namespace focal
