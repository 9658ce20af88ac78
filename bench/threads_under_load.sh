#!/usr/bin/env bash
# Issue 20: more threads must never be slower than one. Times whole `focal curvature IN -o
# OUT.ply` runs (the default estimator and --paper) on the bunny (37,706 vertices) and a 1M
# torus, with --threads 1 and 2, on a quiet machine and with a competing busy process (one
# `while :; do :; done` shell, started and stopped here), and prints the medians and the ratio
# 2 threads / 1 thread (below 1: 2 threads faster). Runs alternate 1 and 2 threads so that
# slow drifts in the load hit both alike.
#
# Usage: bench/threads_under_load.sh [BUILD_DIR] [FOCAL]   (default build/release; FOCAL
#        defaults to BUILD_DIR/cli/focal). Environment: FOCAL_BENCH_REPS (runs per cell,
#        default 11), FOCAL_BENCH_DATA (mesh cache, default build/bench-data),
#        FOCAL_BENCH_QUICK=1 (bunny only).
set -euo pipefail

build=${1:-build/release}
focal=${2:-$build/cli/focal}
data=${FOCAL_BENCH_DATA:-build/bench-data}
reps=${FOCAL_BENCH_REPS:-11}
scratch=$(mktemp -d)
busy_pid=""
stop_busy() {
  if [[ -n $busy_pid ]]; then
    kill "$busy_pid" 2>/dev/null || true
    wait "$busy_pid" 2>/dev/null || true
    busy_pid=""
  fi
}
trap 'stop_busy; rm -rf "$scratch"' EXIT
mkdir -p "$data"

bunny=$data/bunny.off
[[ -f $bunny ]] ||
  tar -xzf /usr/share/doc/libcgal-dev/data.tar.gz -O data/meshes/bunny00.off >"$bunny"
meshes=("bunny:$bunny")
if [[ ${FOCAL_BENCH_QUICK:-0} != 1 ]]; then
  torus=$data/torus-1000000.ply
  [[ -f $torus ]] || "$focal" generate torus --vertices 1000000 -o "$torus" >&2
  meshes+=("torus-1M:$torus")
fi

# Wall seconds of one run, from bash's clock (ms resolution; /usr/bin/time has 10 ms).
time_once() {
  local mesh=$1 threads=$2 estimator=$3 t0 t1
  t0=$(date +%s%N)
  # shellcheck disable=SC2086  # $estimator is a flag, or empty for the default
  "$focal" curvature "$mesh" -o "$scratch/out.ply" --threads "$threads" $estimator >/dev/null
  t1=$(date +%s%N)
  echo "$(((t1 - t0) / 1000000))"
}

median() { sort -n | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }

echo "focal: $focal; $(nproc) CPUs; median of $reps alternated runs per cell, wall ms"
echo
echo "| load | mesh | estimator | 1 thread ms | 2 threads ms | 2T / 1T |"
echo "|------|------|-----------|------------:|-------------:|--------:|"
for load in quiet busy; do
  if [[ $load == busy ]]; then
    bash -c 'while :; do :; done' &
    busy_pid=$!
  fi
  for entry in "${meshes[@]}"; do
    name=${entry%%:*} mesh=${entry#*:}
    for estimator in "" --paper; do
      time_once "$mesh" 1 "$estimator" >/dev/null  # warm the page cache
      : >"$scratch/t1"
      : >"$scratch/t2"
      for ((r = 0; r < reps; r++)); do
        time_once "$mesh" 1 "$estimator" >>"$scratch/t1"
        time_once "$mesh" 2 "$estimator" >>"$scratch/t2"
      done
      m1=$(median <"$scratch/t1")
      m2=$(median <"$scratch/t2")
      awk -v l="$load" -v n="$name" -v e="${estimator:-default}" -v a="$m1" -v b="$m2" \
        'BEGIN {printf "| %s | %s | %s | %.0f | %.0f | %.2f |\n", l, n, e, a, b, b / a}'
    done
  done
  stop_busy
done
