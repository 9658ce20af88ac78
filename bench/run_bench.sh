#!/usr/bin/env bash
# Whole `focal curvature IN -o OUT.ply` runs (read, normals, 1-ring, fit, write binary PLY) on
# generated tori and on the Stanford bunny midpoint-subdivided to size, 10K to 10M vertices, on
# 1 and 2 threads. Prints a markdown table: the fastest of REPS runs (wall time, vertices/s and
# its -v stage times) and the largest peak RSS of them (/usr/bin/time -v).
#
# Then, when bench/peers/.venv exists, bench/peers/peers.py times the peer libraries on the bunny.
#
# Usage: bench/run_bench.sh [BUILD_DIR]   (default build/bench; needs cli/focal and
#        bench/focal_subdivide there). Environment: FOCAL_BENCH_REPS (default 3),
#        FOCAL_BENCH_MAX (largest size, default 10000000), FOCAL_BENCH_DATA (mesh cache,
#        default build/bench-data).
set -euo pipefail

build=${1:-build/bench}
focal=$build/cli/focal
subdivide=$build/bench/focal_subdivide
data=${FOCAL_BENCH_DATA:-build/bench-data}
reps=${FOCAL_BENCH_REPS:-3}
max=${FOCAL_BENCH_MAX:-10000000}
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$data"

# Generated meshes are cached: the 10M torus takes seconds to make and 740 MB to keep.
torus() {
  local n=$1 path=$data/torus-$1.ply
  [[ -f $path ]] || "$focal" generate torus --vertices "$n" -o "$path" >&2
  echo "$path"
}

# The same torus without normals (issue 36's targets hold there too).
torus_without_normals() {
  local n=$1 path=$data/torus-$1-no-normals.ply
  [[ -f $path ]] || "$focal" generate torus --vertices "$n" --no-normals -o "$path" >&2
  echo "$path"
}

bunny() {
  local level=$1 path=$data/bunny-sub$1.ply
  if [[ ! -f $path ]]; then
    [[ -f $data/bunny.off ]] ||
      tar -xzf /usr/share/doc/libcgal-dev/data.tar.gz -O data/meshes/bunny00.off >"$data/bunny.off"
    "$subdivide" "$data/bunny.off" "$path" "$level" >&2
  fi
  echo "$path"
}

vertex_count() { grep -a -m1 '^element vertex' "$1" | awk '{print $3}'; }

# One run: prints "wall_s rss_kb read_ms check_ms normals_ms curvature_ms write_ms" (a stage
# the command does not report prints as 0).
run_once() {
  local mesh=$1 threads=$2 estimator=$3
  # shellcheck disable=SC2086  # $estimator is a list of flags, or empty for the default
  /usr/bin/time -v -o "$scratch/time" \
    "$focal" -v curvature "$mesh" -o "$scratch/out.ply" --threads "$threads" $estimator \
    2>"$scratch/log" >/dev/null
  local wall rss
  wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {n = split($2, t, ":"); s = 0;
         for (i = 1; i <= n; i++) s = s * 60 + t[i]; print s}' "$scratch/time")
  rss=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$scratch/time")
  # The final "  name: 123.4 ms" line of a stage, not its "running for" progress lines.
  stage() { awk -v s="$1:" '$(NF - 2) == s && $NF == "ms" {t = $2} END {print t + 0}' "$scratch/log"; }
  echo "$wall $rss $(stage read) $(stage check) $(stage normals) $(stage curvature) $(stage write)"
}

report() {
  local name=$1 mesh=$2 threads=$3 estimator=${4---paper} n best="" best_rss=0
  n=$(vertex_count "$mesh")
  for ((r = 0; r < reps; r++)); do
    local line
    line=$(run_once "$mesh" "$threads" "$estimator")
    read -r wall rss _ <<<"$line"
    ((rss > best_rss)) && best_rss=$rss
    if [[ -z $best ]] || awk -v a="$wall" -v b="${best%% *}" 'BEGIN {exit !(a < b)}'; then
      best=$line
    fi
  done
  read -r wall _ t_read t_check t_normals t_curv t_write <<<"$best"
  awk -v name="$name" -v n="$n" -v t="$threads" -v w="$wall" -v rss="$best_rss" \
    -v a="$t_read" -v k="$t_check" -v b="$t_normals" -v c="$t_curv" -v d="$t_write" 'BEGIN {
      # /usr/bin/time resolves 10 ms: a faster run has no meaningful rate.
      rate = w > 0 ? sprintf("%5.2f", n / w / 1e6) : "    -"
      printf "| %-10s | %9d | %d | %6.2f | %s | %6.0f | %5.0f | %5.0f | %5.0f | %5.0f | %5.0f |\n",
             name, n, t, w, rate, rss / 1024, a, k, b, c, d }'
  best_wall=$wall  # for the ratio lines below
}

# One line of the targets table: "| name | a / b | target |", nothing when a value is missing.
ratio_line() {
  local name=$1 a=$2 b=$3 target=$4
  [[ -n $a && -n $b ]] || return 0
  awk -v name="$name" -v a="$a" -v b="$b" -v target="$target" \
    'BEGIN { printf "| %s | %.2f | %s |\n", name, a / b, target }'
}

echo "Whole runs: focal -v curvature IN -o OUT.ply --threads T --paper (the paper's closed-form"
echo "1-ring fit, the fast path); fastest of $reps (wall), largest peak RSS"
echo
echo "Stage columns in ms, from -v of the fastest run."
echo
echo "| mesh       |  vertices | T | wall s | M v/s | RSS MB |  read | check | normals | curvature | write |"
echo "|------------|----------:|--:|-------:|------:|-------:|------:|------:|------:|------:|------:|"
for n in 10000 100000 1000000 10000000; do
  ((n <= max)) || continue
  mesh=$(torus "$n")
  for t in 1 2; do report "torus" "$mesh" "$t"; done
done
for level in 0 1 2 3 4; do
  ((37706 * 4 ** level <= max * 1)) || continue
  mesh=$(bunny "$level")
  for t in 1 2; do report "bunny/$level" "$mesh" "$t"; done
done

# The CLI's default, the recommended estimator (jet normals, normal-field rating, per-triangle
# pass): the same table for the torus up to 1M vertices and the bunny.
echo
echo "The default (recommended estimator): focal -v curvature IN -o OUT.ply --threads T"
echo
echo "| mesh       |  vertices | T | wall s | M v/s | RSS MB |  read | check | normals | curvature | write |"
echo "|------------|----------:|--:|-------:|------:|-------:|------:|------:|------:|------:|------:|"
default_1m="" default_10m="" cloud_default="" cloud_k16=""
for n in 100000 1000000 10000000; do
  ((n <= max)) || continue
  mesh=$(torus "$n")
  # 10M on 2 threads only: it is there for the ratio to 1M (issue 36: <= 12x).
  if ((n > 1000000)); then threads_list=2; else threads_list="1 2"; fi
  for t in $threads_list; do report "torus" "$mesh" "$t" ""; done
  ((n == 1000000)) && default_1m=$best_wall
  ((n == 10000000)) && default_10m=$best_wall
done
mesh=$(bunny 0)
for t in 1 2; do report "bunny/0" "$mesh" "$t" ""; done
# A 1M-point cloud with normals (no faces): the default against --k 16 (the nearest-neighbour fit).
if ((max >= 1000000)); then
  cloud=$data/cloud-1000000.ply
  [[ -f $cloud ]] || "$focal" generate torus --cloud --vertices 1000000 -o "$cloud" >&2
  report "cloud" "$cloud" 2 ""
  cloud_default=$best_wall
  report "cloud k16" "$cloud" 2 "--k 16"
  cloud_k16=$best_wall
fi
echo
echo "Targets of issue 36 from the tables above (2 threads, fastest of $reps); the ratios to"
echo "trueform follow with the peers (bench/peers/targets.py)."
echo
echo "| ratio of whole runs | value | target |"
echo "|---|---:|---|"
ratio_line "default, torus 10M / 1M" "$default_10m" "$default_1m" "<= 12"
ratio_line "cloud 1M with normals: default / --k 16" "$cloud_default" "$cloud_k16" "<= 2"

# Readers: the read stage of `focal -v info FILE` (parse, and for STL the weld) on the 1M torus in
# every format, 1 and 2 threads (FOCAL_NUM_THREADS), fastest of $reps; OBJ and OFF from `focal
# generate`, STL binary and ascii exported by trimesh from the peers' venv when it is there.
read_ms() {
  local file=$1 threads=$2 best="" rss_max=0  # $3: the format's name
  for ((r = 0; r < reps; r++)); do
    FOCAL_NUM_THREADS=$threads /usr/bin/time -f "%M" -o "$scratch/time" \
      "$focal" -v info "$file" 2>"$scratch/log" >/dev/null
    local ms rss
    ms=$(awk '$1 == "read:" && $NF == "ms" {t = $2} END {print t + 0}' "$scratch/log")
    rss=$(tail -n1 "$scratch/time")
    ((rss > rss_max)) && rss_max=$rss
    if [[ -z $best ]] || awk -v a="$ms" -v b="$best" 'BEGIN {exit !(a < b)}'; then best=$ms; fi
  done
  printf "| %-11s | %6.0f | %d | %7.0f | %6.0f |\n" "$3" \
    "$(($(stat -c %s "$file") / 1000000))" "$threads" "$best" "$((rss_max / 1024))"
}
if ((max >= 1000000)); then
  echo
  echo "Readers: focal -v info FILE, the 1M-vertex torus; read stage (ms) of the fastest of $reps,"
  echo "largest peak RSS"
  echo
  echo "| format      |     MB | T | read ms | RSS MB |"
  echo "|-------------|-------:|--:|--------:|-------:|"
  for ext in obj off; do
    [[ -f $data/torus-1000000.$ext ]] ||
      "$focal" generate torus --vertices 1000000 -o "$data/torus-1000000.$ext" >&2
  done
  if [[ -x $(dirname "$0")/peers/.venv/bin/python && ! -f $data/torus-1000000-ascii.stl ]]; then
    "$(dirname "$0")/peers/.venv/bin/python" - "$(torus 1000000)" "$data/torus-1000000" <<'PY' >&2
import sys, trimesh
mesh = trimesh.load(sys.argv[1], process=False)
mesh.export(sys.argv[2] + "-binary.stl")
with open(sys.argv[2] + "-ascii.stl", "w") as f:
    f.write(trimesh.exchange.stl.export_stl_ascii(mesh))
PY
  fi
  for t in 1 2; do
    read_ms "$(torus 1000000)" "$t" "PLY binary"
    read_ms "$data/torus-1000000.obj" "$t" "OBJ"
    read_ms "$data/torus-1000000.off" "$t" "OFF"
    for kind in binary ascii; do
      file=$data/torus-1000000-$kind.stl
      if [[ -f $file ]]; then read_ms "$file" "$t" "STL $kind"; fi
    done
  done
fi

# Peers (libigl, pymeshlab, trimesh, VTK) on the bunny as ratios to focal, from their own venv
# made by bench/peers/setup.sh; skipped, with a line saying so, when it is not there. Then the
# side-by-side table of issue 19 on the 1M-vertex torus: focal default and --paper (compute and
# whole process), trueform, libigl, pymeshlab, VTK and CGAL 5.5's jets (bench/points/cgal_peer,
# built from Debian's libcgal-dev), median of FOCAL_BENCH_PEER_REPS (default 3) runs: about 4
# minutes on 2 cores. The peers that take minutes at 1M (trimesh's ball measures, pymeshlab's
# APSS and normal cycles) are left out there.
echo
peers=$(dirname "$0")/peers
if [[ -x $peers/.venv/bin/python ]]; then
  bunny 0 >/dev/null  # extracts bunny.off into the cache
  "$peers/.venv/bin/python" "$peers/peers.py" timing "$data/bunny.off" --focal "$focal" ||
    echo "Peers failed (exit $?); see the messages above."
  if ((max >= 1000000)); then
    cgal=$build/../points/cgal_peer
    [[ -x $cgal ]] || bash "$(dirname "$0")/points/build_peers.sh" "$(dirname "$cgal")" >&2
    # trueform at its pin in bench/python/requirements.txt (not the rest: Open3D is large).
    "$peers/.venv/bin/pip" install --quiet \
      "$(grep '^trueform==' "$(dirname "$0")/python/requirements.txt")" >&2
    echo
    "$peers/.venv/bin/python" "$peers/peers.py" timing "$(torus 1000000)" --focal "$focal" \
      --runs "${FOCAL_BENCH_PEER_REPS:-3}" --threads 2 --trueform --cgal "$cgal" \
      --only libigl "pymeshlab Taubin" "pymeshlab quadric" VTK trueform ||
      echo "Peers at 1M failed (exit $?); see the messages above."
    # Issue 36's targets against trueform, with and without the file's normals.
    for mesh in "$(torus 1000000)" "$(torus_without_normals 1000000)"; do
      echo
      "$peers/.venv/bin/python" "$peers/targets.py" mesh "$mesh" --focal "$focal" \
        --runs "${FOCAL_BENCH_PEER_REPS:-3}" --threads 2 ||
        echo "Targets on $mesh failed (exit $?); see the messages above."
    done
  fi
else
  echo "Peers skipped: no $peers/.venv (bench/peers/setup.sh creates it)."
fi
