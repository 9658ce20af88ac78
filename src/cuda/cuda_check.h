#pragma once
// Checked CUDA runtime calls and a device buffer that frees itself. Only for .cu files.

#include <cuda_runtime.h>

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "focal/core/error.h"

namespace focal::cuda {

/// Throws DeviceError naming the call and the CUDA error unless `status` is cudaSuccess.
inline void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess) {
    throw DeviceError(std::string("CUDA: ") + what + ": " + cudaGetErrorString(status));
  }
}

/// Checks a kernel launch (configuration errors) without waiting for the kernel.
inline void check_launch(const char* kernel) { check(cudaGetLastError(), kernel); }

/// Makes `device` current for its lifetime and restores the caller's device afterwards, so that
/// a library call does not change the calling thread's CUDA state.
class DeviceScope {
 public:
  explicit DeviceScope(int device) {
    check(cudaGetDevice(&previous_), "cudaGetDevice");
    check(cudaSetDevice(device), "cudaSetDevice");
  }
  ~DeviceScope() { cudaSetDevice(previous_); }  // no throw from a destructor
  DeviceScope(const DeviceScope&) = delete;
  DeviceScope& operator=(const DeviceScope&) = delete;

 private:
  int previous_ = 0;
};

/// Where an OwnedBuffer's memory lives: device memory.
struct DeviceMemory {
  static void* allocate(std::size_t bytes) {
    void* p = nullptr;
    check(cudaMalloc(&p, bytes), "cudaMalloc");
    return p;
  }
  static void release(void* p) { cudaFree(p); }  // no throw: errors surface at the next call
};

/// Page-locked host memory (cudaMallocHost): copies from and to it run at the bus's rate and
/// can be asynchronous, unlike pageable memory.
struct PinnedMemory {
  static void* allocate(std::size_t bytes) {
    void* p = nullptr;
    check(cudaMallocHost(&p, bytes), "cudaMallocHost");
    return p;
  }
  static void release(void* p) { cudaFreeHost(p); }
};

/// n elements of T in `Memory`, freed on scope exit; movable, not copyable.
template <class T, class Memory>
class OwnedBuffer {
 public:
  OwnedBuffer() = default;
  explicit OwnedBuffer(std::size_t n) : size_(n) {
    if (n > 0) data_ = static_cast<T*>(Memory::allocate(n * sizeof(T)));
  }
  OwnedBuffer(const OwnedBuffer&) = delete;
  OwnedBuffer& operator=(const OwnedBuffer&) = delete;
  OwnedBuffer(OwnedBuffer&& o) noexcept : data_(o.data_), size_(o.size_) {
    o.data_ = nullptr;
    o.size_ = 0;
  }
  OwnedBuffer& operator=(OwnedBuffer&& o) noexcept {
    std::swap(data_, o.data_);
    std::swap(size_, o.size_);
    return *this;
  }
  ~OwnedBuffer() {
    if (data_ != nullptr) Memory::release(data_);
  }

  [[nodiscard]] T* data() const { return data_; }
  [[nodiscard]] std::size_t size() const { return size_; }

 private:
  T* data_ = nullptr;
  std::size_t size_ = 0;
};

/// n elements of T in page-locked host memory.
template <class T>
using PinnedBuffer = OwnedBuffer<T, PinnedMemory>;

/// n elements of T in device memory, with the copies to and from the host.
template <class T>
class DeviceBuffer : public OwnedBuffer<T, DeviceMemory> {
 public:
  using OwnedBuffer<T, DeviceMemory>::OwnedBuffer;
  using OwnedBuffer<T, DeviceMemory>::data;
  using OwnedBuffer<T, DeviceMemory>::size;

  /// A buffer holding a copy of `host`.
  static DeviceBuffer from_host(const std::vector<T>& host) {
    DeviceBuffer b(host.size());
    b.upload(host.data(), host.size());
    return b;
  }
  void upload(const T* host, std::size_t n) {
    check(cudaMemcpy(data(), host, n * sizeof(T), cudaMemcpyHostToDevice), "cudaMemcpy to device");
  }
  void download(T* host, std::size_t n) const {
    check(cudaMemcpy(host, data(), n * sizeof(T), cudaMemcpyDeviceToHost), "cudaMemcpy to host");
  }
  /// Queued on `stream`: asynchronous where `host` is pinned.
  void upload_async(const T* host, std::size_t n, cudaStream_t stream) {
    check(cudaMemcpyAsync(data(), host, n * sizeof(T), cudaMemcpyHostToDevice, stream),
          "cudaMemcpyAsync to device");
  }
  void download_async(T* host, std::size_t n, cudaStream_t stream) const {
    check(cudaMemcpyAsync(host, data(), n * sizeof(T), cudaMemcpyDeviceToHost, stream),
          "cudaMemcpyAsync to host");
  }
  [[nodiscard]] std::vector<T> to_host() const {
    std::vector<T> host(size());
    download(host.data(), size());
    return host;
  }
};

/// A CUDA stream of the current device, destroyed on scope exit.
class Stream {
 public:
  Stream() {
    check(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking), "cudaStreamCreate");
  }
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;
  ~Stream() { cudaStreamDestroy(stream_); }  // no throw from a destructor

  [[nodiscard]] cudaStream_t get() const { return stream_; }
  /// Waits for everything queued on the stream; throws DeviceError naming `what` on an error.
  void synchronize(const char* what) const { check(cudaStreamSynchronize(stream_), what); }

 private:
  cudaStream_t stream_ = nullptr;
};

}  // namespace focal::cuda
