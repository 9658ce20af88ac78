// focal_gpu_bench: checks every CUDA path against the CPU reference, then times it, and prints a
// Markdown table (bench/gpu/run.sh; rows explained in docs/GPU.md).
//
//  - per-vertex fit (estimate_curvature_cuda) on generated tori: the kernel alone with the data
//    resident (CUDA events, median of --reps), upload + kernel + download (CUDA events), and the
//    public call (wall clock: validation, CSR on the host, transfers), and CurvatureCudaContext
//    with new normals per call (set_normals + fit + download, wall clock);
//  - per-triangle path (triangle_curvature_cuda): the public call, wall clock (no resident entry);
//  - image space at 512^2, 1024^2, 2048^2 (estimate_image_curvature_cuda on geometry_image):
//    the public call per frame, wall clock, transfers included; ImageCurvatureCudaContext's
//    kernels alone on the resident frame and its whole frame through pinned buffers.
// A check that fails prints FAIL in its row and makes the exit status 1; timings are still shown.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <functional>
#include <string>
#include <vector>

#include "cuda/vertex_fit.h"
#include "focal/core/error.h"
#include "focal/cuda/curvature.h"
#include "focal/cuda/device.h"
#include "focal/curvature/triangle_curvature.h"
#include "focal/image_space/image_space.h"
#include "focal/surfaces/geometry_image.h"
#include "focal/surfaces/surfaces.h"

namespace {

struct Row {
  std::string path, size;
  double median_ms = 0;
  double rate = 0;  // elements per second
  std::string unit, check, target;
};

std::vector<Row> rows;
bool all_checks_pass = true;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? NAN : v[v.size() / 2];
}

/// Median wall-clock milliseconds of `reps` calls after one warm-up call.
double wall_ms(int reps, const std::function<void()>& f) {
  f();
  std::vector<double> ms;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  return median(ms);
}

/// Largest |a - b| / scale over entries where both are finite; counts where finiteness differs.
struct Agreement {
  double max_error = 0;
  long mismatched_definedness = 0;
};

template <class A, class B, class S>
Agreement agree(long n, A a, B b, S scale) {
  Agreement g;
  for (long i = 0; i < n; ++i) {
    const double x = a(i), y = b(i);
    if (std::isfinite(x) != std::isfinite(y)) ++g.mismatched_definedness;
    if (!std::isfinite(x) || !std::isfinite(y) || !(scale(i) > 0)) continue;
    g.max_error = std::max(g.max_error, std::abs(x - y) / scale(i));
  }
  return g;
}

std::string verdict(const Agreement& g, double tolerance, const char* what) {
  const bool ok = g.max_error <= tolerance && g.mismatched_definedness == 0;
  all_checks_pass = all_checks_pass && ok;
  char s[160];
  std::snprintf(s, sizeof s, "%s %s %.1e (<= %.0e), %ld undefined differ", ok ? "ok" : "FAIL", what,
                g.max_error, tolerance, g.mismatched_definedness);
  return s;
}

std::string vertices_label(long n) {
  return n >= 1000000 ? std::to_string(n / 1000000) + "M v" : std::to_string(n / 1000) + "K v";
}

focal::AnalyticSurface torus(int vertices) {
  focal::SurfaceOptions s;
  s.kind = focal::SurfaceKind::torus;
  s.triangulation = focal::Triangulation::regular;
  s.target_vertices = vertices;
  return focal::make_surface(s);
}

void per_vertex(int target, int reps) {
  const focal::AnalyticSurface t = torus(target);
  const focal::Mesh& m = t.mesh;
  const long n = m.V.rows();
  const focal::CurvatureOptions o;
  const focal::CurvatureResult cpu = focal::estimate_curvature(m.V, m.F, m.N, o);
  focal::cuda::ResidentVertexFit fit(m.V, m.F, m.N, o);
  std::vector<double> kernel;
  for (int r = 0; r < reps + 3; ++r) {
    const float ms = fit.run_kernel();
    if (r >= 3) kernel.push_back(ms);  // three warm-up launches
  }
  const focal::CurvatureResult gpu = fit.result();
  // Float device path vs double CPU, relative to the vertex's largest |k| (docs/GPU.md: 1e-5).
  const auto kappa = [&](long i) { return std::max(std::abs(cpu.k1[i]), std::abs(cpu.k2[i])); };
  Agreement g = agree(
      n, [&](long i) { return cpu.k1[i]; }, [&](long i) { return gpu.k1[i]; }, kappa);
  const Agreement g2 = agree(
      n, [&](long i) { return cpu.k2[i]; }, [&](long i) { return gpu.k2[i]; }, kappa);
  g.max_error = std::max(g.max_error, g2.max_error);
  g.mismatched_definedness += g2.mismatched_definedness;
  const std::string check = verdict(g, 1e-5, "|dk|/kappa");
  const double k_ms = median(kernel);
  std::vector<double> transfer;
  for (int r = 0; r < std::max(5, reps / 5); ++r) transfer.push_back(fit.run_with_transfers());
  const double t_ms = median(transfer);
  const double api_ms = wall_ms(3, [&] { (void)focal::estimate_curvature_cuda(m.V, m.F, m.N, o); });
  const double cpu_ms = wall_ms(1, [&] { (void)focal::estimate_curvature(m.V, m.F, m.N, o); });
  const std::string size = vertices_label(n);
  rows.push_back({"per-vertex fit, kernel (resident)", size, k_ms, n / k_ms * 1e3, "vertices/s",
                  check, "> 1e9 vertices/s"});
  char bw[64];
  std::snprintf(bw, sizeof bw, "%.1f GB/s over PCIe", fit.transfer_bytes() / t_ms / 1e6);
  rows.push_back({"per-vertex fit, upload + kernel + download", size, t_ms, n / t_ms * 1e3,
                  "vertices/s", bw, ""});
  rows.push_back({"estimate_curvature_cuda (host CSR, transfers)", size, api_ms, n / api_ms * 1e3,
                  "vertices/s", "", ""});
  // The mesh resident, normals changing: set_normals (records rewritten and uploaded) + fit +
  // download, against the one-shot call's bits.
  focal::CurvatureCudaContext context(m.V, m.F, m.N, o);
  const focal::RowMatrixX3d inward = -m.N;
  const double context_ms = wall_ms(3, [&] {
    context.set_normals(inward);
    (void)context.estimate();
  });
  const focal::CurvatureResult want = focal::estimate_curvature_cuda(m.V, m.F, inward, o);
  const focal::CurvatureResult got = context.estimate();
  const bool same =
      (want.H.array() == got.H.array() || (want.H.array().isNaN() && got.H.array().isNaN())).all();
  if (!same) all_checks_pass = false;
  rows.push_back({"CurvatureCudaContext: set_normals + fit + download", size, context_ms,
                  n / context_ms * 1e3, "vertices/s",
                  same ? "H bits of the public call" : "FAIL: bits", ""});
  rows.push_back(
      {"estimate_curvature (CPU reference)", size, cpu_ms, n / cpu_ms * 1e3, "vertices/s", "", ""});
}

void per_triangle(int target) {
  const focal::AnalyticSurface t = torus(target);
  const focal::Mesh& m = t.mesh;
  const long f = m.F.rows();
  const focal::TriangleCurvatureResult cpu = focal::triangle_curvature(m.V, m.F, m.N);
  const focal::TriangleCurvatureResult gpu = focal::triangle_curvature_cuda(m.V, m.F, m.N);
  const auto kappa = [&](long i) { return std::max(std::abs(cpu.k1[i]), std::abs(cpu.k2[i])); };
  const Agreement g = agree(
      f, [&](long i) { return cpu.H[i]; }, [&](long i) { return gpu.H[i]; }, kappa);
  const std::string check = verdict(g, 1e-4, "|dH|/kappa");
  const double ms = wall_ms(5, [&] { (void)focal::triangle_curvature_cuda(m.V, m.F, m.N); });
  rows.push_back({"triangle_curvature_cuda (public call, transfers)",
                  std::to_string(f / 1000000) + "M faces", ms, f / ms * 1e3, "faces/s", check, ""});
}

/// Whether two results hold the same bits (the context runs the one-shot call's kernels).
bool same_bits(const focal::ImageCurvature& a, const focal::ImageCurvature& b) {
  const auto same = [](const auto& x, const auto& y) {
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0;
  };
  return same(a.k1, b.k1) && same(a.k2, b.k2) && same(a.H, b.H) && same(a.K, b.K) &&
         same(a.focal_depth1, b.focal_depth1) && same(a.focal_depth2, b.focal_depth2) &&
         same(a.d1, b.d1) && same(a.d2, b.d2) && same(a.valid, b.valid);
}

/// ImageCurvatureCudaContext on the frame: the kernels alone on the resident G-buffer, and a
/// whole frame through the pinned buffers (upload, kernels, download into a reused result).
void image_space_context(const focal::GBuffer& g, const focal::ImageCurvature& one_shot, int reps) {
  focal::ImageCurvatureCudaContext context(g.width, g.height);
  focal::ImageCurvature out;
  context.estimate(g, out);
  if (!same_bits(out, one_shot)) all_checks_pass = false;
  const std::string check = same_bits(out, one_shot) ? "bits of the public call" : "FAIL: bits";
  const long pixels = static_cast<long>(g.width) * g.height;
  const std::string size = std::to_string(g.width) + "^2";
  const double kernels_ms = wall_ms(reps, [&] { context.compute(); });
  rows.push_back({"image space, context: kernels (resident)", size, kernels_ms,
                  pixels / kernels_ms * 1e3, "pixels/s", check,
                  g.width == 512 ? "< 0.05 ms" : (g.width == 2048 ? "< 0.5 ms" : "")});
  const double frame_ms = wall_ms(reps, [&] { context.estimate(g, out); });
  rows.push_back({"image space, context: upload + kernels + download (pinned)", size, frame_ms,
                  pixels / frame_ms * 1e3, "pixels/s", check, ""});
}

void image_space(int width, int reps) {
  focal::SurfaceOptions s;
  s.kind = focal::SurfaceKind::torus;
  const focal::GeometryImage image = focal::geometry_image(s, width, width);
  const focal::ImageCurvature cpu = focal::estimate_image_curvature(image.gbuffer);
  const focal::ImageCurvature gpu = focal::estimate_image_curvature_cuda(image.gbuffer);
  const long pixels = static_cast<long>(width) * width;
  const auto kappa = [&](long i) {
    return std::max(std::abs(double(cpu.k1[i])), std::abs(double(cpu.k2[i])));
  };
  Agreement g = agree(
      pixels, [&](long i) { return double(cpu.H[i]); }, [&](long i) { return double(gpu.H[i]); },
      kappa);
  const Agreement gk = agree(
      pixels, [&](long i) { return double(cpu.K[i]); }, [&](long i) { return double(gpu.K[i]); },
      [&](long i) { return kappa(i) * kappa(i); });
  g.max_error = std::max(g.max_error, gk.max_error);
  g.mismatched_definedness += gk.mismatched_definedness;
  const std::string check = verdict(g, 1e-4, "|dH|/kappa, |dK|/kappa^2");
  const double ms =
      wall_ms(reps, [&] { (void)focal::estimate_image_curvature_cuda(image.gbuffer); });
  const std::string size = std::to_string(width) + "^2";
  rows.push_back({"image space H, K, focal depths (public call, transfers)", size, ms,
                  pixels / ms * 1e3, "pixels/s", check, ""});
  image_space_context(image.gbuffer, gpu, reps);
}

void print_table(const focal::CudaDevice& d) {
  char date[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  std::printf("Device: %s (compute %d.%d, %d SMs, %.0f GiB); %s\n\n", d.name.c_str(),
              d.compute_major, d.compute_minor, d.multiprocessors, d.memory_bytes / 1073741824.0,
              date);
  std::printf("| path | size | median ms | rate | check vs CPU | target |\n");
  std::printf("|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    std::printf("| %s | %s | %.4g | %.3g %s | %s | %s |\n", r.path.c_str(), r.size.c_str(),
                r.median_ms, r.rate, r.unit.c_str(), r.check.c_str(), r.target.c_str());
  }
}

/// Runs one benchmark section; a section whose path is not there (DeviceError, e.g. a
/// placeholder) or fails is reported and the others still run.
void section(const char* name, const std::function<void()>& f) {
  try {
    f();
  } catch (const focal::Error& e) {
    all_checks_pass = false;
    std::fprintf(stderr, "Error: %s: %s\n", name, e.what());
    rows.push_back({name, "-", NAN, NAN, "", std::string("FAIL: ") + e.what(), ""});
  }
}

}  // namespace

int main(int argc, char** argv) {
  int max_vertices = 10000000, reps = 50;
  for (int a = 1; a + 1 < argc; a += 2) {
    const std::string flag = argv[a];
    if (flag == "--max-vertices")
      max_vertices = std::atoi(argv[a + 1]);
    else if (flag == "--reps")
      reps = std::atoi(argv[a + 1]);
  }
  try {
    const focal::CudaDevice device = focal::require_cuda_device(0);
    for (int n : {1000000, 10000000}) {
      if (n <= max_vertices) section("per-vertex fit", [&] { per_vertex(n, reps); });
    }
    section("per-triangle", [&] { per_triangle(std::min(1000000, max_vertices)); });
    for (int w : {512, 1024, 2048}) section("image space", [&] { image_space(w, reps); });
    print_table(device);
  } catch (const focal::Error& e) {
    std::fprintf(stderr, "Error: %s\n", e.what());
    return 2;
  }
  return all_checks_pass ? 0 : 1;
}
