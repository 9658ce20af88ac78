#!/usr/bin/env bash
# Builds the library, the command and the tests with AddressSanitizer and UndefinedBehaviorSanitizer
# (the `asan` preset: GCC, Debug with Eigen's bounds checks, at -O1 for speed, CPU only) in
# build/asan and runs the whole test suite there. Any sanitizer report fails the test that
# triggered it (-fno-sanitize-recover=all, and halt_on_error below).
#
# Usage: scripts/sanitize.sh [CTEST ARGS...]    e.g. scripts/sanitize.sh -R Robustness
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-deps.sh
cmake --preset asan >/dev/null
cmake --build build/asan -j "$(nproc)"

# detect_leaks stays on (LeakSanitizer); libgomp's thread pool is not reported as a leak by it.
# OpenMP loops run with two threads: enough to exercise the parallel paths (the thread-count
# determinism tests pin their own counts) without oversubscribing CI's two cores under ASan.
export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
export FOCAL_NUM_THREADS=${FOCAL_NUM_THREADS:-2}
# `package` is left out: it builds a consumer project without the sanitizer flags against this
# instrumented library, which cannot link (undefined __asan_* symbols). It tests the installed
# CMake package, not memory safety, and runs in `make test`.
ctest --test-dir build/asan --output-on-failure -j "$(nproc)" -E '^package$' "$@"
