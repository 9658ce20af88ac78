// `focal devices`: the CUDA backend, runtime, driver and GPUs this build can use, and why none
// when none is (docs/GPU.md).
#include <cstdio>
#include <memory>
#include <string>

#include "commands.h"
#include "focal/core/error.h"
#include "focal/cuda/device.h"

namespace focal::cli {
namespace {

/// "13.0" from the runtime's and driver's encoding 13000; "none" for 0.
std::string version_text(int v) {
  if (v == 0) return "none";
  return std::to_string(v / 1000) + "." + std::to_string(v % 1000 / 10);
}

void print_device(const CudaDevice& d) {
  std::printf(
      "device %d:             %s, compute capability %d.%d, %.1f GiB, %d multiprocessors%s\n",
      d.index, d.name.c_str(), d.compute_major, d.compute_minor,
      static_cast<double>(d.memory_bytes) / (1024.0 * 1024.0 * 1024.0), d.multiprocessors,
      d.supported ? "" : " (not usable)");
  if (!d.supported) std::printf("  %s\n", d.unsupported_reason.c_str());
}

void print_devices(bool require) {
  const CudaStatus s = cuda_status();
  std::printf("CUDA backend:         %s\n", s.built ? "built in" : "not built");
  if (s.built) {
    std::printf("CUDA runtime:         %s\n", version_text(s.runtime_version).c_str());
    std::printf("NVIDIA driver:        %s\n",
                s.driver_version == 0
                    ? "none loaded"
                    : ("supports CUDA " + version_text(s.driver_version)).c_str());
    std::printf("architectures built:  %s\n", s.architectures.c_str());
  }
  for (const CudaDevice& d : s.devices) print_device(d);
  if (!s.why_none.empty()) {
    std::printf("usable devices:       none: %s\n", s.why_none.c_str());
    if (require) throw DeviceError("no usable CUDA device: " + s.why_none);
  }
}

}  // namespace

void add_devices_command(CLI::App& app, const Log& /*log*/) {
  auto* cmd =
      app.add_subcommand("devices", "The CUDA backend, driver and GPUs, or why there are none");
  auto require = std::make_shared<bool>(false);
  cmd->add_flag("--require", *require, "exit 2 when no usable CUDA device is present");
  cmd->footer(
      "Examples:\n  focal devices\n  focal devices --require   # exit 2 without a usable GPU");
  cmd->callback([require] { print_devices(*require); });
}

}  // namespace focal::cli
