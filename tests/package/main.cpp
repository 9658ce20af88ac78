// Consumer of the installed focal package: the curvature of a regular icosahedron whose vertices
// lie on the unit sphere, with normals v / |v|. Every normal ray passes through the centre, so
// every vertex has k1 = k2 = 1 up to rounding, class umbilic. Exit status 0 when all checks pass.

#include <focal/focal.h>

#include <cmath>
#include <cstdio>
#include <string_view>

namespace {

focal::Mesh icosahedron() {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  focal::Mesh mesh;
  mesh.V.resize(12, 3);
  mesh.V << -1, t, 0, 1, t, 0, -1, -t, 0, 1, -t, 0,  //
      0, -1, t, 0, 1, t, 0, -1, -t, 0, 1, -t,        //
      t, 0, -1, t, 0, 1, -t, 0, -1, -t, 0, 1;
  mesh.V.rowwise().normalize();
  mesh.F.resize(20, 3);
  mesh.F << 0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6,
      7, 1, 8, 3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9,
      8, 1;
  mesh.N = mesh.V;  // the unit sphere's outward normals
  return mesh;
}

}  // namespace

int main() {
  const focal::Mesh mesh = icosahedron();
  const focal::CurvatureResult c = focal::estimate_curvature(mesh.V, mesh.F, mesh.N);

  // The rays meet exactly at the centre: only rounding separates k from 1.
  constexpr double kTolerance = 1e-12;
  int failures = 0;
  for (int i = 0; i < mesh.V.rows(); ++i) {
    const std::string_view name = focal::class_name(c.class_of(i));
    const bool ok = std::abs(c.k1[i] - 1.0) <= kTolerance &&
                    std::abs(c.k2[i] - 1.0) <= kTolerance && std::abs(c.H[i] - 1.0) <= kTolerance &&
                    std::abs(c.K[i] - 1.0) <= kTolerance && name == "umbilic";
    std::printf("vertex %2d: k1 = %.17g, k2 = %.17g, %.*s%s\n", i, c.k1[i], c.k2[i],
                static_cast<int>(name.size()), name.data(),
                ok ? "" : "   <-- expected 1, 1, umbilic");
    if (!ok) ++failures;
  }

  // A mesh prepared once for several calls (docs/GUIDE.md): the same bits as on the arrays.
  const focal::PreparedMesh prepared(mesh);
  const auto check = [&failures](bool ok, const char* what) {
    if (!ok) {
      std::printf("%s\n", what);
      ++failures;
    }
  };
  check(!focal::check_mesh(prepared).has_problems(), "check_mesh found problems");
  check(focal::estimate_curvature(prepared).k1 == c.k1, "prepared: other k1");
  // The front door (README, C++): the paper's method on the file's normals is the same fit.
  const focal::Estimate door = focal::curvature(mesh, {.estimator = focal::Estimator::paper});
  check(door.curvature.k1 == c.k1 && door.undefined_count == 0, "curvature(paper): other k1");
  const focal::Estimate e = focal::estimate(prepared, {.estimator = focal::Estimator::paper});
  check(!e.N.has_value() && e.curvature.k1 == c.k1, "estimate(paper): other k1 or normals");
  const focal::RecommendedResult r =
      focal::estimate_curvature_recommended(mesh.V, mesh.F, mesh.normals());
  check(r.curvature.k1.size() == 12 && r.N.rows() == 12, "recommended: wrong shapes");
  const focal::FocalMeshes f = focal::focal_meshes(prepared.with_normals(r.N), r.curvature);
  check(f.gamma1.mesh.V.rows() == 12, "focal meshes: wrong shapes");
  // The vertices as a point cloud (the kd-tree, nanoflann, is private to the library): exact
  // with exact normals over the k nearest, as on the mesh.
  const focal::CloudCurvature cloud =
      focal::estimate_cloud_curvature(mesh.V, mesh.normals(), {.k = 5});
  check((cloud.curvature.k1.array() - 1.0).abs().maxCoeff() <= kTolerance, "cloud: k1 != 1");

  // The library's errors cross the package boundary as focal::InvalidInput.
  focal::RowMatrixX3i bad = mesh.F;
  bad(0, 0) = 12;
  try {
    (void)focal::estimate_curvature(mesh.V, bad, mesh.N);
    std::printf("a face index out of range was not rejected\n");
    ++failures;
  } catch (const focal::InvalidInput& e) {
    std::printf("face index out of range rejected: %s\n", e.what());
  }

  std::printf("%s\n", failures == 0 ? "focal package: OK" : "focal package: FAILED");
  return failures == 0 ? 0 : 1;
}
