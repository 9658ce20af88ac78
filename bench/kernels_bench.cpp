// Google Benchmark of the pipeline's stages on regular tori of 10K to 1M vertices, on 1 and 2
// threads. Rates are per wall-clock second (UseRealTime: the work runs on OpenMP threads).
// Run: build/bench/bench/focal_kernels_bench (make bench runs it with the whole-run script).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>

#include "bench_meshes.h"
#include "curvature/vertex_fit.h"
#include "curvature/vertex_rows.h"
#include "focal/core/execution.h"
#include "focal/curvature/baselines.h"
#include "focal/curvature/curvature.h"
#include "focal/curvature/focal_mesh.h"
#include "focal/curvature/triangle_curvature.h"
#include "focal/io/fields_io.h"
#include "focal/io/mesh_io.h"
#include "focal/mesh/check.h"
#include "focal/mesh/neighbourhood.h"
#include "focal/mesh/orientation.h"
#include "focal/normals/vertex_normals.h"

namespace focal::bench {
namespace {

// Arguments of every benchmark: {vertices, threads}.
void sizes_and_threads(benchmark::internal::Benchmark* b) {
  for (int n : {10'000, 100'000, 1'000'000}) {
    for (int t : {1, 2}) b->Args({n, t});
  }
  b->ArgNames({"vertices", "threads"})->UseRealTime()->Unit(benchmark::kMillisecond);
}

const Mesh& setup(benchmark::State& state) { return torus(static_cast<int>(state.range(0))); }

/// The benchmark's thread count, set for its calls by an ExecutionScope.
int threads_of(const benchmark::State& state) { return static_cast<int>(state.range(1)); }

void per_vertex(benchmark::State& state, const Mesh& m) {
  state.counters["vertices/s"] = benchmark::Counter(static_cast<double>(m.V.rows()),
                                                    benchmark::Counter::kIsIterationInvariantRate);
}

void BM_Normals(benchmark::State& state) {
  const ExecutionScope scope({.threads = threads_of(state)});
  const Mesh& m = setup(state);
  for (auto _ : state) {
    benchmark::DoNotOptimize(vertex_normals(m.V, m.F, NormalWeighting::max));
  }
  per_vertex(state, m);
}
BENCHMARK(BM_Normals)->Apply(sizes_and_threads);

void BM_Adjacency(benchmark::State& state) {
  const ExecutionScope scope({.threads = threads_of(state)});
  const Mesh& m = setup(state);
  for (auto _ : state)
    benchmark::DoNotOptimize(vertex_adjacency(static_cast<int>(m.V.rows()), m.F));
  per_vertex(state, m);
}
BENCHMARK(BM_Adjacency)->Apply(sizes_and_threads);

void BM_TwoRing(benchmark::State& state) {
  const ExecutionScope scope({.threads = threads_of(state)});
  const Mesh& m = setup(state);
  const Neighbourhoods one = vertex_adjacency(static_cast<int>(m.V.rows()), m.F);
  for (auto _ : state) benchmark::DoNotOptimize(k_ring(one, 2));
  per_vertex(state, m);
}
BENCHMARK(BM_TwoRing)->Apply(sizes_and_threads);

// The fit step alone (issue 5 target: 20 M vertices/s on 2 threads, closed form, 1-ring):
// rays, normal equations, solve, eigen-decomposition, residual and the result arrays.
void fit_step(benchmark::State& state, CurvatureOptions o,
              detail::SimdIsa isa = detail::SimdIsa::best) {
  const Mesh& m = setup(state);
  std::vector<char> ok;
  const RowMatrixX3d unit = detail::unit_rows(m.N, ok);
  const Neighbourhoods one = vertex_adjacency(static_cast<int>(m.V.rows()), m.F);
  const Neighbourhoods rings = o.rings == 1 ? one : k_ring(one, o.rings);
  const detail::VertexFitInput in{m.V, unit, ok, rings, mean_edge_length(m.V, m.F)};
  for (auto _ : state) benchmark::DoNotOptimize(detail::fit_vertices(in, o, isa));
  per_vertex(state, m);
}

CurvatureOptions with_rings(int rings) {
  CurvatureOptions o;
  o.rings = rings;
  return o;
}

void BM_FitClosedForm(benchmark::State& state) { fit_step(state, {}); }
BENCHMARK(BM_FitClosedForm)->Apply(sizes_and_threads);

// The lane kernel compiled for each instruction set ({vertices, threads, isa}: 1 AVX-512,
// 2 AVX2, 3 baseline x86-64; same bits, see tests/simd_kernels_test.cpp).
void BM_FitClosedFormByIsa(benchmark::State& state) {
  const auto isa = static_cast<detail::SimdIsa>(state.range(2));
  if (!detail::simd_isa_available(isa)) return state.SkipWithError("not on this CPU");
  fit_step(state, {}, isa);
}
BENCHMARK(BM_FitClosedFormByIsa)
    ->ArgsProduct({{1'000'000}, {1}, {1, 2, 3}})
    ->ArgNames({"vertices", "threads", "isa"})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

void BM_FitClosedForm2Ring(benchmark::State& state) { fit_step(state, with_rings(2)); }
BENCHMARK(BM_FitClosedForm2Ring)->Apply(sizes_and_threads);

void BM_FitLevenbergMarquardt(benchmark::State& state) {
  CurvatureOptions o;
  o.solver = Solver::levenberg_marquardt;
  fit_step(state, o);
}
BENCHMARK(BM_FitLevenbergMarquardt)
    ->Args({10'000, 1})
    ->Args({10'000, 2})
    ->ArgNames({"vertices", "threads"})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

// estimate_curvature as the library user calls it: unit normals, 1-ring, mean edge length, fit.
void BM_EstimateCurvature(benchmark::State& state) {
  const ExecutionScope scope({.threads = threads_of(state)});
  const Mesh& m = setup(state);
  CurvatureOptions o;
  for (auto _ : state) benchmark::DoNotOptimize(estimate_curvature(m.V, m.F, m.N, o));
  per_vertex(state, m);
}
BENCHMARK(BM_EstimateCurvature)->Apply(sizes_and_threads);

// The per-triangle path (issue 5 target: 50 M faces/s on 2 threads).
void BM_TriangleCurvature(benchmark::State& state) {
  const ExecutionScope scope({.threads = threads_of(state)});
  const Mesh& m = setup(state);
  CurvatureOptions o;
  for (auto _ : state) benchmark::DoNotOptimize(triangle_curvature(m.V, m.F, m.N, o));
  state.counters["faces/s"] = benchmark::Counter(static_cast<double>(m.F.rows()),
                                                 benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_TriangleCurvature)->Apply(sizes_and_threads);

// The same with only k1, k2, H, K and the class asked for (TriangleFields): 41 B per face
// written instead of 225.
void BM_TriangleCurvatureCurvaturesOnly(benchmark::State& state) {
  const ExecutionScope scope({.threads = threads_of(state)});
  const Mesh& m = setup(state);
  CurvatureOptions o;
  TriangleFields fields;
  fields.coefficients = fields.focal_depths = fields.directions = fields.slits = false;
  fields.face_normal = fields.shape_operator = false;
  for (auto _ : state) benchmark::DoNotOptimize(triangle_curvature(m.V, m.F, m.N, o, fields));
  state.counters["faces/s"] = benchmark::Counter(static_cast<double>(m.F.rows()),
                                                 benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_TriangleCurvatureCurvaturesOnly)->Apply(sizes_and_threads);

// Method::triangle: the per-face operators averaged per vertex (what `--method triangle` runs).
void BM_EstimateCurvatureTriangleMethod(benchmark::State& state) {
  const ExecutionScope scope({.threads = threads_of(state)});
  const Mesh& m = setup(state);
  CurvatureOptions o;
  o.method = Method::triangle;
  for (auto _ : state) benchmark::DoNotOptimize(estimate_curvature(m.V, m.F, m.N, o));
  per_vertex(state, m);
}
BENCHMARK(BM_EstimateCurvatureTriangleMethod)->Apply(sizes_and_threads);

// The robustness check of `focal curvature` (check stage): statistics, orientation, normals.
void BM_CheckMesh(benchmark::State& state) {
  const ExecutionScope scope({.threads = threads_of(state)});
  const Mesh& m = setup(state);
  for (auto _ : state) {
    benchmark::DoNotOptimize(check_mesh(m.V, m.F, m.normals()));
  }
  per_vertex(state, m);
}
BENCHMARK(BM_CheckMesh)->Apply(sizes_and_threads);

void BM_OrientationReport(benchmark::State& state) {
  const ExecutionScope scope({.threads = threads_of(state)});
  const Mesh& m = setup(state);
  for (auto _ : state) benchmark::DoNotOptimize(orientation_report(m.V, m.F));
  per_vertex(state, m);
}
BENCHMARK(BM_OrientationReport)->Apply(sizes_and_threads);

void BM_FocalMeshes(benchmark::State& state) {
  const ExecutionScope scope({.threads = threads_of(state)});
  const Mesh& m = setup(state);
  const CurvatureResult c = estimate_curvature(m.V, m.F, m.N);
  const FocalMeshOptions o{};
  for (auto _ : state) benchmark::DoNotOptimize(focal_meshes(m.V, m.F, m.N, c, o));
  per_vertex(state, m);
}
BENCHMARK(BM_FocalMeshes)->Apply(sizes_and_threads);

void BM_WriteCurvaturePly(benchmark::State& state) {
  const ExecutionScope scope({.threads = threads_of(state)});
  const Mesh& m = setup(state);
  const CurvatureResult c = estimate_curvature(m.V, m.F, m.N);
  const auto path = std::filesystem::temp_directory_path() / "focal-bench-write.ply";
  for (auto _ : state) write_curvature_ply(path, m, c, {.binary = true, .comments = {}});
  std::filesystem::remove(path);
  per_vertex(state, m);
}
BENCHMARK(BM_WriteCurvaturePly)->Apply(sizes_and_threads);

void BM_ReadPly(benchmark::State& state) {
  const ExecutionScope scope({.threads = threads_of(state)});
  const Mesh& m = setup(state);
  const auto path = std::filesystem::temp_directory_path() / "focal-bench-read.ply";
  write_ply(path, m);
  for (auto _ : state) benchmark::DoNotOptimize(read_mesh(path));
  std::filesystem::remove(path);
  per_vertex(state, m);
}
BENCHMARK(BM_ReadPly)->Apply(sizes_and_threads);

// ---- The comparison estimators (focal/curvature/baselines.h) against focal on the same mesh and
// threads. Counters: `x_focal_fit`, the baseline's time over focal's estimate_curvature on
// normals at hand (the fit step with its 1-ring and unit normals), and `x_focal_with_normals`,
// over vertex_normals (Max) + estimate_curvature, i.e. both starting from positions and faces
// as the baselines do. Focal is timed in the same process right before (best of 5).
using Estimator = std::function<CurvatureResult(const Mesh&, const CurvatureOptions&)>;

double best_seconds(int runs, const std::function<void()>& work) {
  double best = 1e300;
  for (int r = 0; r < runs; ++r) {
    const auto start = std::chrono::steady_clock::now();
    work();
    best = std::min(
        best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

void compare_with_focal(benchmark::State& state, const Mesh& m, const Estimator& baseline) {
  const ExecutionScope scope({.threads = threads_of(state)});
  CurvatureOptions o;
  const RowMatrixX3d N = vertex_normals(m.V, m.F, NormalWeighting::max);
  const double fit =
      best_seconds(5, [&] { benchmark::DoNotOptimize(estimate_curvature(m.V, m.F, N, o)); });
  const double with_normals = best_seconds(5, [&] {
    benchmark::DoNotOptimize(
        estimate_curvature(m.V, m.F, vertex_normals(m.V, m.F, NormalWeighting::max), o));
  });
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) benchmark::DoNotOptimize(baseline(m, o));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() /
      static_cast<double>(state.iterations());
  state.counters["x_focal_fit"] = seconds / fit;
  state.counters["x_focal_with_normals"] = seconds / with_normals;
  per_vertex(state, m);
}

// Arguments {mesh, threads}: mesh 0 is the bunny, 1 the 1M-vertex torus.
void meshes_and_threads(benchmark::internal::Benchmark* b) {
  for (int mesh : {0, 1}) {
    for (int t : {1, 2}) b->Args({mesh, t});
  }
  b->ArgNames({"bunny0_torus1M", "threads"})->UseRealTime()->Unit(benchmark::kMillisecond);
}

void baseline_benchmark(benchmark::State& state, const Estimator& baseline) {
  const Mesh* m = state.range(0) == 0 ? bunny() : &torus(1'000'000);
  if (m == nullptr) {
    state.SkipWithError("no bunny: install libcgal-demo or put bunny.off in build/bench-data");
    return;
  }
  compare_with_focal(state, *m, baseline);
}

void BM_BaselineMeyer2003(benchmark::State& state) {
  baseline_benchmark(state, [](const Mesh& m, const CurvatureOptions& o) {
    return baselines::meyer_2003(m.V, m.F, o);
  });
}
BENCHMARK(BM_BaselineMeyer2003)->Apply(meshes_and_threads);

void BM_BaselineCohenSteinerMorvan2003(benchmark::State& state) {
  baseline_benchmark(state, [](const Mesh& m, const CurvatureOptions& o) {
    return baselines::cohen_steiner_morvan_2003(m.V, m.F, o);
  });
}
BENCHMARK(BM_BaselineCohenSteinerMorvan2003)->Apply(meshes_and_threads);

void BM_BaselineLachaud2020(benchmark::State& state) {  // Max normals, as in focal eval
  baseline_benchmark(state, [](const Mesh& m, const CurvatureOptions& o) {
    return baselines::lachaud_2020(m.V, m.F, std::nullopt, {}, o);
  });
}
BENCHMARK(BM_BaselineLachaud2020)->Apply(meshes_and_threads);

void BM_BaselineYang2006(benchmark::State& state) {
  baseline_benchmark(state, [](const Mesh& m, const CurvatureOptions& o) {
    return baselines::yang_2006(m.V, m.F, {}, o);
  });
}
BENCHMARK(BM_BaselineYang2006)->Apply(meshes_and_threads);

void BM_BaselineGrinspun2006(benchmark::State& state) {
  baseline_benchmark(state, [](const Mesh& m, const CurvatureOptions& o) {
    return baselines::grinspun_2006(m.V, m.F, o);
  });
}
BENCHMARK(BM_BaselineGrinspun2006)->Apply(meshes_and_threads);

}  // namespace
}  // namespace focal::bench

BENCHMARK_MAIN();
