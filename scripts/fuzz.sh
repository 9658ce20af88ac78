#!/usr/bin/env bash
# Builds the libFuzzer targets in fuzz/ (one per mesh reader) with clang, AddressSanitizer and
# UndefinedBehaviorSanitizer in build/fuzz, then runs each for FUZZ_SECONDS seconds (default 15)
# from the seed corpus in fuzz/corpus/<format>/. Fails on the first crash, sanitizer report,
# input that takes over 10 s, or allocation over 256 MB (no reader may allocate more than a small
# multiple of its input, and inputs stay below libFuzzer's default 4 kB here). A failing input is
# left as build/fuzz/crash-<format>-<hash>; replay it with
#   build/fuzz/fuzz/<format>_fuzzer build/fuzz/crash-<format>-<hash>
# and add it to tests/mesh_io_test.cpp as a regression test once fixed.
#
# Usage: scripts/fuzz.sh [FORMAT...]     (default: ply obj off stl xyz pcd las)
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${FUZZ_SECONDS:-15}
formats=("$@")
[[ ${#formats[@]} -gt 0 ]] || formats=(ply obj off stl xyz pcd las)

bash scripts/install-deps.sh fuzz
cmake -S . -B build/fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DFOCAL_WITH_CUDA=OFF \
  -DFOCAL_BUILD_FUZZERS=ON -DFOCAL_BUILD_TESTS=OFF -DFOCAL_BUILD_CLI=OFF >/dev/null
targets=()
for f in "${formats[@]}"; do targets+=("${f}_fuzzer"); done
cmake --build build/fuzz -j "$(nproc)" --target "${targets[@]}"

for f in "${formats[@]}"; do
  # New inputs go to a working corpus in the build folder; the seeds in the repository stay small.
  work=build/fuzz/corpus/$f
  mkdir -p "$work"
  echo "== fuzzing the $f reader for $seconds s"
  log=build/fuzz/$f.log
  rc=0
  "build/fuzz/fuzz/${f}_fuzzer" "$work" "fuzz/corpus/$f" -dict="fuzz/$f.dict" \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=256 \
    -artifact_prefix="build/fuzz/crash-$f-" -print_final_stats=1 >"$log" 2>&1 || rc=$?
  grep -E '^(stat::number_of_executed_units|stat::peak_rss_mb|#[0-9]+ +DONE)' "$log" || true
  if [[ $rc -ne 0 ]]; then
    tail -n 60 "$log" >&2
    echo "fuzz: the $f reader failed (exit $rc); the log is $log" >&2
    exit 1
  fi
done
echo "fuzz: no crash in ${formats[*]} ($seconds s each)"
