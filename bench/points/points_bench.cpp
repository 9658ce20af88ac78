// Stage times of focal's cloud path on a random torus cloud (uniform by area, exact normals):
// kd-tree + k nearest neighbours, the two-slit fit, and normals estimated and oriented (PCA + MST
// + jets). Prints wall and process CPU seconds per stage; wall times on a shared machine are
// noisy, CPU seconds less so (docs/POINTS.md).
//
// Usage: focal_points_bench [POINTS=1000000] [K=16] [THREADS=0]

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <numbers>
#include <random>

#include "curvature/vertex_fit.h"
#include "focal/core/execution.h"
#include "focal/curvature/cloud_curvature.h"
#include "focal/normals/cloud_normals.h"
#include "focal/points/neighbours.h"
#include "mesh/prepared_access.h"

namespace {

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

class Timer {
 public:
  explicit Timer(const char* name) : name_(name) {}
  ~Timer() {
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_).count();
    std::printf("%-28s wall %8.3f s   cpu %8.3f s\n", name_, wall, cpu_seconds() - cpu_);
  }

 private:
  const char* name_;
  std::chrono::steady_clock::time_point wall_ = std::chrono::steady_clock::now();
  double cpu_ = cpu_seconds();
};

/// Torus (R = 1, r = 0.4) points uniform by area: v accepted with probability (R + r cos v) / (R +
/// r).
void torus_cloud(int n, focal::RowMatrixX3d& V, focal::RowMatrixX3d& N) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * std::numbers::pi), unit(0.0, 1.0);
  V.resize(n, 3), N.resize(n, 3);
  for (int i = 0; i < n;) {
    const double u = angle(rng), v = angle(rng);
    if (unit(rng) * 1.4 > 1.0 + 0.4 * std::cos(v)) continue;
    const Eigen::RowVector3d normal(std::cos(v) * std::cos(u), std::cos(v) * std::sin(u),
                                    std::sin(v));
    N.row(i) = normal;
    V.row(i) = Eigen::RowVector3d(std::cos(u), std::sin(u), 0.0) + 0.4 * normal;
    ++i;
  }
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 1000000;
  const int k = argc > 2 ? std::atoi(argv[2]) : 16;
  const int threads = argc > 3 ? std::atoi(argv[3]) : 0;
  focal::RowMatrixX3d V, N;
  torus_cloud(n, V, N);
  std::printf("%d points, k = %d, threads = %d\n", n, k, threads);
  const focal::ExecutionScope scope({.threads = threads});
  focal::Neighbourhoods nb;
  {
    Timer t("kd-tree + kNN");
    nb = focal::nearest_neighbours(V, k);
  }
  std::vector<char> ok;
  const focal::RowMatrixX3d unit = focal::detail::unit_rows(N, ok);
  {
    Timer t("two-slit fit (closed form)");
    focal::CurvatureOptions o;
    const auto r = focal::detail::fit_vertices({V, unit, ok, nb, 0.003}, o);
    std::printf("  (H of point 0: %.6f)\n", r.H[0]);
  }
  {
    Timer t("PCA normals");
    (void)focal::pca_normals(V, nb);
  }
  {
    Timer t("cloud_normals (PCA+MST+jet)");
    (void)focal::cloud_normals(V, nb, {});
  }
  {
    Timer t("estimate_cloud_curvature");
    (void)focal::estimate_cloud_curvature(V, focal::NormalsRef(N), {.k = k});
  }
  return 0;
}
