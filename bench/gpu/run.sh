#!/usr/bin/env bash
# Builds and runs the GPU benchmark of focal's CUDA backend on the machine's first CUDA device:
# each GPU path is checked against the CPU reference, then timed (median of many runs, CUDA
# events for the kernel alone, wall clock for the public calls with host transfers); prints a
# Markdown table with the device name and date (docs/GPU.md explains the rows).
#
# Usage: bench/gpu/run.sh [BUILD_DIR]   (default build/gpu-bench). Environment:
#   FOCAL_GPU_BENCH_MAX   largest per-vertex mesh (default 10000000 vertices)
#   FOCAL_GPU_BENCH_REPS  kernel repetitions for the medians (default 50)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-build/gpu-bench}

if ! command -v nvcc >/dev/null && [[ ! -x /usr/local/cuda/bin/nvcc ]]; then
  echo "Error: no nvcc: the GPU benchmark needs the CUDA toolkit" >&2
  exit 2
fi
export PATH=$PATH:/usr/local/cuda/bin
command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version,clocks.max.sm \
  --format=csv,noheader >&2 || true

cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >&2
cmake --build "$build" --target focal_gpu_bench >&2
"$build/focal_gpu_bench" --max-vertices "${FOCAL_GPU_BENCH_MAX:-10000000}" \
  --reps "${FOCAL_GPU_BENCH_REPS:-50}"
