#include "focal/curvature/recommended.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "core/result_rows.h"
#include "curvature/corrected_step.h"
#include "curvature/height_fit.h"
#include "curvature/hermite_fit.h"
#include "curvature/recommended_steps.h"
#include "curvature/robust_fit.h"
#include "curvature/spike_repair.h"
#include "curvature/triangle_fit.h"
#include "curvature/vertex_fit.h"
#include "curvature/vertex_rows.h"
#include "focal/core/error.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/normals/jets.h"
#include "focal/normals/vertex_normals.h"
#include "mesh/position_spikes.h"
#include "mesh/prepared_access.h"
#include "normals/jet_normals_from.h"
#include "normals/vertex_normals_from.h"

namespace focal {
namespace {

using namespace detail::recommended;

/// A 1-ring fit residual at or below this is rounding (corrected_step.h).
using detail::kExactFitResidual;

/// On clean positions, the per-triangle characteristic equation averaged to the vertices
/// (Method::triangle) is more accurate than the 1-ring fit on irregular meshes (measured 1.3 to
/// 1.8 times lower H error, docs/notes/estimator-log.md), but only second-order exact where the fit
/// is exact: `fit` keeps its rows where its residual says the rays fit exactly, or where the
/// triangles give no estimate, and takes the triangles' elsewhere, except where `replaced` (if
/// not empty) is set: the corrected step writes those rows, so the pass runs on the faces of the
/// other vertices only (a vertex's row reads its own faces, in the same order: the same bits).
void prefer_triangles(const Context& c, const PreparedMesh& fitted,
                      const std::vector<char>& replaced, CurvatureResult& fit) {
  CurvatureOptions o = paper_options(c);
  o.method = Method::triangle;
  const Eigen::Index n = fitted.vertex_count();
  std::vector<char> wanted(static_cast<std::size_t>(n));
  detail::parallel_for(n, 0, [&](std::int64_t i) {
    const auto v = static_cast<std::size_t>(i);
    wanted[v] = !(fit.residual[i] <= kExactFitResidual) && (replaced.empty() || !replaced[v]);
  });
  const FacesRef& F = fitted.F();
  std::vector<int> faces;
  if (!replaced.empty()) {
    for (Eigen::Index f = 0; f < F.rows(); ++f) {
      if (wanted[static_cast<std::size_t>(F(f, 0))] || wanted[static_cast<std::size_t>(F(f, 1))] ||
          wanted[static_cast<std::size_t>(F(f, 2))]) {
        faces.push_back(static_cast<int>(f));
      }
    }
  }
  if (replaced.empty() || faces.size() == static_cast<std::size_t>(F.rows())) {
    return detail::replace_with_triangles(fitted, o, wanted, fit);
  }
  if (faces.empty()) return;
  RowMatrixX3i part(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t k = 0; k < faces.size(); ++k) {
    part.row(static_cast<Eigen::Index>(k)) = F.row(faces[k]);
  }
  // The whole mesh's scale (the classes' tolerances), the fitted normals, the same threads.
  const PreparedMesh sub = detail::PreparedAccess::make(
      fitted.V(), part, fitted.normals(), {.mean_edge_length = c.edge_length}, "prefer_triangles");
  detail::replace_with_triangles(sub, o, wanted, fit);
}

/// The robust fit (curvature/robust_fit.h) of the listed vertices over `rings` rings, Gaussian
/// weighted when `gaussian`, into their rows of `fit` (with `only_rejecting`, only where it
/// rejected rays); no ray from a vertex flagged in `skip`.
void robust_refit(const Context& c, const PreparedMesh& fitted, int rings, bool gaussian,
                  const std::vector<char>& skip, const std::vector<int>& vertices,
                  bool only_rejecting, CurvatureResult& fit) {
  if (vertices.empty()) return;
  if (!c.one_ring) c.one_ring = detail::one_ring(c.mesh);
  const detail::UnitNormals& unit = detail::unit_normals(fitted);
  const Neighbourhoods wider = rings > 1 ? k_ring(*c.one_ring, rings) : Neighbourhoods{};
  const detail::VertexFitInput in{c.mesh.V(), unit.N, unit.ok, rings > 1 ? wider : *c.one_ring,
                                  c.edge_length};
  detail::robust_fit_vertices({in, skip, gaussian ? c.edge_length * rings : 0.0}, vertices,
                              detail::class_tolerances(paper_options(c), c.edge_length), 0,
                              only_rejecting, fit);
}

std::vector<int> all_vertices(const Context& c) {
  std::vector<int> out(static_cast<std::size_t>(c.mesh.vertex_count()));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<int>(i);
  return out;
}

/// Never NaN where a fit is possible: vertices left undefined (too few rays in the hemisphere
/// of their normal, an ill-posed fit) are fitted again, robustly, in the frame of the mean of
/// their neighbours' normals (their own may be the wild one), over one and then two more rings
/// than the plan's: kMaxExtraRings bounds the estimator's reach (recommended_reach). `N` is the
/// normal field of the fit; the rows of the refitted vertices are replaced by that mean.
void fill_undefined(const Context& c, const RecommendedPlan& plan, const std::vector<char>& skip,
                    RowMatrixX3d& N, CurvatureResult& fit) {
  for (int extra = 1; extra <= kMaxExtraRings; ++extra) {
    std::vector<int> candidates, undefined;
    for (int i = 0; i < c.mesh.vertex_count(); ++i) {
      if (fit.class_of(i) == PointClass::undefined) candidates.push_back(i);
    }
    if (candidates.empty()) return;
    // The 1-ring, dropped for the per-triangle pass, is rebuilt only when a vertex needs it.
    if (!c.one_ring) c.one_ring = detail::one_ring(c.mesh);
    for (const int i : candidates) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (const int* j = c.one_ring->begin(i); j != c.one_ring->end(i); ++j) {
        if (N.row(*j).allFinite()) mean += N.row(*j).transpose();
      }
      if (!(mean.norm() > 0.0)) continue;  // no neighbour with a normal: no fit possible
      N.row(i) = mean.normalized().transpose();
      undefined.push_back(i);
    }
    if (undefined.empty()) return;
    robust_refit(c, c.mesh.with_normals(N), plan.rings + extra, true, skip, undefined, false, fit);
  }
}

/// Vertices next to a crease vertex: the triangles there use the crease vertex's normal, which
/// belongs to neither piece; the 1-ring fit without crease vertices replaces them.
void refit_beside_creases(const Context& c, const PreparedMesh& fitted, const VectorXu8& crease,
                          CurvatureResult& fit) {
  if (crease.size() == 0 || crease.maxCoeff() == 0) return;
  if (!c.one_ring) c.one_ring = detail::one_ring(c.mesh);
  const std::vector<char> skip(crease.begin(), crease.end());
  robust_refit(c, fitted, 1, false, skip, near_flagged(c, skip, 1), false, fit);
}

/// Vertices within 2 rings of a crease vertex, set (empty: crease handling is off). The
/// Hermite fit's rings and the corrected step's balls would reach across the crease there;
/// refit_beside_creases and the per-triangle pass stay.
std::vector<char> near_creases(const Context& c, const VectorXu8& crease) {
  std::vector<char> out(crease.begin(), crease.end());
  if (!out.empty()) {
    for (const int v : near_flagged(c, out, 2)) out[static_cast<std::size_t>(v)] = 1;
  }
  return out;
}

/// The `repaired` spikes as #V flags for the quartic fits' moved vertices (empty: none).
std::vector<char> moved_flags(const Context& c, const std::vector<int>& repaired) {
  std::vector<char> moved;
  if (!repaired.empty()) {
    moved.assign(static_cast<std::size_t>(c.mesh.vertex_count()), 0);
    for (const int v : repaired) moved[static_cast<std::size_t>(v)] = 1;
  }
  return moved;
}

/// Trusted file normals on clean positions: the quartic Hermite fit (curvature/hermite_fit.h)
/// where the two-slit fit is not exact, except `near_crease` (near_creases), with the
/// `repaired` spikes and the normals that are not the file's (outliers replaced) as the fit's
/// moved and guessed vertices; returns the rows it wrote.
std::vector<char> hermite(const Context& c, const PreparedMesh& fitted,
                          const std::vector<char>& near_crease, const std::vector<int>& repaired,
                          CurvatureResult& fit) {
  if (!c.one_ring) c.one_ring = detail::one_ring(c.mesh);
  const detail::UnitNormals& unit = detail::unit_normals(fitted);
  const auto count = static_cast<std::size_t>(c.mesh.vertex_count());
  const std::vector<char> moved = moved_flags(c, repaired);
  // The fitted normals that are not the file's (outliers replaced by the positions' normals).
  std::vector<char> guessed(count, 0);
  const NormalsRef file = *c.mesh.normals();
  detail::parallel_for(c.mesh.vertex_count(), 0, [&](std::int64_t v) {
    const Eigen::RowVector3d n = file.row(v);
    guessed[static_cast<std::size_t>(v)] = !(unit.N.row(v).dot(n) >= (1.0 - 1e-12) * n.norm());
  });
  return detail::prefer_hermite_fit(
      fitted.V(), unit.N, unit.ok, *c.one_ring, *detail::incidence(c.mesh), near_crease, moved,
      guessed, kExactFitResidual, detail::class_tolerances(paper_options(c), c.edge_length), fit);
}

/// Clean positions without trusted normals: the quartic height fit of the positions
/// (curvature/height_fit.h) where the two-slit fit is not exact, except `near_crease`
/// (near_creases), with the `repaired` spikes as the fit's moved vertices; returns the rows it
/// wrote.
std::vector<char> heights(const Context& c, const PreparedMesh& fitted,
                          const std::vector<char>& near_crease, const std::vector<int>& repaired,
                          CurvatureResult& fit) {
  if (!c.one_ring) c.one_ring = detail::one_ring(c.mesh);
  const detail::UnitNormals& unit = detail::unit_normals(fitted);
  return detail::prefer_height_fit(fitted.V(), unit.N, unit.ok, *c.one_ring,
                                   *detail::incidence(c.mesh), near_crease,
                                   moved_flags(c, repaired), kExactFitResidual,
                                   detail::class_tolerances(paper_options(c), c.edge_length), fit);
}

/// Trusted file normals on clean positions: the corrected curvature measures
/// (curvature/corrected_step.h) where the fit is not exact, except where `keep` (near_creases)
/// or `written` (the Hermite fit's rows) is set; no measure, and no stencil asymmetry, where no
/// vertex is left (a clean mesh the Hermite fit covers).
detail::CorrectedRows corrected(const Context& c, const PreparedMesh& fitted,
                                std::vector<char> keep, const std::vector<char>& written,
                                const CurvatureResult& fit) {
  if (!c.one_ring) c.one_ring = detail::one_ring(c.mesh);
  // A vertex of one face keeps that face's operator (its spread, the residual, is 0: the
  // per-triangle pass's row counts as exact, as it did when the pass ran first).
  keep.resize(static_cast<std::size_t>(c.mesh.vertex_count()), 0);
  const auto incidence = detail::incidence(c.mesh);
  bool any = false;
  for (int v = 0; v < c.mesh.vertex_count(); ++v) {
    const auto i = static_cast<std::size_t>(v);
    if (incidence->size(v) < 2 || written[i]) keep[i] = 1;
    any = any || (!keep[i] && !(fit.residual[v] <= kExactFitResidual));
  }
  if (!any) return {{}, std::vector<char>(keep.size(), 0)};
  return detail::corrected_rows(fitted, *c.one_ring, paper_options(c), keep, kExactFitResidual,
                                fit);
}

/// Positions with spikes moved back, and the spikes (ascending).
struct Repaired {
  RowMatrixX3d V;
  std::vector<int> spikes;
};

/// Spikes on trusted file normals (spike_repair.h): the positions with each spike moved back
/// onto the surface its neighbours and the normals describe, or nothing when there is none.
std::optional<Repaired> spike_repaired(const Context& c) {
  // Unit rows of its own, not the mesh's kept ones: nothing after this step reads them, and kept
  // they would stay alive through the fit and the per-triangle pass (24 B a vertex).
  std::vector<char> ok;
  const RowMatrixX3d N = detail::unit_rows(*c.mesh.normals(), ok, 0);
  const Eigen::VectorXd offset = detail::normal_offsets(c.mesh.V(), N, *c.one_ring, 0);
  const std::vector<int> spikes = detail::find_spikes(c.mesh.V(), N, *c.one_ring, offset);
  if (spikes.empty()) return std::nullopt;
  return Repaired{detail::repaired_positions(c.mesh.V(), N, *c.one_ring, offset, spikes), spikes};
}

/// Spikes without trusted normals (mesh/position_spikes.h, judged from the positions with Max's
/// normals as the screen's directions): the positions with each spike moved onto the quadric
/// of its 2-ring without it, or nothing when there is none.
std::optional<Repaired> position_spike_repaired(const Context& c) {
  const detail::PositionSpikes spikes = detail::position_spikes(
      c.mesh.V(), c.mesh.F(), *c.one_ring, *detail::incidence(c.mesh), c.max, 0);
  if (spikes.vertices.empty()) return std::nullopt;
  RowMatrixX3d V = c.mesh.V();
  for (std::size_t k = 0; k < spikes.vertices.size(); ++k) {
    V.row(spikes.vertices[k]) = spikes.repaired[k].transpose();
  }
  return Repaired{std::move(V), spikes.vertices};
}

}  // namespace

namespace {

/// estimate_curvature_recommended; `repair_spikes`: step 7 may start again on repaired
/// positions; `repaired`: the vertices it moved, when it did.
RecommendedResult estimate(const PreparedMesh& mesh, const RecommendedOptions& options,
                           bool repair_spikes, const std::vector<int>& repaired = {}) {
  Context c = make_context(mesh, options);
  RecommendedResult out;
  const RecommendedMeshWide mesh_wide = choose_normals(c, out);
  if (repair_spikes && out.plan.rings == 1) {
    // Spikes (step 7): the whole estimate again on the repaired positions, with this mesh's
    // mesh-wide choices and scale (away from the spikes the positions, and so the estimate, are
    // the same). With trusted normals the normals tell where a spike belongs; without, the
    // positions around it.
    if (const std::optional<Repaired> r =
            out.file_normals_used ? spike_repaired(c) : position_spike_repaired(c)) {
      RecommendedOptions o = options;
      o.mesh_wide = mesh_wide;
      const PreparedMesh repaired = detail::PreparedAccess::make(
          r->V, mesh.F(), mesh.normals(), {.mean_edge_length = c.edge_length},
          "estimate_curvature_recommended");
      return estimate(repaired, o, false, r->spikes);
    }
  }
  // Max's normals served the choice of normals only: their memory is the later steps'.
  c.max.resize(0, 3);
  // The mesh with the chosen normals: the fit and the per-triangle pass share their unit rows.
  const PreparedMesh fitted = mesh.with_normals(out.N);
  const std::vector<char> no_skip;
  if (out.plan.rings == 1) {
    out.curvature = two_slit_fit(c, fitted, out.plan.rings, out.plan.gaussian);
    // The Hermite fit, then the corrected step where it wrote no row: the per-triangle pass
    // then skips the rows they replace. Each judges the fit's residual (whether it is exact) of
    // rows the others do not write, so the measures are written (and their whole-mesh result
    // freed) before the pass runs.
    std::vector<char> replaced;
    if (out.file_normals_used) {
      std::vector<char> near_crease = near_creases(c, out.crease);
      replaced = hermite(c, fitted, near_crease, repaired, out.curvature);
      detail::CorrectedRows measures =
          corrected(c, fitted, std::move(near_crease), replaced, out.curvature);
      detail::apply_corrected_rows(measures, 0, out.curvature);
      for (std::size_t v = 0; v < replaced.size(); ++v) replaced[v] |= measures.replace[v];
    } else if (mesh_wide.height_share <= detail::kHeightMaxMedianShare) {
      replaced = heights(c, fitted, near_creases(c, out.crease), repaired, out.curvature);
    }
    // The 1-ring's memory is the per-triangle pass's (later steps rebuild it if they need it).
    c.one_ring.reset();
    prefer_triangles(c, fitted, replaced, out.curvature);
    replaced = {};
    refit_beside_creases(c, fitted, out.crease, out.curvature);
  } else {
    // Noisy positions: where rays lie far off the fit (wild normals), it is repeated without.
    out.curvature = two_slit_fit(c, fitted, out.plan.rings, out.plan.gaussian);
    robust_refit(c, fitted, out.plan.rings, out.plan.gaussian, no_skip, all_vertices(c), true,
                 out.curvature);
  }
  fill_undefined(c, out.plan, no_skip, out.N, out.curvature);
  if (!out.file_normals_used) detail::undefine_isolated_triangles(mesh.F(), out.curvature);
  return out;
}

}  // namespace

RecommendedResult estimate_curvature_recommended(const PreparedMesh& mesh,
                                                 const RecommendedOptions& options) {
  validate_options(options, "estimate_curvature_recommended");
  return estimate(mesh, options, true);
}

RecommendedResult estimate_curvature_recommended(PositionsRef V, FacesRef F,
                                                 std::optional<NormalsRef> N,
                                                 const RecommendedOptions& options) {
  validate_options(options, "estimate_curvature_recommended");
  return estimate_curvature_recommended(
      detail::PreparedAccess::make(V, F, std::move(N), {}, "estimate_curvature_recommended"),
      options);
}

}  // namespace focal
