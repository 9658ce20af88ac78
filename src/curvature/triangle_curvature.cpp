#include "focal/curvature/triangle_curvature.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "core/simd_lanes.h"
#include "curvature/normal_rays_detail.h"
#include "curvature/triangle_fit.h"
#include "curvature/vertex_rows.h"
#include "focal/core/error.h"
#include "focal/curvature/normal_rays.h"
#include "kernels/local_shape.h"
#include "kernels/triplet.h"
#include "kernels/vec3.h"
#include "mesh/prepared_access.h"
#include "mesh/topology.h"

namespace focal {
namespace {

/// A result of m faces with the asked fields allocated but not written: each face's row is then
/// written once (values or NaN) by the thread that computes it, so nothing is filled twice and
/// the pages are first touched in parallel.
TriangleCurvatureResult unwritten_faces(Eigen::Index m, const TriangleFields& want) {
  TriangleCurvatureResult r;
  // Huge pages where the kernel grants them: at 2M faces the asked fields are up to 450 MB,
  // otherwise first-touched 4 KiB at a time (see detail::advise_huge_pages).
  const auto scalars = [&](bool asked, std::initializer_list<Eigen::VectorXd*> fields) {
    for (Eigen::VectorXd* v : fields) {
      v->resize(asked ? m : 0);
      detail::advise_huge_pages(v->data(), sizeof(double) * static_cast<std::size_t>(v->size()));
    }
  };
  scalars(want.coefficients, {&r.A, &r.B, &r.C});
  scalars(want.curvatures, {&r.K, &r.H, &r.k1, &r.k2});
  scalars(want.focal_depths, {&r.lambda1, &r.lambda2});
  const auto vectors = [&](bool asked, std::initializer_list<RowMatrixX3d*> fields) {
    for (RowMatrixX3d* d : fields) {
      d->resize(asked ? m : 0, 3);
      detail::advise_huge_pages(d->data(), sizeof(double) * static_cast<std::size_t>(d->size()));
    }
  };
  vectors(want.directions, {&r.d1, &r.d2});
  vectors(want.slits, {&r.slit1, &r.slit2});
  vectors(want.face_normal, {&r.face_normal});
  r.shape_operator.resize(want.shape_operator ? m : 0, 4);
  detail::advise_huge_pages(r.shape_operator.data(),
                            sizeof(double) * static_cast<std::size_t>(r.shape_operator.size()));
  r.point_class.resize(m);
  return r;
}

// ---- The per-face solve, one face per lane.
//
// Faces in groups of the lane width (simd_lanes.h), each lane running the characteristic
// equation of kernels/triplet.h (the formula the device's per-triangle and image-space kernels
// run in float): the three vertex rays in the frame of the face's mean normal, the sagitta
// shift, the curvatures and, where asked, directions, slits and the shape operator, all as
// selects per lane; faces without a solution get NaN and `undefined`. No lane reads another, so
// every instruction set and thread count gives the same bits, those of the formula on scalar
// doubles (tests/triangle_curvature_test.cpp compares the two).

using detail::broadcast;
using detail::lane_count;
using detail::lanes_of;
using detail::MaskOf;
using kernels::Vec3;

/// What the per-vertex averaging reads of a solved face, written once per face by the face
/// kernel instead of being recomputed at each of the face's three corners: the face's frame (its
/// normal and the axes kernels::frame_of gives it, the bits frame_of gives there), its
/// symmetrised shape operator [s00 s01; s01 s11] and its area. Unspecified where the face is
/// undefined (the averaging skips those).
struct FaceRecord {
  double n[3], x[3], y[3];
  double s00, s01, s11;
  double area;
};

/// What the face kernel reads.
struct FaceInput {
  PositionsRef V;
  const RowMatrixX3d& N;        ///< unit normals (unit_rows)
  const std::vector<char>& ok;  ///< normal flags (unit_rows)
  FacesRef F;
  detail::ClassTolerances tol;
  const TriangleFields& want;
  FaceRecord* records = nullptr;  ///< where set, row f of F's record is written there too
};

/// Stores lanes [0, active) of x at rows first... of v (one vector store for a whole group).
template <class L>
FOCAL_LANE_INLINE void store_scalars(Eigen::VectorXd& v, std::int64_t first, int active, L x) {
  if (active == lane_count<L>) return detail::store_lanes(v.data() + first, x);
  for (int l = 0; l < active; ++l) v[first + l] = x[l];
}

template <class L>
FOCAL_LANE_INLINE void store_rows(RowMatrixX3d& m, std::int64_t first, int active, L x, L y, L z) {
  double* row = m.data() + 3 * first;
  for (int l = 0; l < active; ++l) row[3 * l] = x[l], row[3 * l + 1] = y[l], row[3 * l + 2] = z[l];
}

/// Half the length of (b - a) x (c - a) for the corners a, b, c: the operations of Eigen's
/// `0.5 * (b - a).cross(c - a).norm()` (kernels/vec3.h keeps Eigen's order), which the averaging
/// computed at each of the face's corners before, so the area keeps its bits.
template <class L>
FOCAL_LANE_INLINE L face_area_of(const Vec3<L> (&p)[3]) {
  return 0.5 * kernels::norm(kernels::cross(p[1] - p[0], p[2] - p[0]));
}

/// The records (FaceRecord) of faces [first, first + active) from their frame, shape operator M
/// and area.
template <class L>
FOCAL_LANE_INLINE void store_records(FaceRecord* records, int active,
                                     const kernels::Frame<L>& frame, const triplet::Mat2<L>& M,
                                     L area) {
  const L s01 = 0.5 * (M.b + M.c);
  for (int l = 0; l < active; ++l) {
    FaceRecord& r = records[l];
    r.n[0] = frame.n.x[l], r.n[1] = frame.n.y[l], r.n[2] = frame.n.z[l];
    r.x[0] = frame.x.x[l], r.x[1] = frame.x.y[l], r.x[2] = frame.x.z[l];
    r.y[0] = frame.y.x[l], r.y[1] = frame.y.y[l], r.y[2] = frame.y.z[l];
    r.s00 = M.a[l], r.s01 = s01[l], r.s11 = M.d[l];
    r.area = area[l];
  }
}

/// Solves faces [first, first + active) and writes their asked fields.
template <class L>
FOCAL_LANE_INLINE void solve_face_group(const FaceInput& in, std::int64_t first, int active,
                                        TriangleCurvatureResult& r) {
  constexpr int W = lane_count<L>;
  int corner[3][W];
  for (int l = 0; l < W; ++l) {
    const std::int64_t f = first + std::min(l, active - 1);
    for (int c = 0; c < 3; ++c) corner[c][l] = in.F(f, c);
  }
  const auto column = [&](const auto& matrix, int c, int col) FOCAL_LANE_LAMBDA {
    return lanes_of<L>([&](int l) { return matrix(corner[c][l], col); });
  };
  Vec3<L> p[3], n[3];
  auto valid = lanes_of<L>([](int l) { return static_cast<double>(l); }) < active;
  for (int c = 0; c < 3; ++c) {
    p[c] = {column(in.V, c, 0), column(in.V, c, 1), column(in.V, c, 2)};
    n[c] = {column(in.N, c, 0), column(in.N, c, 1), column(in.N, c, 2)};
    valid &= lanes_of<MaskOf<L>>([&](int l) {
      return in.ok[static_cast<std::size_t>(corner[c][l])] ? std::int64_t{-1} : std::int64_t{0};
    });
  }
  const triplet::Equation<L> e = triplet::characteristic_equation(p, n, valid);
  const kernels::Frame<L>& frame = e.frame;
  const L nan = broadcast<L>(std::numeric_limits<double>::quiet_NaN());
  const auto or_nan = [&](L x) FOCAL_LANE_LAMBDA { return e.valid ? x : nan; };
  const TriangleFields& want = in.want;
  if (want.coefficients) {
    store_scalars(r.A, first, active, or_nan(e.A)), store_scalars(r.B, first, active, or_nan(e.B));
    store_scalars(r.C, first, active, or_nan(e.C));
  }
  if (want.curvatures) {
    store_scalars(r.K, first, active, or_nan(e.K)), store_scalars(r.H, first, active, or_nan(e.H));
    store_scalars(r.k1, first, active, or_nan(e.k1));
    store_scalars(r.k2, first, active, or_nan(e.k2));
  }
  if (want.focal_depths) {
    store_scalars(r.lambda1, first, active, or_nan(e.lambda1));
    store_scalars(r.lambda2, first, active, or_nan(e.lambda2));
  }
  // In double the equation is solved in world units (triplet::Precision): e.M is the shape
  // operator itself.
  static_assert(!triplet::Precision<double>::scaled);
  if (in.records) store_records(in.records + first, active, frame, e.M, face_area_of(p));
  if (want.shape_operator) {
    double* row = r.shape_operator.data() + 4 * first;
    const L m00 = or_nan(e.M.a), m01 = or_nan(e.M.b), m10 = or_nan(e.M.c), m11 = or_nan(e.M.d);
    for (int l = 0; l < active; ++l) {
      row[4 * l] = m00[l], row[4 * l + 1] = m01[l], row[4 * l + 2] = m10[l];
      row[4 * l + 3] = m11[l];
    }
  }
  if (want.directions || want.slits) {
    const kernels::Principal<L> d = triplet::principal_directions(e);
    const auto to_3d = [&](L a, L b, RowMatrixX3d& m) FOCAL_LANE_LAMBDA {
      const Vec3<L> w = frame.from_plane(a, b);
      store_rows(m, first, active, or_nan(w.x), or_nan(w.y), or_nan(w.z));
    };
    if (want.directions) to_3d(d.d1x, d.d1y, r.d1), to_3d(-d.d1y, d.d1x, r.d2);
    if (want.slits) {
      L s1x, s1y, s2x, s2y;
      triplet::slits_in_plane(e, d, s1x, s1y, s2x, s2y);
      to_3d(s1x, s1y, r.slit1), to_3d(s2x, s2y, r.slit2);
    }
  }
  if (want.face_normal) {
    store_rows(r.face_normal, first, active, or_nan(frame.n.x), or_nan(frame.n.y),
               or_nan(frame.n.z));
  }
  const auto point_class = e.valid ? kernels::classify(e.k1, e.k2, in.tol.zero, in.tol.umbilic)
                                   : kernels::class_code<L>(PointClass::undefined);
  for (int l = 0; l < active; ++l) {
    r.point_class[first + l] = static_cast<std::uint8_t>(point_class[l]);
  }
}

template <class L>
FOCAL_LANE_INLINE void solve_face_block_lanes(const FaceInput& in, std::int64_t begin,
                                              std::int64_t end, TriangleCurvatureResult& r) {
  constexpr int W = lane_count<L>;
  for (std::int64_t first = begin; first < end; first += W) {
    solve_face_group<L>(in, first, static_cast<int>(std::min<std::int64_t>(W, end - first)), r);
  }
}

FOCAL_TARGET_AVX512 void solve_face_block_avx512(const FaceInput& in, std::int64_t begin,
                                                 std::int64_t end, TriangleCurvatureResult& r) {
  solve_face_block_lanes<detail::Lanes8>(in, begin, end, r);
}
FOCAL_TARGET_AVX2 void solve_face_block_avx2(const FaceInput& in, std::int64_t begin,
                                             std::int64_t end, TriangleCurvatureResult& r) {
  solve_face_block_lanes<detail::Lanes4>(in, begin, end, r);
}
void solve_face_block_baseline(const FaceInput& in, std::int64_t begin, std::int64_t end,
                               TriangleCurvatureResult& r) {
  solve_face_block_lanes<detail::Lanes2>(in, begin, end, r);
}

using FaceBlock = void (*)(const FaceInput&, std::int64_t, std::int64_t, TriangleCurvatureResult&);

FaceBlock solve_face_block_for(detail::SimdIsa isa) {
  return detail::kernel_for(isa, solve_face_block_avx512, solve_face_block_avx2,
                            solve_face_block_baseline);
}

/// The minimal rotation taking unit a to unit b (Rodrigues; a.b > -1 holds since both normals
/// lie in each other's hemisphere here): its axis a x b and cosine a.b, computed once for the
/// two face axes it turns. In plain scalars (kernels/vec3.h, Eigen's order of operations: the
/// bits of the Eigen code it replaced), which pack into no SSE pairs.
struct Rotation {
  Vec3<double> axis;
  double c;

  Rotation(const Vec3<double>& a, const Vec3<double>& b)
      : axis(kernels::cross(a, b)), c(kernels::dot(a, b)) {}
  /// The rotation applied to w: w + axis x w + axis x (axis x w) / (1 + c).
  [[nodiscard]] Vec3<double> operator()(const Vec3<double>& w) const {
    const Vec3<double> once = kernels::cross(axis, w), twice = kernels::cross(axis, once);
    const double d = 1.0 + c;
    return {(w.x + once.x) + twice.x / d, (w.y + once.y) + twice.y / d,
            (w.z + once.z) + twice.z / d};
  }
};

/// The face's symmetrised shape operator in a vertex's tangent frame: the face frame is rotated
/// onto the vertex's tangent plane (a rotation, not a projection, so that a face operator kI
/// stays kI exactly, as on a sphere).
Eigen::Matrix2d operator_in_frame(const FaceRecord& face, const TangentFrame& to) {
  const auto vec = [](const double* v) { return Vec3<double>{v[0], v[1], v[2]}; };
  Eigen::Matrix2d sym;
  sym << face.s00, face.s01, face.s01, face.s11;
  const Rotation rotate(vec(face.n), kernels::vec3_of(to.n));
  const Vec3<double> x = rotate(vec(face.x)), y = rotate(vec(face.y));
  const Vec3<double> to_x = kernels::vec3_of(to.x), to_y = kernels::vec3_of(to.y);
  Eigen::Matrix2d q;  // orthogonal change of basis from the rotated face axes to (to.x, to.y)
  q << kernels::dot(to_x, x), kernels::dot(to_x, y), kernels::dot(to_y, x), kernels::dot(to_y, y);
  return q * sym * q.transpose();
}

}  // namespace

TriangleCurvatureResult triangle_curvature(const PreparedMesh& mesh,
                                           const CurvatureOptions& options,
                                           const TriangleFields& fields) {
  return detail::triangle_curvature(mesh, options, fields, detail::SimdIsa::best);
}

TriangleCurvatureResult triangle_curvature(PositionsRef V, FacesRef F, NormalsRef N,
                                           const CurvatureOptions& options) {
  return triangle_curvature(V, F, N, options, TriangleFields{});
}

TriangleCurvatureResult triangle_curvature(PositionsRef V, FacesRef F, NormalsRef N,
                                           const CurvatureOptions& options,
                                           const TriangleFields& fields) {
  return detail::triangle_curvature(V, F, N, options, fields, detail::SimdIsa::best);
}

TriangleCurvatureResult detail::triangle_curvature(PositionsRef V, FacesRef F, NormalsRef N,
                                                   const CurvatureOptions& options,
                                                   const TriangleFields& fields, SimdIsa isa) {
  return triangle_curvature(PreparedAccess::make(V, F, N, {}, "triangle curvature"), options,
                            fields, isa);
}

namespace {

/// The asked fields of the faces F (any subset of a mesh's faces: each face's row depends on its
/// own corners only, so it has the same bits in any subset).
TriangleCurvatureResult solve_faces(const FaceInput& in, detail::SimdIsa isa, int threads) {
  TriangleCurvatureResult r = unwritten_faces(in.F.rows(), in.want);
  const FaceBlock solve_block = solve_face_block_for(isa);
  // Blocks are whole groups of every lane width, so each face's row is written by one thread.
  detail::parallel_for_blocks(
      in.F.rows(), 1024, threads,
      [&](std::int64_t begin, std::int64_t end) { solve_block(in, begin, end, r); });
  return r;
}

}  // namespace

TriangleCurvatureResult detail::triangle_curvature(const PreparedMesh& mesh,
                                                   const CurvatureOptions& options,
                                                   const TriangleFields& fields, SimdIsa isa) {
  if (!mesh.has_normals()) throw InvalidInput("triangle curvature: the mesh has no normals");
  const UnitNormals& unit = unit_normals(mesh);
  const ClassTolerances tol = class_tolerances(options, mesh.mean_edge_length());
  return solve_faces({mesh.V(), unit.N, unit.ok, mesh.F(), tol, fields}, isa, 0);
}

namespace {

/// One face's part of a vertex's mean operator.
struct FacePart {
  double area;
  Eigen::Matrix2d op;
};

/// Vertex i's estimate from its faces: the principal curvatures of the area-weighted mean of
/// its usable faces' operators, their spread about it, and how many faces were used and left out.
struct VertexAverage {
  TangentFrame frame;
  detail::Principal2 principal;
  double spread = 0.0;
  int used = 0, excluded = 0;
  bool defined = false;
};

/// The solved faces of a block of vertices: face f of the mesh is row row[f] of `faces` and of
/// `records`.
struct SolvedFaces {
  TriangleCurvatureResult faces;
  const std::vector<FaceRecord, detail::DefaultInitAllocator<FaceRecord>>& records;
  const std::vector<int>& row;
};

/// Area-weighted mean of the operators of vertex i's usable faces, and their spread about it.
VertexAverage average_at_vertex(const SolvedFaces& solved, const detail::VertexFaces& inc,
                                const RowMatrixX3d& unit, Eigen::Index i,
                                std::vector<FacePart>& parts) {
  VertexAverage out;
  out.frame = detail::frame_of(unit.row(i).transpose());
  const TangentFrame& frame = out.frame;
  const TriangleCurvatureResult& faces = solved.faces;
  parts.clear();
  Eigen::Matrix2d mean = Eigen::Matrix2d::Zero();
  double area = 0.0;
  for (int k = inc.begin(i); k < inc.end(i); ++k) {
    const int f = inc.faces[static_cast<std::size_t>(k)];
    const int s = solved.row[static_cast<std::size_t>(f)];
    const FaceRecord& face = solved.records[static_cast<std::size_t>(s)];
    if (faces.point_class[s] == static_cast<std::uint8_t>(PointClass::undefined) ||
        !(Eigen::Map<const Eigen::Vector3d>(face.n).dot(frame.n) > 0.0)) {
      continue;
    }
    parts.push_back({face.area, operator_in_frame(face, frame)});
    mean += parts.back().area * parts.back().op;
    area += parts.back().area;
  }
  out.used = static_cast<int>(parts.size());
  out.excluded = inc.size(i) - out.used;
  if (!(area > 0.0)) return out;
  mean /= area;
  double spread = 0.0;
  for (const auto& [a, m] : parts) spread += a * (m - mean).squaredNorm();
  out.principal =
      detail::principal_from_symmetric(mean(0, 0), 0.5 * (mean(0, 1) + mean(1, 0)), mean(1, 1));
  out.spread = std::sqrt(spread / area);
  out.defined = true;
  return out;
}

/// Row i of `r` from vertex i's estimate (undefined where it has none).
void store_average(const VertexAverage& a, const detail::ClassTolerances& tol, Eigen::Index i,
                   CurvatureResult& r) {
  r.rays_used[i] = a.used;
  r.rays_excluded[i] = a.excluded;
  if (!a.defined) return detail::store_undefined(r, i);
  detail::store_vertex(r, i, a.frame, a.principal, a.spread, tol);
}

/// Vertices whose faces are solved at a time: their records and classes (105 B a face, ~7 MB a
/// block) instead of the whole mesh's (210 MB at 2M faces; the face operators, normals and
/// classes alone made the peak of the recommended estimator's run). Half the block of the 57 B
/// a face before the records: the same memory in the pass.
constexpr std::int64_t kAverageBlock = std::int64_t{1} << 15;

/// The faces of vertices [begin, end) that have a valid normal, each once: their indices and
/// corners, row[f] set to f's position in them (to be reset to -1 by the caller).
struct BlockFaces {
  std::vector<int> listed;
  RowMatrixX3i F;
};
BlockFaces faces_of_block(FacesRef F, const detail::VertexFaces& inc, const std::vector<char>& ok,
                          std::int64_t begin, std::int64_t end, std::vector<int>& row) {
  BlockFaces out;
  for (auto i = begin; i < end; ++i) {
    if (!ok[static_cast<std::size_t>(i)]) continue;
    for (int k = inc.begin(i); k < inc.end(i); ++k) {
      const int f = inc.faces[static_cast<std::size_t>(k)];
      int& r = row[static_cast<std::size_t>(f)];
      if (r < 0) r = static_cast<int>(out.listed.size()), out.listed.push_back(f);
    }
  }
  out.F.resize(static_cast<Eigen::Index>(out.listed.size()), 3);
  for (std::size_t k = 0; k < out.listed.size(); ++k) {
    out.F.row(static_cast<Eigen::Index>(k)) = F.row(out.listed[k]);
  }
  return out;
}

/// Runs body(i, average) for every vertex with a valid normal, body(i, nullopt) for the others,
/// in parallel blocks (each row visited by one thread).
template <class Body>
void for_each_average(const PreparedMesh& mesh, const CurvatureOptions& options, Body&& body) {
  // Only what the averaging reads: the faces' records and classes.
  TriangleFields needed;
  needed.coefficients = needed.curvatures = needed.focal_depths = false;
  needed.directions = needed.slits = needed.face_normal = needed.shape_operator = false;
  if (!mesh.has_normals()) throw InvalidInput("triangle curvature: the mesh has no normals");
  const PositionsRef& V = mesh.V();
  const FacesRef& F = mesh.F();
  const detail::UnitNormals& unit_normals = detail::unit_normals(mesh);
  const RowMatrixX3d& unit = unit_normals.N;
  const std::vector<char>& ok = unit_normals.ok;
  const std::shared_ptr<const detail::VertexFaces> incidence = detail::incidence(mesh);
  const detail::VertexFaces& inc = *incidence;
  const detail::ClassTolerances tol = detail::class_tolerances(options, mesh.mean_edge_length());
  std::vector<int> row(static_cast<std::size_t>(F.rows()), -1);
  // Written in full by the face kernel (each row by the thread that solves its face).
  std::vector<FaceRecord, detail::DefaultInitAllocator<FaceRecord>> records;
  for (std::int64_t first = 0; first < V.rows(); first += kAverageBlock) {
    const std::int64_t last = std::min<std::int64_t>(V.rows(), first + kAverageBlock);
    const BlockFaces block = faces_of_block(F, inc, ok, first, last, row);
    records.resize(static_cast<std::size_t>(block.F.rows()));
    const SolvedFaces solved{
        solve_faces({V, unit, ok, block.F, tol, needed, records.data()}, detail::SimdIsa::best, 0),
        records, row};
    // Scratch per block of vertices, as in the per-vertex fit: no allocation per vertex.
    detail::parallel_for_blocks(last - first, 256, 0, [&](std::int64_t begin, std::int64_t end) {
      std::vector<FacePart> parts;
      for (auto i = first + begin; i < first + end; ++i) {
        if (ok[static_cast<std::size_t>(i)]) {
          body(i, std::optional<VertexAverage>(average_at_vertex(solved, inc, unit, i, parts)));
        } else {
          body(i, std::optional<VertexAverage>());
        }
      }
    });
    for (int f : block.listed) row[static_cast<std::size_t>(f)] = -1;
  }
}

}  // namespace

CurvatureResult detail::vertex_curvature_from_triangles(const PreparedMesh& mesh,
                                                        const CurvatureOptions& options) {
  const ClassTolerances tol = class_tolerances(options, mesh.mean_edge_length());
  CurvatureResult r = detail::unwritten_result(mesh.vertex_count());
  for_each_average(mesh, options, [&](Eigen::Index i, const std::optional<VertexAverage>& a) {
    if (a) return store_average(*a, tol, i, r);
    detail::store_undefined(r, i);
    r.rays_used[i] = r.rays_excluded[i] = 0;
  });
  return r;
}

void detail::replace_with_triangles(const PreparedMesh& mesh, const CurvatureOptions& options,
                                    const std::vector<char>& replace, CurvatureResult& r) {
  const ClassTolerances tol = class_tolerances(options, mesh.mean_edge_length());
  for_each_average(mesh, options, [&](Eigen::Index i, const std::optional<VertexAverage>& a) {
    // As a copied row: only where the class the row would get is not undefined (NaN curvatures).
    if (!a || !a->defined || !replace[static_cast<std::size_t>(i)]) return;
    const Principal2& p = a->principal;
    if (classify(p.k1, p.k2, tol.zero, tol.umbilic) == PointClass::undefined) return;
    store_average(*a, tol, i, r);
  });
}

}  // namespace focal
