// estimate_curvature_cuda: the per-vertex closed-form two-slit fit on a CUDA device, one thread
// per vertex. The math is kernels/vertex_fit.h (shared with the CPU test); this file moves data
// and launches.
//
// One thread per vertex rather than a warp per vertex: a 1-ring has about 6 neighbours and the
// fit is a few hundred flops, so a warp would idle most lanes; neighbouring threads read
// overlapping rings, which the caches serve. Reproducible: every output is written by the thread
// of its vertex from a fixed-order loop (no atomics).

// Eigen is host-only here: without this nvcc would annotate it for the device and warn.
#define EIGEN_NO_CUDA

#include <cuda_runtime.h>

#include "cuda/cuda_check.h"
#include "cuda/vertex_fit.h"
#include "focal/cuda/curvature.h"
#include "focal/cuda/device.h"

namespace focal {
namespace cuda {
namespace {

constexpr int kBlock = 256;

__global__ void vertex_fit_kernel(VertexFitParams<float> p) {
  const int i = static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x);
  if (i < p.vertex_count) fit_vertex(p, i);
}

/// A pair of CUDA events timing a stretch of the default stream.
class EventTimer {
 public:
  EventTimer() {
    check(cudaEventCreate(&start_), "cudaEventCreate");
    if (const cudaError_t e = cudaEventCreate(&stop_); e != cudaSuccess) {
      cudaEventDestroy(start_);
      check(e, "cudaEventCreate");
    }
  }
  ~EventTimer() {
    cudaEventDestroy(start_);
    cudaEventDestroy(stop_);
  }
  EventTimer(const EventTimer&) = delete;
  EventTimer& operator=(const EventTimer&) = delete;

  void start() { check(cudaEventRecord(start_), "cudaEventRecord"); }
  /// Waits for the stretch to finish (kernel errors surface here) and returns its milliseconds.
  float stop() {
    check(cudaEventRecord(stop_), "cudaEventRecord");
    check(cudaEventSynchronize(stop_), "vertex_fit_kernel (asynchronous error)");
    float ms = 0.0f;
    check(cudaEventElapsedTime(&ms, start_, stop_), "cudaEventElapsedTime");
    return ms;
  }

 private:
  cudaEvent_t start_ = nullptr;
  cudaEvent_t stop_ = nullptr;
};

}  // namespace

struct ResidentVertexFit::State {
  int device = 0;
  PreparedVertexFit<float> host;
  DeviceBuffer<VertexRecord<float>> vertices;
  DeviceBuffer<int> offsets, indices;
  DeviceBuffer<float> k1, k2, H, K, d1, d2, residual;
  DeviceBuffer<std::uint8_t> point_class;
  DeviceBuffer<int> rays_used, rays_excluded;

  [[nodiscard]] std::size_t n() const { return host.vertices.size(); }

  void allocate() {
    const std::size_t count = n();
    for (DeviceBuffer<float>* b : {&k1, &k2, &H, &K, &residual}) *b = DeviceBuffer<float>(count);
    d1 = DeviceBuffer<float>(3 * count);
    d2 = DeviceBuffer<float>(3 * count);
    point_class = DeviceBuffer<std::uint8_t>(count);
    rays_used = DeviceBuffer<int>(count);
    rays_excluded = DeviceBuffer<int>(count);
    vertices = DeviceBuffer<VertexRecord<float>>(count);
    offsets = DeviceBuffer<int>(static_cast<std::size_t>(host.rings.offsets.size()));
    indices = DeviceBuffer<int>(static_cast<std::size_t>(host.rings.indices.size()));
  }

  void upload() {
    vertices.upload(host.vertices.data(), host.vertices.size());
    offsets.upload(host.rings.offsets.data(), offsets.size());
    if (indices.size() > 0) indices.upload(host.rings.indices.data(), indices.size());
  }

  void launch() const {
    if (n() == 0) return;
    VertexFitParams<float> p = host.params;
    p.vertices = vertices.data();
    p.offsets = offsets.data();
    p.indices = indices.data();
    p.out = {k1.data(),        k2.data(),           H.data(),        K.data(),
             d1.data(),        d2.data(),           residual.data(), point_class.data(),
             rays_used.data(), rays_excluded.data()};
    const auto blocks = static_cast<unsigned>((n() + kBlock - 1) / kBlock);
    vertex_fit_kernel<<<blocks, kBlock>>>(p);
    check_launch("vertex_fit_kernel");
  }

  void download(VertexFitFields<float>& f) const {
    const std::size_t count = n();
    k1.download(f.k1.data(), count);
    k2.download(f.k2.data(), count);
    H.download(f.H.data(), count);
    K.download(f.K.data(), count);
    residual.download(f.residual.data(), count);
    d1.download(f.d1.data(), 3 * count);
    d2.download(f.d2.data(), 3 * count);
    point_class.download(f.point_class.data(), count);
    rays_used.download(f.rays_used.data(), count);
    rays_excluded.download(f.rays_excluded.data(), count);
  }
};

ResidentVertexFit::ResidentVertexFit(PositionsRef V, FacesRef F, NormalsRef N,
                                     const CurvatureOptions& options, int device)
    : state_(std::make_unique<State>()) {
  (void)require_cuda_device(device);  // DeviceError first: no backend, no device, bad index
  state_->device = device;
  state_->host = prepare_vertex_fit<float>(V, F, N, options);
  const DeviceScope scope(device);
  if (state_->n() == 0) return;
  state_->allocate();
  state_->upload();
}

ResidentVertexFit::~ResidentVertexFit() = default;

void ResidentVertexFit::set_normals(NormalsRef N) {
  const std::size_t count = state_->n();
  if (static_cast<std::size_t>(N.rows()) != count) {
    throw InvalidInput("CurvatureCudaContext: " + std::to_string(N.rows()) + " normals for " +
                       std::to_string(count) + " vertices");
  }
  for (std::size_t i = 0; i < count; ++i) {
    set_record_normal(N, static_cast<Eigen::Index>(i), state_->host.vertices[i]);
  }
  if (count == 0) return;
  const DeviceScope scope(state_->device);
  state_->vertices.upload(state_->host.vertices.data(), count);
}

float ResidentVertexFit::run_kernel() {
  const DeviceScope scope(state_->device);
  EventTimer timer;
  timer.start();
  state_->launch();
  return timer.stop();
}

float ResidentVertexFit::run_with_transfers() {
  const DeviceScope scope(state_->device);
  VertexFitFields<float> fields(state_->n());
  EventTimer timer;
  timer.start();
  state_->upload();
  state_->launch();
  state_->download(fields);
  return timer.stop();
}

CurvatureResult ResidentVertexFit::result() const {
  const DeviceScope scope(state_->device);
  VertexFitFields<float> fields(state_->n());
  if (state_->n() > 0) state_->download(fields);  // cudaMemcpy waits for the kernel
  return to_result(fields);
}

int ResidentVertexFit::vertex_count() const { return static_cast<int>(state_->n()); }

std::size_t ResidentVertexFit::transfer_bytes() const {
  const std::size_t n = state_->n();
  const std::size_t in = n * sizeof(VertexRecord<float>) +
                         sizeof(int) * static_cast<std::size_t>(state_->host.rings.offsets.size() +
                                                                state_->host.rings.indices.size());
  const std::size_t out = n * (11 * sizeof(float) + sizeof(std::uint8_t) + 2 * sizeof(int));
  return in + out;
}

}  // namespace cuda

namespace {

CurvatureResult fit_once(cuda::ResidentVertexFit& fit) {
  if (fit.vertex_count() > 0) (void)fit.run_kernel();
  return fit.result();
}

}  // namespace

CurvatureResult estimate_curvature_cuda(PositionsRef V, FacesRef F, NormalsRef N,
                                        const CurvatureOptions& options, int device) {
  cuda::ResidentVertexFit fit(V, F, N, options, device);
  return fit_once(fit);
}

struct CurvatureCudaContext::Resident {
  Resident(PositionsRef V, FacesRef F, NormalsRef N, const CurvatureOptions& options, int device)
      : fit(V, F, N, options, device) {}
  cuda::ResidentVertexFit fit;
};

CurvatureCudaContext::CurvatureCudaContext(PositionsRef V, FacesRef F, NormalsRef N,
                                           const CurvatureOptions& options, int device)
    : resident_(std::make_unique<Resident>(V, F, N, options, device)) {}

CurvatureCudaContext::~CurvatureCudaContext() = default;
CurvatureCudaContext::CurvatureCudaContext(CurvatureCudaContext&&) noexcept = default;
CurvatureCudaContext& CurvatureCudaContext::operator=(CurvatureCudaContext&&) noexcept = default;

void CurvatureCudaContext::set_normals(NormalsRef N) { resident_->fit.set_normals(N); }

CurvatureResult CurvatureCudaContext::estimate() { return fit_once(resident_->fit); }

int CurvatureCudaContext::vertex_count() const { return resident_->fit.vertex_count(); }

}  // namespace focal
