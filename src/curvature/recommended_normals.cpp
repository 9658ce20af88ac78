// Steps 1 to 3 of the recommended estimator (recommended.h): the normals to fit, the file's
// where they agree with the positions (outliers replaced), else jets or Max's normals chosen by
// their roughness, and at creases Max's normals.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "curvature/normal_choice.h"
#include "curvature/recommended_steps.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/normals/jets.h"
#include "mesh/prepared_access.h"
#include "normals/jet_normals_from.h"

namespace focal::detail::recommended {
namespace {

/// `jets` (the 2-ring cubic jets) with the rows of vertices whose 2-ring is cut by a boundary
/// (within kBoundaryJetDistance rings of it) replaced by cubic jets over kBoundaryJetRings
/// rings where those are the smoother field there (1-ring two-slit residual, roughness_of): a
/// one-sided 2-ring holds about half an interior 2-ring's points, about as many as a cubic's 10
/// coefficients, and its jet nearly interpolates them; the one-sided 3-ring holds about as many
/// points as an interior 2-ring (on a thin tube it reaches around it, and the 2-ring may stay
/// smoother). Rows where the wider jet fails stay.
RowMatrixX3d with_boundary_jets(const Context& c, const RowMatrixX3d& jets) {
  const std::vector<bool> boundary =
      boundary_vertices(static_cast<int>(c.mesh.vertex_count()), c.mesh.F());
  std::vector<int> near;
  const Eigen::VectorXi distance = rings_to_boundary(*c.one_ring, boundary, kBoundaryJetDistance);
  for (int i = 0; i < distance.size(); ++i) {
    if (distance[i] <= kBoundaryJetDistance) near.push_back(i);
  }
  RowMatrixX3d out = jets;
  if (near.empty()) return out;
  const JetNormals wide = detail::jet_normals_at(c.mesh.V(), *c.one_ring, c.max,
                                                 jet_options(kBoundaryJetRings, 3), near);
  for (std::size_t k = 0; k < near.size(); ++k) {
    const auto row = static_cast<Eigen::Index>(k);
    if (wide.N.row(row).allFinite()) out.row(near[k]) = wide.N.row(row);
  }
  const Eigen::VectorXd r2 = roughness_at(c, jets, near), r3 = roughness_at(c, out, near);
  for (std::size_t k = 0; k < near.size(); ++k) {
    const auto row = static_cast<Eigen::Index>(k);
    if (std::isfinite(r2[row]) && !(r3[row] <= r2[row])) out.row(near[k]) = jets.row(near[k]);
  }
  return out;
}

using detail::select_normal;

/// select_normal at every vertex.
RowMatrixX3d select_normals(NormalsRef primary, const Eigen::VectorXd& primary_roughness,
                            NormalsRef secondary, const Eigen::VectorXd& secondary_roughness,
                            int threads) {
  RowMatrixX3d out(primary.rows(), 3);
  detail::parallel_for(primary.rows(), threads, [&](std::int64_t i) {
    out.row(i) = select_normal(primary.row(i).transpose(), primary_roughness[i],
                               secondary.row(i).transpose(), secondary_roughness[i], true)
                     .first.transpose();
  });
  return out;
}

/// Where the chosen normal has none (the jets had too few points, a degenerate fit): Max's
/// normal if any; turned to the file's side (`side`, -1 or +1; the fit's residuals do not
/// change: the rays are the same lines).
Eigen::Vector3d with_max_fallback(const Context& c, Eigen::Vector3d n, Eigen::Index i,
                                  double side) {
  if (!n.allFinite()) n = c.max.row(i).transpose();
  return side < 0.0 ? Eigen::Vector3d(-n) : n;
}

/// The positions' normal at vertex i on clean positions (the jets' `J` or Max's, by
/// select_normal on their roughness `rj`, `rm` there), as choose_normals picks it, and its
/// roughness.
std::pair<Eigen::Vector3d, double> positions_normal(const Context& c, NormalsRef J, double rj,
                                                    double rm, Eigen::Index i, double side) {
  const auto [n, r] = select_normal(J.row(i).transpose(), rj, c.max.row(i).transpose(), rm, true);
  return {with_max_fallback(c, n, i, side), r};
}

/// The vertices whose flag is set, ascending.
std::vector<int> flagged_vertices(const std::vector<char>& flag) {
  std::vector<int> out;
  for (std::size_t i = 0; i < flag.size(); ++i) {
    if (flag[i]) out.push_back(static_cast<int>(i));
  }
  return out;
}

/// The 2-ring cubic jets' normals at the listed vertices into their rows of J.
void add_jets_at(const Context& c, const std::vector<int>& vertices, RowMatrixX3d& J) {
  if (vertices.empty()) return;
  const JetNormals jets =
      detail::jet_normals_at(c.mesh.V(), *c.one_ring, c.max, jet_options(2, 3), vertices);
  for (std::size_t k = 0; k < vertices.size(); ++k) {
    J.row(vertices[k]) = jets.N.row(static_cast<Eigen::Index>(k));
  }
}

/// A file normal whose 1-ring roughness is above this many times the median of the file's is in
/// doubt (replace_outliers): a normal off by an angle a from the surface's leaves the rays of its
/// 1-ring misfit by about a in its frame, so an outlier of a few times the field's own roughness
/// stands out. Measured on focal eval's 89 cases (seed 1): 4.6% of the vertices in doubt.
constexpr double kDoubtfulRoughness = 3.0;

/// The file's normals, replaced by the positions' only at outliers: where a file normal is
/// unusable or gives no fit, or where it is more than `limit` radians from the jet normal and the
/// positions' normal (positions_normal) is clearly smoother. On a file whose normals agree with
/// the positions, such vertices are isolated bad normals; elsewhere the exact normals stay exact
/// (replacing them where two truncation-level residuals happen to differ by 2x cost up to 0.5%
/// of H error on clean irregular meshes). Only a normal in doubt by its own 1-ring fit (rougher
/// than kDoubtfulRoughness times the file's median `median_roughness`, a mesh-wide choice so
/// that a tile screens as the whole mesh; or none) is compared with its jet normal, and the jets
/// are computed there (and at the 1-rings of the outliers, whose roughness reads them):
/// elsewhere the file's normal is kept whatever they are.
RowMatrixX3d replace_outliers(const Context& c, NormalsRef file, double side, double limit,
                              double median_roughness) {
  const Eigen::VectorXd file_roughness = roughness_of(c, file);
  const double doubtful = kDoubtfulRoughness * median_roughness;
  RowMatrixX3d out(file.rows(), 3);
  std::vector<char> doubt(static_cast<std::size_t>(file.rows()));
  detail::parallel_for(file.rows(), 0, [&](std::int64_t i) {
    const Eigen::Vector3d a = file.row(i).transpose().normalized();
    out.row(i) = a.transpose();
    doubt[static_cast<std::size_t>(i)] = !a.allFinite() || !(file_roughness[i] <= doubtful);
  });
  const std::vector<int> in_doubt = flagged_vertices(doubt);
  if (in_doubt.empty()) return out;
  // Jet normals where computed, NaN elsewhere (never read there).
  RowMatrixX3d J = RowMatrixX3d::Constant(file.rows(), 3, NAN);
  add_jets_at(c, in_doubt, J);
  const auto may_replace = [&](Eigen::Index i) {
    const double disagreement = normal_angle(file.row(i).transpose(), side * J.row(i).transpose());
    return !(disagreement <= limit) || !std::isfinite(file_roughness[i]);
  };
  std::vector<int> at;
  for (const int i : in_doubt) {
    if (!out.row(i).allFinite() || may_replace(i)) at.push_back(i);
  }
  if (at.empty()) return out;
  std::vector<char> ring_of_outlier(static_cast<std::size_t>(file.rows()), 0);
  for (const int i : at) {
    for (const int* j = c.one_ring->begin(i); j != c.one_ring->end(i); ++j) {
      ring_of_outlier[static_cast<std::size_t>(*j)] = !doubt[static_cast<std::size_t>(*j)];
    }
  }
  add_jets_at(c, flagged_vertices(ring_of_outlier), J);
  const Eigen::VectorXd jets_roughness = roughness_at(c, J, at);
  const Eigen::VectorXd max_roughness = roughness_at(c, c.max, at);
  detail::parallel_for(static_cast<std::int64_t>(at.size()), 0, [&](std::int64_t k) {
    const int i = at[static_cast<std::size_t>(k)];
    const auto [b, rb] = positions_normal(c, J, jets_roughness[k], max_roughness[k], i, side);
    out.row(i) = select_normal(file.row(i).transpose(), file_roughness[i], b, rb, may_replace(i))
                     .first.transpose();
  });
  return out;
}

/// `N` with each row that points against the sum of its 1-ring neighbours' turned round. Under
/// strong noise a few jets fit in a frame tilted past 90 degrees (their first frame, Max's
/// normal, comes from folded faces); such a normal leaves every neighbour's ray out of its fit.
RowMatrixX3d turned_with_neighbours(const Context& c, RowMatrixX3d N) {
  std::vector<char> turn(static_cast<std::size_t>(N.rows()), 0);
  detail::parallel_for(N.rows(), 0, [&](std::int64_t i) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    const int v = static_cast<int>(i);
    for (const int* j = c.one_ring->begin(v); j != c.one_ring->end(v); ++j) {
      if (N.row(*j).allFinite()) sum += N.row(*j).transpose();
    }
    turn[static_cast<std::size_t>(i)] = N.row(i).dot(sum) < 0.0 ? 1 : 0;
  });
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    if (turn[static_cast<std::size_t>(i)]) N.row(i) = -N.row(i);
  }
  return N;
}

/// Rows of a jet's normal more than this angle from their patch normal (acos 0.5 = 60 degrees):
/// no smooth surface turns so much over a jet's rings; such a jet fitted a graph over a frame
/// that folded faces tilted.
constexpr double kRealignCosine = 0.5;

/// A patch's vector area against its area at least this (a patch that does not fold onto
/// itself: a thin part's two sides within the rings cancel) for its normal to judge a jet's.
constexpr double kFlatPatch = 0.5;

/// Each vertex's patch normal over `rings` rings: the faces' area vectors at each vertex
/// (columns 0-2) with their areas (column 3), summed over the vertex and its 1-ring `rings`
/// times: a weighted vector area of the faces within `rings` + 1 rings, unit, or zero where it
/// folds onto itself (kFlatPatch). Folded slivers, as strong noise makes them at a regular
/// mesh's pole, weigh by their small areas and do not turn it.
RowMatrixX3d patch_normals(const Context& c, int rings) {
  const PositionsRef& V = c.mesh.V();
  const FacesRef& F = c.mesh.F();
  const auto& incidence = *detail::incidence(c.mesh);
  using Sums = Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>;
  Sums sums(V.rows(), 4), next(V.rows(), 4);
  detail::parallel_for(V.rows(), 0, [&](std::int64_t v) {
    Eigen::Vector4d sum = Eigen::Vector4d::Zero();
    for (int k = incidence.begin(v); k < incidence.end(v); ++k) {
      const int f = incidence.faces[static_cast<std::size_t>(k)];
      const Eigen::Vector3d a = V.row(F(f, 0)).transpose();
      const Eigen::Vector3d n =
          (V.row(F(f, 1)).transpose() - a).cross(V.row(F(f, 2)).transpose() - a);
      if (n.allFinite()) sum += Eigen::Vector4d(n.x(), n.y(), n.z(), n.norm());
    }
    sums.row(v) = sum.transpose();
  });
  for (int r = 0; r < rings; ++r) {
    detail::parallel_for(V.rows(), 0, [&](std::int64_t v) {
      Eigen::RowVector4d sum = sums.row(v);
      const int u = static_cast<int>(v);
      for (const int* j = c.one_ring->begin(u); j != c.one_ring->end(u); ++j) sum += sums.row(*j);
      next.row(v) = sum;
    });
    sums.swap(next);
  }
  RowMatrixX3d out(V.rows(), 3);
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    const Eigen::Vector3d n = sums.row(v).head<3>().transpose();
    const double area = sums(v, 3);
    out.row(v) = area > 0.0 && n.norm() >= kFlatPatch * area ? Eigen::RowVector3d(n.normalized())
                                                             : Eigen::RowVector3d::Zero();
  }
  return out;
}

/// `N` (jets of options `o`) turned to the side of each row's patch normal over the jets'
/// rings where there is one, and each row still far from it (kRealignCosine) fitted again in
/// its frame, kept where the new jet is nearer to it. Folded faces come in clusters (a pole's
/// fan) whose Max normals, the jets' first frames, turn or tilt together, so that the 1-ring's
/// normals cannot tell; the patch reaches past the cluster.
RowMatrixX3d oriented_by_patches(const Context& c, RowMatrixX3d N, const JetOptions& o) {
  const RowMatrixX3d patch = patch_normals(c, o.rings);
  std::vector<int> far;
  for (Eigen::Index i = 0; i < N.rows(); ++i) {
    const Eigen::RowVector3d p = patch.row(i);
    if (p.isZero() || !N.row(i).allFinite()) continue;
    if (N.row(i).dot(p) < 0.0) N.row(i) = -N.row(i);
    if (N.row(i).dot(p) < kRealignCosine) far.push_back(static_cast<int>(i));
  }
  if (far.empty()) return N;
  // The refits' first frames: the patch normals (rows other than `far` are not read).
  const JetNormals refit = detail::jet_normals_at(c.mesh.V(), *c.one_ring, patch, o, far);
  for (std::size_t k = 0; k < far.size(); ++k) {
    const int v = far[k];
    const Eigen::RowVector3d n = refit.N.row(static_cast<Eigen::Index>(k));
    if (n.allFinite() && n.dot(patch.row(v)) > N.row(v).dot(patch.row(v))) N.row(v) = n;
  }
  return N;
}

/// A face at a vertex v: its normal and its corners other than v (the one there is twice, or a
/// value no corner has where there is none): two faces share an edge at v exactly when those
/// meet.
struct FaceAtVertex {
  Eigen::Vector3d normal;
  int other[2];
};

/// Faces at one vertex above which crease_vertices sorts them by corner instead of trying every
/// pair (a pair loop over 32 faces is 496 tests, cheaper than the sort).
constexpr std::size_t kPairsUpTo = 32;

/// Whether two of `faces` that share an edge (a corner other than v) have normals at an angle
/// whose cosine is below `cos_limit`: the pairs of faces listed under each corner, found by
/// sorting (face, corner) entries; `corners` is scratch.
bool any_crease_by_corner(const std::vector<FaceAtVertex>& faces, double cos_limit,
                          std::vector<std::pair<int, int>>& corners) {
  corners.clear();
  for (std::size_t a = 0; a < faces.size(); ++a) {
    const auto& o = faces[a].other;
    corners.emplace_back(o[0], static_cast<int>(a));
    if (o[1] != o[0]) corners.emplace_back(o[1], static_cast<int>(a));
  }
  std::sort(corners.begin(), corners.end());
  for (std::size_t first = 0; first < corners.size();) {
    std::size_t last = first + 1;
    while (last < corners.size() && corners[last].first == corners[first].first) ++last;
    for (std::size_t a = first; a < last; ++a) {
      for (std::size_t b = a + 1; b < last; ++b) {
        const auto& fa = faces[static_cast<std::size_t>(corners[a].second)];
        const auto& fb = faces[static_cast<std::size_t>(corners[b].second)];
        if (corners[a].second != corners[b].second && fa.normal.dot(fb.normal) < cos_limit)
          return true;
      }
    }
    first = last;
  }
  return false;
}

/// Crease vertices (recommended.h, step 5): corners of an edge whose two faces' normals differ
/// by more than RecommendedOptions::crease_angle. Per vertex, over pairs of its faces that
/// share an edge at it.
std::vector<char> crease_vertices(const Context& c) {
  const PositionsRef& V = c.mesh.V();
  const FacesRef& F = c.mesh.F();
  const auto& incidence = *detail::incidence(c.mesh);
  const double cos_limit = std::cos(c.options.crease_angle);
  // Each face's unit normal once (a face has three corners whose pairs read it).
  RowMatrixX3d face_normal(F.rows(), 3);
  detail::parallel_for_blocks(F.rows(), 4096, 0, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t f = begin; f < end; ++f) {
      const Eigen::Vector3d a = V.row(F(f, 0)).transpose(), b = V.row(F(f, 1)).transpose(),
                            d = V.row(F(f, 2)).transpose();
      face_normal.row(f) = (b - a).cross(d - a).normalized().transpose();
    }
  });
  const auto at_vertex = [&](int f, int v) {
    FaceAtVertex out{face_normal.row(f).transpose(), {-1 - f, -1 - f}};
    int found = 0;
    for (int x = 0; x < 3 && found < 2; ++x) {
      if (F(f, x) != v) out.other[found++] = F(f, x);
    }
    if (found == 1) out.other[1] = out.other[0];
    return out;
  };
  const auto share_edge = [](const FaceAtVertex& a, const FaceAtVertex& b) {
    return a.other[0] == b.other[0] || a.other[0] == b.other[1] || a.other[1] == b.other[0] ||
           a.other[1] == b.other[1];
  };
  std::vector<char> crease(static_cast<std::size_t>(c.mesh.vertex_count()), 0);
  detail::parallel_for_blocks(
      c.mesh.vertex_count(), 1024, 0, [&](std::int64_t begin, std::int64_t end) {
        // Each face's normal and corners once per vertex (a face meets two others at v).
        std::vector<FaceAtVertex> faces;
        std::vector<std::pair<int, int>> corners;  // any_crease_by_corner's scratch
        for (auto i = begin; i < end; ++i) {
          const int v = static_cast<int>(i);
          faces.clear();
          for (int a = incidence.begin(v); a < incidence.end(v); ++a)
            faces.push_back(at_vertex(incidence.faces[static_cast<std::size_t>(a)], v));
          if (faces.size() > kPairsUpTo) {
            // The centre of a fan of thousands of faces: the faces that share each corner, by
            // sorting, instead of every pair (quadratic); the same pairs are compared.
            crease[static_cast<std::size_t>(i)] = any_crease_by_corner(faces, cos_limit, corners);
            continue;
          }
          for (std::size_t a = 0; a < faces.size() && !crease[static_cast<std::size_t>(i)]; ++a) {
            for (std::size_t b = a + 1; b < faces.size(); ++b) {
              if (share_edge(faces[a], faces[b]) &&
                  faces[a].normal.dot(faces[b].normal) < cos_limit) {
                crease[static_cast<std::size_t>(i)] = 1;
                break;
              }
            }
          }
        }
      });
  return crease;
}

}  // namespace

std::vector<int> near_flagged(const Context& c, const std::vector<char>& flagged, int rings) {
  if (!c.one_ring) c.one_ring = detail::one_ring(c.mesh);
  // Nothing flagged (a mesh without creases): nothing near, without the search over every ring.
  if (std::none_of(flagged.begin(), flagged.end(), [](char f) { return f != 0; })) return {};
  const Eigen::VectorXi distance =
      rings_to_boundary(*c.one_ring, std::vector<bool>(flagged.begin(), flagged.end()), rings);
  std::vector<int> out;
  for (int i = 0; i < distance.size(); ++i) {
    if (distance[i] >= 1 && distance[i] <= rings) out.push_back(i);
  }
  return out;
}

RecommendedMeshWide choose_normals(const Context& c, RecommendedResult& out) {
  const std::optional<NormalsRef> file = c.mesh.normals();
  const bool has_normals = file.has_value();
  // Without file normals the jets of every vertex are the clean plan's normals: computed once.
  std::optional<JetNormals> all_jets;
  if (!has_normals) all_jets = local_jets(c, 2, 3);
  const RecommendedMeshWide mesh_wide = c.options.mesh_wide
                                            ? *c.options.mesh_wide
                                            : measure_mesh_wide(c, all_jets ? &*all_jets : nullptr);
  out.plan = plan_for(mesh_wide, c.options);
  // The file's side (a tile takes the whole mesh's); normals from the positions take the side of
  // the faces until turned.
  const double side = has_normals ? mesh_wide.side : 1.0;
  out.file_disagreement = mesh_wide.file_disagreement;
  out.file_normals_used = has_normals && file_normals_agree(out.file_disagreement, out.plan.noise,
                                                            c.options.file_agreement);
  if (out.file_normals_used) {
    // The file's normals, except outliers where the positions' choice is clearly smoother.
    out.N = replace_outliers(c, *file, side, c.options.outlier_disagreement * out.plan.noise,
                             mesh_wide.file_roughness);
  } else {
    if (out.plan.rings > 1) {
      // Noisy positions: normals from wider, lower-degree jets that average the noise.
      JetOptions o = jet_options(out.plan.jet_rings, out.plan.jet_degree);
      o.iterations = out.plan.jet_iterations;
      out.N = oriented_by_patches(
          c,
          turned_with_neighbours(c, detail::jet_normals_from(c.mesh.V(), *c.one_ring, c.max, o).N),
          o);
    } else {
      // The jets where Max's normals are not clearly smoother: Max's are exact on spheres, but
      // first-order (rough) on irregular meshes.
      if (!all_jets) all_jets = local_jets(c, 2, 3);
      const RowMatrixX3d J = with_boundary_jets(c, all_jets->N);
      out.N = select_normals(J, roughness_of(c, J), c.max, roughness_of(c, c.max), 0);
    }
    for (Eigen::Index i = 0; i < out.N.rows(); ++i) {
      if (side > 0.0 && out.N.row(i).allFinite()) continue;  // nothing to change
      out.N.row(i) = with_max_fallback(c, out.N.row(i).transpose(), i, side).transpose();
    }
  }
  if (out.plan.rings == 1 && c.options.crease_angle > 0.0) {
    // Creases on clean positions: jets over the 2-ring mix the pieces' normals; each face lies
    // on one piece, so Max's normals (of the faces) stay on their piece.
    const std::vector<char> crease = crease_vertices(c);
    out.crease = Eigen::Map<const Eigen::Matrix<char, Eigen::Dynamic, 1>>(
                     crease.data(), static_cast<Eigen::Index>(crease.size()))
                     .cast<std::uint8_t>();
    // Used file normals are kept there where they agree with Max's normal within half the
    // crease angle (the jets they were judged against mix the pieces); others take Max's.
    const double agree = std::cos(0.5 * c.options.crease_angle);
    for (const int v : near_flagged(c, crease, 2)) {
      const Eigen::RowVector3d max = side * c.max.row(v);
      const bool keep_file = out.file_normals_used && file->row(v).normalized().dot(max) > agree;
      out.N.row(v) = keep_file ? Eigen::RowVector3d(file->row(v).normalized()) : max;
    }
  }
  return mesh_wide;
}

}  // namespace focal::detail::recommended
