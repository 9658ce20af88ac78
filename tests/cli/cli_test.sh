#!/usr/bin/env bash
# Tests of the `focal` command: exit codes, messages, the files it writes (or does not write) and
# the values in them. Exit codes (cli/main.cpp): 0 success, 1 usage error, 2 I/O or data error.
#
# Usage: cli_test.sh FOCAL_BINARY SCRATCH_DIR
# Prints one line per check and, last, "N passed, M failed"; exits 1 when any check failed.
#
# Most value checks use a unit sphere written by `focal generate` with its exact normals: every
# normal ray passes through the centre, so the two-slit fit is exact there (k1 = k2 = 1 up to
# rounding) and any looser bound has a stated reason.
#
# Checks run `bash -c '...' _ ARGS` with the script in single quotes on purpose (values come in as
# $1, $2...), so shellcheck's "expressions don't expand in single quotes" does not apply.
# shellcheck disable=SC2016
set -euo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 FOCAL_BINARY SCRATCH_DIR" >&2
  exit 2
fi
FOCAL=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
SCRATCH=$2
[[ -n $SCRATCH && $SCRATCH != / ]] || { echo "refusing to use '$SCRATCH' as scratch folder" >&2; exit 2; }
rm -rf "$SCRATCH"
mkdir -p "$SCRATCH"
cd "$SCRATCH"
LOG=$PWD/.log # stdout / stderr of the last run, kept out of the way of the outputs checked
mkdir -p "$LOG"
OUT=$LOG/stdout
ERR=$LOG/stderr

passed=0
failed=0
ok() {
  printf 'ok    %s\n' "$1"
  passed=$((passed + 1))
}
bad() {
  printf 'FAIL  %s%s\n' "$1" "${2:+ -- $2}"
  failed=$((failed + 1))
}
# check NAME COMMAND...: passes when COMMAND succeeds.
check() {
  local name=$1
  shift
  if "$@"; then ok "$name"; else bad "$name"; fi
}

# run ARGS...: runs focal; stdout in $OUT, stderr in $ERR, exit status in $rc.
rc=0
run() {
  rc=0
  "$FOCAL" "$@" >"$OUT" 2>"$ERR" || rc=$?
}

# expect_ok NAME ARGS...: focal ARGS exits 0.
expect_ok() {
  local name=$1
  shift
  run "$@"
  if [[ $rc -eq 0 ]]; then ok "$name"; else bad "$name" "exit $rc: $(head -c 300 "$ERR")"; fi
}

# expect_error NAME CODE TEXT OUTPUT ARGS...: focal ARGS exits CODE, stderr has an `Error:` line
# containing TEXT, and the path OUTPUT does not exist afterwards.
expect_error() {
  local name=$1 code=$2 text=$3 output=$4
  shift 4
  run "$@"
  local why=""
  [[ $rc -eq $code ]] || why+="exit $rc, expected $code; "
  grep -q '^Error: ' "$ERR" || why+="no 'Error:' line on stderr; "
  grep '^Error: ' "$ERR" | grep -qF -- "$text" || why+="no 'Error:' line mentions '$text'; "
  [[ ! -e $output ]] || why+="$output was created; "
  if [[ -z $why ]]; then ok "$name"; else bad "$name" "$why$(head -c 300 "$ERR")"; fi
}

# A number as focal writes it. Fields are matched against it before any arithmetic: mawk reads
# "nan" as a NaN, which fails every comparison, so a NaN would pass a "d > tol" test unnoticed.
NUM='^[-+]?([0-9]+[.]?[0-9]*|[.][0-9]+)([eE][-+]?[0-9]+)?$'

# max_dev FILE "COLS" TARGET: max |x - TARGET| over the listed CSV columns of every data row;
# prints "non-numeric" when any field is not a finite number or there are no rows.
max_dev() {
  awk -F, -v cols="$2" -v t="$3" -v re="$NUM" '
    BEGIN { n = split(cols, c, " ") }
    NR > 1 {
      rows++
      for (i = 1; i <= n; i++) {
        x = $(c[i])
        if (x !~ re) { bad = 1; continue }
        d = x - t; if (d < 0) d = -d; if (d > m) m = d
      }
    }
    END { if (bad || rows == 0) print "non-numeric"; else printf "%.3g\n", m }' "$1" 2>/dev/null || echo "no-file"
}

# within VALUE BOUND: VALUE is a number <= BOUND.
within() {
  awk -v x="$1" -v b="$2" -v re="$NUM" 'BEGIN { exit !(x ~ re && x + 0 <= b + 0) }'
}

# check_within NAME VALUE BOUND
check_within() {
  if within "$2" "$3"; then ok "$1 (got $2, bound $3)"; else bad "$1" "got $2, bound $3"; fi
}

# classes FILE: the distinct values of the class column (the last) with their counts.
# The class column by its name (the recommended estimator's CSV ends with `crease`).
classes() { awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "class") k = i; next }
  { c[$k]++ } END { for (x in c) printf "%s=%d ", x, c[x] }' "$1" 2>/dev/null || true; }

# data_rows FILE: lines after the header.
data_rows() { awk 'END { print NR - 1 }' "$1" 2>/dev/null || echo -1; }

# ply_header FILE: the header lines of a (binary or ascii) PLY file.
ply_header() { sed '/^end_header/q' "$1" 2>/dev/null || true; }

# ply_vertex_lines FILE: the vertex lines of an ascii PLY file.
ply_vertex_lines() {
  awk '/^element vertex / { n = $3 } body && n > 0 { print; n-- } /^end_header/ { body = 1 }' "$1" 2>/dev/null || true
}

# ico FORMAT: the regular icosahedron with unit circumradius and outward faces, without normals.
# FORMAT off, or obj (which gets an extra isolated vertex (5, 5, 5) as the 8th vertex).
ico() {
  awk -v fmt="$1" 'BEGIN {
    t = (1 + sqrt(5)) / 2; r = sqrt(1 + t * t)
    split("-1 t 0|1 t 0|-1 -t 0|1 -t 0|0 -1 t|0 1 t|0 -1 -t|0 1 -t|t 0 -1|t 0 1|-t 0 -1|-t 0 1", P, "|")
    split("0 11 5|0 5 1|0 1 7|0 7 10|0 10 11|1 5 9|5 11 4|11 10 2|10 7 6|7 1 8|3 9 4|3 4 2|3 2 6|" \
          "3 6 8|3 8 9|4 9 5|2 4 11|6 2 10|8 6 7|9 8 1", T, "|")
    if (fmt == "off") { print "OFF"; print "12 20 0" }
    for (i = 1; i <= 12; i++) {
      split(P[i], c, " ")
      for (j = 1; j <= 3; j++) c[j] = (c[j] == "t" ? t : c[j] == "-t" ? -t : c[j]) / r
      printf "%s%.17g %.17g %.17g\n", (fmt == "obj" ? "v " : ""), c[1], c[2], c[3]
      if (fmt == "obj" && i == 7) print "v 5 5 5"
    }
    for (i = 1; i <= 20; i++) {
      split(T[i], f, " ")
      if (fmt == "off") { printf "3 %d %d %d\n", f[1], f[2], f[3]; continue }
      for (j = 1; j <= 3; j++) { f[j]++; if (f[j] >= 8) f[j]++ }  # 1-based, after the extra vertex
      printf "f %d %d %d\n", f[1], f[2], f[3]
    }
  }'
}

HEADER='k1,k2,H,K,d1x,d1y,d1z,d2x,d2y,d2z,residual,class,crease'

# ---------------------------------------------------------------------------------------------
# Help and version
run -h
check "focal -h exits 0" test "$rc" -eq 0
check "focal -h shows the usage and every command" \
  bash -c 'grep -q "^Usage: .*SUBCOMMAND" "$1" && grep -q "^  info " "$1" && grep -q "^  generate " "$1" &&
           grep -q "^  curvature " "$1" && grep -q "^  focal-mesh " "$1"' _ "$OUT"
check "focal -h shows examples" grep -q '^  focal curvature mesh.ply -o fields.csv' "$OUT"

run curvature -h
check "focal curvature -h exits 0" test "$rc" -eq 0
check "focal curvature -h shows usage, options and examples" \
  bash -c 'grep -q "^Usage: .*curvature" "$1" && grep -q -- "--rings" "$1" && grep -q -- "--normals" "$1" &&
           grep -q "Examples:" "$1" && grep -q "^  focal curvature bunny.off -o bunny.csv" "$1"' _ "$OUT"
for sub in info generate focal-mesh; do
  run "$sub" -h
  check "focal $sub -h exits 0 with usage and an example" \
    bash -c '[[ $2 -eq 0 ]] && grep -q "^Usage: .*'"$sub"'" "$1" && grep -q "^  focal '"$sub"' " "$1"' _ "$OUT" "$rc"
done
run --version
check "focal --version prints the version" bash -c '[[ $2 -eq 0 ]] && grep -qx "focal 0.1.0" "$1"' _ "$OUT" "$rc"

# ---------------------------------------------------------------------------------------------
# Devices: the backend, driver and GPUs, or why none is usable; --require turns "none" into
# exit 2 (on a GPU machine it exits 0, as FOCAL_REQUIRE_GPU=1 runs of the suite expect).
run devices
check "focal devices exits 0 and names the backend" \
  bash -c '[[ $2 -eq 0 ]] && grep -q "^CUDA backend: " "$1"' _ "$OUT" "$rc"
if grep -q "^usable devices: *none: " "$OUT"; then
  expect_error "focal devices --require without a usable GPU: exit 2 saying why" 2 "no usable CUDA device: " "" devices --require
else
  run devices --require
  check "focal devices --require with a usable GPU exits 0" test "$rc" -eq 0
fi

# ---------------------------------------------------------------------------------------------
# The test surface
run generate sphere -o s.ply --truth t.csv
check "generate sphere exits 0 and reports what it wrote" \
  bash -c '[[ $2 -eq 0 ]] && grep -q "^wrote s.ply: sphere, [0-9]* vertices, [0-9]* triangles, truth in t.csv" "$1"' _ "$OUT" "$rc"
NV=$(sed -n 's/^wrote s.ply: sphere, \([0-9]*\) vertices.*/\1/p' "$OUT" || true)
NF=$(sed -n 's/^wrote s.ply: sphere, [0-9]* vertices, \([0-9]*\) triangles.*/\1/p' "$OUT" || true)
NV=${NV:-0} NF=${NF:-0}
check "generated vertex count is close to the default target 2000 ($NV)" test "$NV" -ge 1800 -a "$NV" -le 2200
check "s.ply header declares $NV vertices, $NF faces and normals" \
  bash -c 'h=$(sed "/^end_header/q" s.ply); grep -qx "element vertex $1" <<<"$h" && grep -qx "element face $2" <<<"$h" &&
           grep -qx "property double nx" <<<"$h"' _ "$NV" "$NF"
check "truth CSV has the header and one row per vertex" \
  bash -c '[[ $(head -1 t.csv) == k1,k2,H,K,d1x,d1y,d1z,d2x,d2y,d2z && $(awk "END{print NR-1}" t.csv) -eq $1 ]]' _ "$NV"
check_within "truth: k1 = k2 = H = K = 1 on the unit sphere" "$(max_dev t.csv "1 2 3 4" 1)" 1e-12

run info s.ply
check "info exits 0" test "$rc" -eq 0
check "info shows the vertex count $NV and the triangle count $NF" \
  bash -c 'grep -Eq "^vertices: +$1\$" "$3" && grep -Eq "^triangles: +$2 " "$3"' _ "$NV" "$NF" "$OUT"
check "info: the sphere is closed, one component, normals present" \
  bash -c 'grep -Eq "^edges: .*\(boundary 0, non-manifold 0\)" "$1" && grep -Eq "^components: +1 \(0 inward\)" "$1" &&
           grep -Eq "^vertex normals: +present" "$1"' _ "$OUT"
H_EDGE=$(sed -n 's/^mean edge length: *//p' "$OUT" || true)
check "info shows a mean edge length ($H_EDGE)" within "${H_EDGE:-x}" 1
H_EDGE=${H_EDGE:-0}
H2=$(awk -v h="$H_EDGE" 'BEGIN { printf "%.6g", h * h }')

# ---------------------------------------------------------------------------------------------
# Usage errors: exit 1, an Error: line, no output
expect_error "no subcommand: exit 1" 1 "subcommand" out.csv
expect_error "unknown subcommand: exit 1" 1 "frobnicate" out.csv frobnicate s.ply -o out.csv
expect_error "extra argument: exit 1" 1 "extra" out.csv curvature s.ply -o out.csv extra
expect_error "two commands at once: exit 1" 1 "curvature" out.csv info s.ply curvature s.ply -o out.csv
check "two commands at once: nothing on stdout (neither ran)" test ! -s "$OUT"
expect_error "unknown option: exit 1" 1 "--bogus" out.csv curvature s.ply -o out.csv --bogus
expect_error "missing -o: exit 1" 1 "--output" out.csv curvature s.ply
expect_error "missing input: exit 1" 1 "input" out.csv curvature -o out.csv
expect_error "--solver foo: exit 1" 1 "--solver" out.csv curvature s.ply -o out.csv --solver foo
expect_error "--method foo: exit 1" 1 "--method" out.csv curvature s.ply -o out.csv --method foo
expect_error "--weights foo: exit 1" 1 "--weights" out.csv curvature s.ply -o out.csv --weights foo
expect_error "--normals foo: exit 1" 1 "--normals" out.csv curvature s.ply -o out.csv --normals foo
expect_error "--rings 0: exit 1" 1 "--rings" out.csv curvature s.ply -o out.csv --rings 0
expect_error "--rings 17: exit 1" 1 "--rings" out.csv curvature s.ply -o out.csv --rings 17
expect_error "--rings two: exit 1" 1 "--rings" out.csv curvature s.ply -o out.csv --rings two
expect_error "--threads -1: exit 1" 1 "--threads" out.csv curvature s.ply -o out.csv --threads -1
expect_error "curvature -o out.txt (bad extension): exit 1" 1 "out.txt" out.txt curvature s.ply -o out.txt
expect_error "focal-mesh --max-distance -1: exit 1" 1 "--max-distance" pre.focal1.ply focal-mesh s.ply -o pre --max-distance -1
expect_error "focal-mesh --solver foo: exit 1" 1 "--solver" pre.focal1.ply focal-mesh s.ply -o pre --solver foo
expect_error "generate unknown surface: exit 1" 1 "foo" g.ply generate foo -o g.ply
expect_error "generate -o g.stl (cannot write STL): exit 1" 1 "g.stl" g.stl generate sphere -o g.stl
expect_error "generate --vertices 3: exit 1" 1 "--vertices" g.ply generate sphere -o g.ply --vertices 3
expect_error "info without input: exit 1" 1 "input" out.csv info
check "nothing was written by the usage errors" bash -c '[[ -z $(ls -A | grep -vx -e s.ply -e t.csv -e .log) ]]'

# ---------------------------------------------------------------------------------------------
# Input errors: exit 2, an Error: line naming the file, no output
printf 'OFF\n6 8 0\n1 0 0\n-1 0 0\n0 1 0\n' >truncated.off
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n' >bad_index.obj
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n2\n3\n' >no_y.ply
: >empty.ply
mkdir -p folder.ply
expect_error "missing input file: exit 2" 2 "missing.ply" out.csv curvature missing.ply -o out.csv
expect_error "directory as input: exit 2" 2 "folder.ply" out.csv curvature folder.ply -o out.csv
expect_error "truncated OFF: exit 2" 2 "truncated.off" out.csv curvature truncated.off -o out.csv
expect_error "truncated OFF: the message says where" 2 "line 5" out.csv curvature truncated.off -o out.csv
expect_error "OBJ face index out of range: exit 2" 2 "bad_index.obj" out.csv curvature bad_index.obj -o out.csv
expect_error "PLY without y: exit 2" 2 "no_y.ply" out.csv curvature no_y.ply -o out.csv
expect_error "empty PLY: exit 2" 2 "empty.ply" out.csv curvature empty.ply -o out.csv
expect_error "unknown input format: exit 2" 2 "t.csv" out.csv curvature t.csv -o out.csv
expect_error "info on a missing file: exit 2" 2 "missing.off" out.csv info missing.off
expect_error "focal-mesh on a truncated OFF: exit 2" 2 "truncated.off" pre.focal1.ply focal-mesh truncated.off -o pre
check "focal-mesh on a truncated OFF writes no focal2 either" test ! -e pre.focal2.ply
printf 'old\n' >keep.csv
run curvature truncated.off -o keep.csv
check "a failed run leaves an existing output as it was" bash -c '[[ $1 -eq 2 && $(cat keep.csv) == old ]]' _ "$rc"

# Outputs into a folder that does not exist: exit 2, nothing left behind
expect_error "curvature -o nodir/c.csv: exit 2" 2 "nodir/c.csv" nodir curvature s.ply -o nodir/c.csv
expect_error "curvature -o nodir/c.ply: exit 2" 2 "nodir/c.ply" nodir curvature s.ply -o nodir/c.ply
expect_error "focal-mesh -o nodir/pre: exit 2" 2 "nodir/pre" nodir focal-mesh s.ply -o nodir/pre
expect_error "generate -o nodir/g.ply: exit 2" 2 "nodir/g.ply" nodir generate sphere -o nodir/g.ply
expect_error "generate --truth nodir/t.csv: exit 2, no mesh left" 2 "nodir/t.csv" g.ply \
  generate sphere -o g.ply --truth nodir/t.csv
# The second focal mesh cannot be written (its name is taken by a folder): no first one is left.
mkdir -p clash.focal2.ply
expect_error "focal-mesh whose 2nd output fails: exit 2, no 1st output left" 2 "clash.focal2.ply" \
  clash.focal1.ply focal-mesh s.ply -o clash

# ---------------------------------------------------------------------------------------------
# Curvature of the unit sphere with its exact normals
run curvature s.ply -o c.csv
check "curvature s.ply -o c.csv exits 0 silently" bash -c '[[ $1 -eq 0 && ! -s $2 ]]' _ "$rc" "$ERR"
check "CSV header is exactly $HEADER" test "$(head -1 c.csv)" = "$HEADER"
check "CSV has one row per vertex ($NV)" test "$(data_rows c.csv)" -eq "$NV"
check "CSV rows have 13 fields" bash -c '[[ -s c.csv && -z $(awk -F, "NF != 13" c.csv) ]]'
check "sphere: no crease vertex" test "$(awk -F, 'NR > 1 { s += $13 } END { print s + 0 }' c.csv)" -eq 0
run curvature s.ply -o cp.csv --paper
check "--paper CSV has no crease column" test "$(head -1 cp.csv)" = "${HEADER%,crease}"
# Exact normals: every ray passes through the centre and the closed-form fit is exact.
check_within "sphere: every k1 and k2 is 1 within 1e-6" "$(max_dev c.csv "1 2" 1)" 1e-6
check_within "sphere: every H and K is 1 within 1e-6" "$(max_dev c.csv "3 4" 1)" 1e-6
check_within "sphere: residual 0 within 1e-9 (rays meet exactly)" "$(max_dev c.csv 11 0)" 1e-9
check "sphere: every class is umbilic" test "$(classes c.csv)" = "umbilic=$NV "

# Radius 2: k = 1/r = 0.5, positive with outward normals.
run generate sphere --a 2 -o s2.ply
run curvature s2.ply -o c2.csv
check_within "sphere of radius 2: k1, k2 = 0.5 within 1e-6" "$(max_dev c2.csv "1 2" 0.5)" 1e-6

# The same fields as ascii PLY: positions, normals and directions together.
run curvature s.ply -o ca.ply --ascii
check "curvature -o ca.ply --ascii exits 0" test "$rc" -eq 0
check "ascii PLY: format ascii, $NV vertices" \
  bash -c 'h=$(sed "/^end_header/q" ca.ply); grep -qx "format ascii 1.0" <<<"$h" && grep -qx "element vertex $1" <<<"$h"' _ "$NV"
ply_vertex_lines ca.ply >ca.vertices
check "ascii PLY: $NV vertex lines of 19 values (the last: crease, 0 on the sphere)" \
  bash -c '[[ $1 -gt 0 && $(wc -l <ca.vertices) -eq $1 && -z $(awk "NF != 19 || \$19 != 0" ca.vertices) ]]' _ "$NV"
# Columns: x y z nx ny nz k1 k2 H K d1x d1y d1z d2x d2y d2z residual class; fields are float32
# (relative rounding 6e-8), so 1e-6 bounds the rounding of these sums of three products.
DIR_DEV=$(awk -v re="$NUM" '{
    n++
    for (i = 1; i <= 17; i++) if ($i !~ re) bad = 1
    v[1] = $11*$11 + $12*$12 + $13*$13 - 1         # |d1| = 1
    v[2] = $14*$14 + $15*$15 + $16*$16 - 1         # |d2| = 1
    v[3] = $11*$14 + $12*$15 + $13*$16             # d1 . d2 = 0
    v[4] = $11*$4 + $12*$5 + $13*$6                # d1 . N = 0
    v[5] = $14*$4 + $15*$5 + $16*$6                # d2 . N = 0
    v[6] = ($12*$16 - $13*$15)*$4 + ($13*$14 - $11*$16)*$5 + ($11*$15 - $12*$14)*$6 - 1  # (d1 x d2) . N = 1
    for (i = 1; i <= 6; i++) { d = v[i] < 0 ? -v[i] : v[i]; if (d > m) m = d }
  } END { if (bad || n == 0) print "non-numeric"; else printf "%.3g\n", m }' ca.vertices || true)
check_within "ascii PLY: d1, d2 unit, orthogonal, tangent, (d1, d2, N) right-handed" "$DIR_DEV" 1e-6
K_DEV=$(awk -v re="$NUM" '{
    n++
    for (i = 7; i <= 8; i++) { if ($i !~ re) { bad = 1; continue } d = $i - 1; if (d < 0) d = -d; if (d > m) m = d }
  } END { if (bad || n == 0) print "non-numeric"; else printf "%.3g\n", m }' ca.vertices || true)
check_within "ascii PLY: k1, k2 = 1 within 1e-6 (float32)" "$K_DEV" 1e-6
check "ascii PLY: class code 3 (umbilic) everywhere" bash -c '[[ -s ca.vertices && -z $(awk "\$18 != 3" ca.vertices) ]]'

# Binary PLY: the header lists the fields and the class codes.
run curvature s.ply -o c.ply
check "curvature -o c.ply exits 0" test "$rc" -eq 0
ply_header c.ply >c.header
check "PLY: binary little endian with $NV vertices and $NF faces" \
  bash -c 'grep -qx "format binary_little_endian 1.0" c.header && grep -qx "element vertex $1" c.header &&
           grep -qx "element face $2" c.header' _ "$NV" "$NF"
check "PLY: vertex properties are x y z nx ny nz k1 k2 H K d1x d1y d1z d2x d2y d2z residual class crease" \
  test "$(awk '/^element/ { e = $2 } e == "vertex" && $1 == "property" { printf "%s ", $3 }' c.header)" \
  = "x y z nx ny nz k1 k2 H K d1x d1y d1z d2x d2y d2z residual class crease "
check "PLY: k1 is float, class is uchar" bash -c 'grep -qx "property float k1" c.header && grep -qx "property uchar class" c.header'
check "PLY: a comment lists the class codes" \
  grep -q '^comment .*class codes: 0=elliptic 1=hyperbolic 2=parabolic 3=umbilic 4=flat 5=undefined' c.header
run info c.ply
check "PLY output reads back with $NV vertices" bash -c '[[ $1 -eq 0 ]] && grep -Eq "^vertices: +$2\$" "$3"' _ "$rc" "$NV" "$OUT"

# --float32: every real number written as a float (the library's tests check each value is the
# float of the double); here: the same rows, words and flags, shorter numbers, `float` in PLY.
# max_digits FILE COLS: the most significant digits of a number in the listed columns (fields
# split on commas and blanks); a float needs at most 9, a double up to 17.
max_digits() {
  awk -F'[ ,]' -v cols="$2" 'BEGIN { n = split(cols, c, " ") }
    function digits(x) { sub(/^-/, "", x); sub(/[eE].*/, "", x); sub(/[.]/, "", x); sub(/^0+/, "", x); return length(x) }
    NR > 1 || FILENAME !~ /csv$/ { for (i = 1; i <= n; i++) { d = digits($(c[i])); if (d > m) m = d } }
    END { print m + 0 }' "$1" 2>/dev/null || echo 99
}
run curvature s.ply -o c32.csv --float32
check "--float32 CSV: exit 0, the header and row count of the double file" \
  bash -c '[[ $1 -eq 0 && $(head -1 c32.csv) == "$(head -1 c.csv)" && $(awk "END { print NR }" c32.csv) -eq $(awk "END { print NR }" c.csv) ]]' _ "$rc"
check "--float32 CSV: class and crease columns are the double file's" \
  bash -c 'cmp -s <(cut -d, -f12- c.csv) <(cut -d, -f12- c32.csv)'
check_within "--float32 CSV: k1, k2 = 1 within 1e-6" "$(max_dev c32.csv "1 2" 1)" 1e-6
check_within "--float32 CSV: at most 9 significant digits (float shortest form)" \
  "$(max_digits c32.csv "1 2 3 4 5 6 7 8 9 10 11")" 9
check "the double CSV has numbers of more than 9 digits (max_digits sees the difference)" \
  bash -c '[[ $1 -gt 9 ]]' _ "$(max_digits c.csv "1 2 3 4 5 6 7 8 9 10 11")"
check "--float32 CSV is smaller than the double one" \
  bash -c '[[ $(wc -c <c32.csv) -lt $(wc -c <c.csv) ]]'
run curvature s.ply -o c32.ply --float32
ply_header c32.ply >c32.header
check "--float32 PLY: positions, normals and fields are float, class and crease uchar" \
  bash -c '[[ $1 -eq 0 ]] && grep -qx "property float x" c32.header && grep -qx "property float nz" c32.header &&
           grep -qx "property float k1" c32.header && grep -qx "property uchar crease" c32.header &&
           ! grep -q double c32.header' _ "$rc"
# 6 reals of 4 bytes less per vertex, and "float" is one letter shorter than "double" in 6 lines.
check "--float32 PLY: 24 bytes less per vertex than the double file (and 6 in the header)" \
  bash -c '[[ $(( $(wc -c <c.ply) - $(wc -c <c32.ply) )) -eq $(( 24 * $1 + 6 )) ]]' _ "$NV"
run info c32.ply
check "--float32 PLY reads back with $NV vertices" bash -c '[[ $1 -eq 0 ]] && grep -Eq "^vertices: +$2\$" "$3"' _ "$rc" "$NV" "$OUT"
run curvature s.ply -o ca32.ply --ascii --float32
ply_vertex_lines ca32.ply >ca32.vertices
check "--float32 --ascii PLY: $NV vertex lines of 19 values, class and crease as in the double file" \
  bash -c '[[ $(wc -l <ca32.vertices) -eq $1 ]] && cmp -s <(cut -d" " -f18- ca.vertices) <(cut -d" " -f18- ca32.vertices)' _ "$NV"
check_within "--float32 --ascii PLY: at most 9 significant digits" \
  "$(max_digits ca32.vertices "$(seq -s " " 1 17)")" 9
run focal-mesh s.ply -o p64 --ascii
run focal-mesh s.ply -o p32 --float32 --ascii
check "focal-mesh --float32: float focal points, uchar focal_flag" \
  bash -c '[[ $1 -eq 0 ]] && for j in 1 2; do h=$(sed "/^end_header/q" p32.focal$j.ply) &&
           grep -qx "property float x" <<<"$h" && grep -qx "property uchar focal_flag" <<<"$h" &&
           ! grep -q double <<<"$h" || exit 1; done' _ "$rc"
check "focal-mesh --float32: the flags of the double files" \
  bash -c 'flags() { awk "/^element vertex / { n = \$3 } body && n > 0 { print \$4; n-- } /^end_header/ { body = 1 }" "$1"; }
           [[ -s p64.focal1.ply ]] && cmp -s <(flags p64.focal1.ply) <(flags p32.focal1.ply) &&
           cmp -s <(flags p64.focal2.ply) <(flags p32.focal2.ply)'
run normals s.ply -o n32.xyz --float32
check "normals --float32: exit 0, $NV points" \
  bash -c '[[ $1 -eq 0 && $(wc -l <n32.xyz) -eq $2 ]]' _ "$rc" "$NV"
check_within "normals --float32: at most 9 significant digits" "$(max_digits n32.xyz "1 2 3 4 5 6")" 9

# ---------------------------------------------------------------------------------------------
# Estimator options on the sphere
variant() { # NAME BOUND ARGS...: runs curvature with ARGS into v.csv, checks |k - 1| <= BOUND
  local name=$1 bound=$2
  shift 2
  rm -f v.csv
  run curvature s.ply -o v.csv "$@"
  if [[ $rc -ne 0 ]]; then bad "$name: exit $rc" "$(head -c 300 "$ERR")"; return; fi
  check "$name: one row per vertex" test "$(data_rows v.csv)" -eq "$NV"
  check_within "$name: |k - 1|" "$(max_dev v.csv "1 2" 1)" "$bound"
}
# Rays through the centre are fitted exactly whatever the solver, neighbourhood or weights.
variant "--solver levenberg-marquardt" 1e-6 --solver levenberg-marquardt
variant "--rings 2" 1e-6 --rings 2
variant "--weights gaussian" 1e-6 --weights gaussian
variant "--rings 3 --weights gaussian --solver levenberg-marquardt" 1e-6 --rings 3 --weights gaussian --solver levenberg-marquardt
variant "--normals file" 1e-6 --normals file
# Max's weights give the exact normal at vertices whose neighbours lie on a sphere (Max 1999).
variant "--normals max" 1e-6 --normals max
# The triangle method fits rays in the plane of each face, which lies inside the sphere by its
# sag s ~ r_circ^2 / 2 ~ e^2 / 6 (e the edges), so k = 1 / (1 - s) ~ 1 + e^2 / 6: bound h^2,
# h the mean edge length, leaves room for edges up to ~2.4 h.
variant "--method triangle" "$H2" --method triangle
check "--method triangle: output differs from the vertex method" bash -c '[[ -s v.csv ]] && ! cmp -s v.csv c.csv'

# ---------------------------------------------------------------------------------------------
# The default is the recommended estimator (recommended.h); --paper is the paper's method.
# On exact normals the recommended estimator keeps them: the sphere's output is the paper's.
variant "--paper" 1e-6 --paper
DEFAULT_VS_PAPER=$(paste -d, v.csv c.csv | awk -F, 'NR > 1 { for (i = 1; i <= 4; i++) {
    d = $i - $(i + 12); if (d < 0) d = -d; if (d > m) m = d } } END { printf "%.3g\n", m + 0 }')
check_within "--paper on exact normals: k1 k2 H K as the default's (rounding of the normals)" \
  "$DEFAULT_VS_PAPER" 1e-12
variant "--paper --rings 2" 1e-6 --paper --rings 2
# Noisy file normals (the paper's 5%): the default replaces them with normals from the positions.
run generate torus --triangulation irregular --vertices 3000 --normal-noise 0.05 -o tn.ply --truth tn.csv
run curvature tn.ply -o tn-default.csv
run curvature tn.ply -o tn-paper.csv --paper
rel_h() { # ESTIMATE.csv: relative RMS error of H against tn.csv (column 3 of both; the truth
  # starts after the estimate's columns, 13 with the default's crease column, 12 with --paper)
  paste -d, "$1" tn.csv | awk -F, -v n="$(head -1 "$1" | awk -F, '{ print NF }')" \
    'NR > 1 { d = $3 - $(n + 3); e += d * d; t += $(n + 3) * $(n + 3) }
    END { if (t > 0) printf "%.4g\n", sqrt(e / t); else print "nan" }'
}
REL_DEFAULT=$(rel_h tn-default.csv)
REL_PAPER=$(rel_h tn-paper.csv)
# Measured 0.0156 (default) and 0.131 (paper) at 3010 vertices, seed 1.
check_within "noisy normals, default: relative RMS error of H" "$REL_DEFAULT" 0.03
check "noisy normals: the default is 4x more accurate than --paper ($REL_DEFAULT vs $REL_PAPER)" \
  awk -v a="$REL_DEFAULT" -v b="$REL_PAPER" 'BEGIN { exit !(a > 0 && 4 * a < b) }'
run curvature tn.ply -o tn-v.csv -v
check "-v names the recommended estimator and its plan" grep -q "recommended estimator: .*1-ring fit" "$ERR"
# Angle weights are exact only on symmetric vertex stars: the normal errors are O(h^2), and a
# curvature is a normal difference over an edge, so the bound is O(h): h.
variant "--normals angle" "$H_EDGE" --normals angle
check "--normals angle: output differs from the file's normals" bash -c '[[ -s v.csv ]] && ! cmp -s v.csv c.csv'
# Area weights are only first-order where the incident triangles differ in size (next to the
# poles, thin fan triangles meet grid cells): normal errors O(h), curvature errors O(1). The bound
# is empirical for this mesh (measured 0.17): it checks the option runs and gives a sphere-like
# positive curvature, not accuracy.
variant "--normals area" 0.25 --normals area
check "--normals area: output differs from the file's normals" bash -c '[[ -s v.csv ]] && ! cmp -s v.csv c.csv'
check "--normals area: every vertex elliptic or umbilic" \
  bash -c '[[ -s v.csv && -z $(awk -F, "NR > 1 && \$12 != \"elliptic\" && \$12 != \"umbilic\"" v.csv) ]]'

# Results do not depend on the thread count (README): an irregular torus, non-trivial values.
run generate torus --triangulation irregular --vertices 3000 -o torus.ply
run curvature torus.ply -o torus1.csv --threads 1
run curvature torus.ply -o torus3.csv --threads 3
check "--threads 1 and --threads 3 give identical files (irregular torus)" \
  bash -c '[[ -s torus1.csv ]] && cmp -s torus1.csv torus3.csv'
check "torus: both elliptic and hyperbolic vertices" \
  bash -c 'c=$(awk -F, "NR > 1 { print \$12 }" torus1.csv | sort -u); grep -qx elliptic <<<"$c" && grep -qx hyperbolic <<<"$c"'

# --tiles N: the mesh in N tiles with halos, one after the other (docs/SCALE.md): the same file.
run curvature torus.ply -o torus-tiles.csv --tiles 7 --threads 1
check "--tiles 7 gives the file of the whole run (recommended estimator)" \
  bash -c '[[ $1 -eq 0 && -s torus-tiles.csv ]] && cmp -s torus1.csv torus-tiles.csv' _ "$rc"
run curvature torus.ply -o torus-paper.csv --paper --rings 2
run curvature torus.ply -o torus-paper-tiles.csv --paper --rings 2 --tiles 5
check "--tiles 5 gives the file of the whole run (--paper --rings 2)" \
  bash -c '[[ $1 -eq 0 && -s torus-paper.csv ]] && cmp -s torus-paper.csv torus-paper-tiles.csv' _ "$rc"
expect_error "--tiles 0: a usage error" 1 "--tiles" t0.csv curvature torus.ply -o t0.csv --tiles 0
expect_error "--tiles with a .ply output: a usage error" 1 ".csv" t.ply curvature torus.ply -o t.ply --tiles 3

# ---------------------------------------------------------------------------------------------
# Meshes without normals
ico off >ico.off
run info ico.off
check "hand-written icosahedron: 12 vertices, no normals" \
  bash -c '[[ $1 -eq 0 ]] && grep -Eq "^vertices: +12\$" "$2" && grep -Eq "^vertex normals: +none" "$2"' _ "$rc" "$OUT"
expect_error "--normals file on a mesh without normals: exit 2" 2 "no vertex normals" out.csv \
  curvature ico.off -o out.csv --normals file
# Default: Max's weights, exact on the icosahedron (its vertices lie on the unit sphere), so
# every ray again passes through the centre.
run curvature ico.off -o ico.csv
check "icosahedron without normals: exit 0, 12 rows" bash -c '[[ $1 -eq 0 && $(awk "END{print NR-1}" ico.csv) -eq 12 ]]' _ "$rc"
check_within "icosahedron without normals: k1, k2 = 1 within 1e-6" "$(max_dev ico.csv "1 2" 1)" 1e-6

# The generated sphere as OFF is NOFF (normals); stripping them gives a normals-free OFF.
run generate sphere -o so.off
check "generate -o so.off writes NOFF (it has normals)" bash -c '[[ $1 -eq 0 && $(head -1 so.off) == NOFF ]]' _ "$rc"
awk 'NR == 1 { print "OFF"; next } NR == 2 { nv = $1; print; next } nv > 0 { print $1, $2, $3; nv--; next } { print }' \
  so.off >plain.off 2>/dev/null || true
run info plain.off
check "the stripped OFF has $NV vertices and no normals" \
  bash -c 'grep -Eq "^vertices: +$1\$" "$2" && grep -Eq "^vertex normals: +none" "$2"' _ "$NV" "$OUT"
expect_error "--normals file on the stripped OFF: exit 2" 2 "no vertex normals" out.csv \
  curvature plain.off -o out.csv --normals file
run curvature plain.off -o plain.csv
check_within "stripped OFF, default (Max normals where smoother than jets): k1, k2 = 1 within 1e-6" "$(max_dev plain.csv "1 2" 1)" 1e-6

# An isolated vertex (the 8th of 13) in an OBJ: its row is NaN and undefined, in place.
ico obj >iso.obj
run curvature iso.obj -o iso.csv
check "OBJ with an isolated vertex: exit 0, 13 rows" bash -c '[[ $1 -eq 0 && $(awk "END{print NR-1}" iso.csv) -eq 13 ]]' _ "$rc"
check "isolated vertex: row 8 is all nan with class undefined" \
  test "$(sed -n 9p iso.csv)" = "nan,nan,nan,nan,nan,nan,nan,nan,nan,nan,nan,undefined,0"
sed 9d iso.csv >iso_others.csv 2>/dev/null || true
check_within "the other 12 rows: k1, k2 = 1 within 1e-6" "$(max_dev iso_others.csv "1 2" 1)" 1e-6
check "the other 12 rows are umbilic" test "$(classes iso_others.csv)" = "umbilic=12 "

# ---------------------------------------------------------------------------------------------
# Dirty input: one Warning: line counting the problems, affected rows undefined, --strict errors
run curvature iso.obj -o iso2.csv
check "isolated vertex: exactly one Warning: line, naming the file and the count" \
  bash -c '[[ $(grep -c "^Warning: " "$1") -eq 1 ]] && grep -q "^Warning: iso.obj: found 1 unreferenced vertex (--strict" "$1"' _ "$ERR"
check "the warning changes nothing in the output" cmp -s iso.csv iso2.csv
expect_error "--strict on the isolated vertex: exit 2" 2 "iso.obj: --strict: 1 unreferenced vertex" iso3.csv \
  curvature iso.obj -o iso3.csv --strict
expect_error "focal-mesh --strict: exit 2, no focal mesh" 2 "--strict" isof.focal1.ply focal-mesh iso.obj -o isof --strict
check "focal-mesh --strict writes no focal2 either" test ! -e isof.focal2.ply
run curvature s.ply -o strict.csv --strict
check "--strict on the clean sphere: exit 0, no warning, same output" \
  bash -c '[[ $1 -eq 0 && ! -s $2 ]] && cmp -s strict.csv c.csv' _ "$rc" "$ERR"

# A NaN coordinate (vertex 2) and a duplicate face: the run completes, vertex 2 is undefined.
printf 'OFF\n5 5 0\n0 0 0\n1 0 0\nnan 1 0\n0 1 0\n0.5 0.5 1\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n3 0 1 4\n' >nan.off
run curvature nan.off -o nan.csv
check "NaN coordinate: exit 0, 5 rows" bash -c '[[ $1 -eq 0 && $2 -eq 5 ]]' _ "$rc" "$(data_rows nan.csv)"
check "NaN coordinate: the warning counts it and the duplicate face" \
  grep -q "^Warning: nan.off: found 1 non-finite vertex, 1 duplicate face" "$ERR"
check "NaN coordinate: row 2 is all nan with class undefined" \
  test "$(sed -n 4p nan.csv)" = "nan,nan,nan,nan,nan,nan,nan,nan,nan,nan,nan,undefined,0"
expect_error "NaN coordinate with --strict: exit 2" 2 "1 non-finite vertex" nan2.csv curvature nan.off -o nan2.csv --strict

# File normals that are not unit length are normalised, and counted in the summary.
printf 'NOFF\n3 1\n0 0 0 0 0 2\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n' >long.off
run curvature long.off -o long.csv
check "non-unit normal: exit 0, counted, and every vertex flat" \
  bash -c '[[ $1 -eq 0 && $3 == "flat=3 " ]] && grep -q "^Warning: long.off: found 1 non-unit normal" "$2"' _ "$rc" "$ERR" "$(classes long.csv)"

# A single triangle without normals: no finding to report, and no curvature to estimate (its three
# estimated normals are the one face normal): three undefined rows, not flat ones, and the
# warning that every vertex is undefined as the only line (issue 13).
printf 'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' >one.off
run curvature one.off -o one.csv --strict
check "single triangle: exit 0 with --strict, 3 undefined rows, only the all-undefined warning" \
  bash -c '[[ $1 -eq 0 && $(wc -l <"$2") -eq 1 && $3 == "undefined=3 " ]] &&
    grep -q "^Warning: one.off: every vertex is undefined (3)" "$2"' _ "$rc" "$ERR" "$(classes one.csv)"

# What the normals stage takes from the check stage (cli/estimator_flags.cpp reuses its findings
# instead of recomputing the orientation and the face normals): each warning still appears.
# The icosahedron with every face reversed: one closed inward component, turned outward, so the
# output equals that of the outward icosahedron (default and --paper).
ico off | awk 'NF == 4 && $1 == 3 { print 3, $2, $4, $3; next } { print }' >inward.off
for estimator in default --paper; do
  flag=${estimator/default/}
  run curvature ico.off -o ico-out.csv ${flag:+"$flag"}
  run curvature inward.off -o inward.csv ${flag:+"$flag"}
  check "inward icosahedron ($estimator): warns that it reversed the faces, output as outward" \
    bash -c 'grep -q "^Warning: inward.off: 1 closed component(s) are oriented inward; their faces were reversed" "$1" &&
             cmp -s "$2" ico-out.csv' _ "$ERR" inward.csv
done
# The sphere with its normals negated: counted against the faces, and the estimator warns.
awk 'NR == 2 { nv = $1 } NR > 2 && nv > 0 { print $1, $2, $3, -$4, -$5, -$6; nv--; next } { print }' \
  so.off >against.off 2>/dev/null || true
for estimator in default --paper; do
  flag=${estimator/default/}
  run curvature against.off -o against.csv ${flag:+"$flag"}
  check "normals against the faces ($estimator): counted, and the sign warning" \
    bash -c '[[ $1 -eq 0 ]] && grep -q "normals against their faces" "$2" &&
             grep -q "^Warning: against.off: most file normals point against the face orientation" "$2"' _ "$rc" "$ERR"
done
# A missing (NaN) normal row is filled from the faces; outward normals raise no sign warning.
awk 'NR == 3 { print $1, $2, $3, "nan nan nan"; next } { print }' so.off >missing.off 2>/dev/null || true
run curvature missing.off -o missing.csv --paper
check "a NaN file normal: filled from the faces, no sign warning" \
  bash -c '[[ $1 -eq 0 ]] && grep -q "1 vertices have no usable normal in the file" "$2" &&
           ! grep -q "point against" "$2"' _ "$rc" "$ERR"
check_within "a NaN file normal: k1, k2 = 1 within 1e-6 (Max normals are exact on the sphere)" \
  "$(max_dev missing.csv "1 2" 1)" 1e-6

# Unwritable output: a folder in the way; nothing is left behind.
mkdir -p taken.csv
expect_error "output path is a folder: exit 2" 2 "taken.csv" taken.csv/x curvature s.ply -o taken.csv

# ---------------------------------------------------------------------------------------------
# Determinism: byte-identical files for FOCAL_NUM_THREADS=1 and 2, both methods, all outputs.
# The irregular torus has 3000 vertices, above the size from which loops run in parallel.
for method in vertex triangle; do
  for n in 1 2; do
    FOCAL_NUM_THREADS=$n "$FOCAL" curvature torus.ply -o "det-$method-$n.csv" --method "$method" >/dev/null 2>&1 || true
    FOCAL_NUM_THREADS=$n "$FOCAL" curvature torus.ply -o "det-$method-$n.ply" --method "$method" --rings 2 >/dev/null 2>&1 || true
    FOCAL_NUM_THREADS=$n "$FOCAL" focal-mesh torus.ply -o "det-$method-$n" --method "$method" >/dev/null 2>&1 || true
  done
  for out in csv ply focal1.ply focal2.ply; do
    check "FOCAL_NUM_THREADS=1 and 2 give identical $out files (--method $method)" \
      bash -c '[[ -s $1 ]] && cmp -s "$1" "$2"' _ "det-$method-1.$out" "det-$method-2.$out"
  done
done

# ---------------------------------------------------------------------------------------------
# Focal meshes
run focal-mesh s.ply -o pre
check "focal-mesh exits 0 and reports both files" \
  bash -c '[[ $1 -eq 0 ]] && grep -q "^wrote pre.focal1.ply ($2 faces) and pre.focal2.ply ($2 faces)" "$3"' _ "$rc" "$NF" "$OUT"
for j in 1 2; do
  check "pre.focal$j.ply: $NV vertices with focal_flag, $NF faces" \
    bash -c '[[ -f $1 ]] && h=$(sed "/^end_header/q" "$1") && grep -qx "element vertex $2" <<<"$h" &&
             grep -qx "property uchar focal_flag" <<<"$h" && grep -qx "element face $3" <<<"$h"' _ "pre.focal$j.ply" "$NV" "$NF"
done
# Gamma_j = S - N / k_j: on the unit sphere every focal point is the centre.
run focal-mesh s.ply -o pa --ascii
for j in 1 2; do
  FOCAL_DEV=$(ply_vertex_lines "pa.focal$j.ply" | awk -v re="$NUM" '{
      n++; if ($4 != 0) flag = 1
      for (i = 1; i <= 3; i++) { if ($i !~ re) { bad = 1; continue } d = $i < 0 ? -$i : $i; if (d > m) m = d }
    } END { if (bad || flag || n == 0) print "bad"; else printf "%.3g\n", m }' || true)
  check_within "pa.focal$j.ply: every focal point at the centre, flag finite" "$FOCAL_DEV" 1e-6
done

# ---------------------------------------------------------------------------------------------
# -v: stage timings and a summary on stderr
stages_ok() { # STDERR STAGE...: a timing line "  <stage>: <ms> ms" for each stage
  local f=$1
  shift
  for s in "$@"; do grep -Eq "^  $s: +[0-9]+\.[0-9] ms\$" "$f" || return 1; done
}
run -v curvature s.ply -o cv.csv
check "-v curvature: exit 0" test "$rc" -eq 0
check "-v curvature: stage timings read, normals, curvature, write" stages_ok "$ERR" read normals curvature write
check "-v curvature: summary of classes" grep -q "^  classes: .*umbilic=$NV" "$ERR"
check "-v curvature: the CSV is the same as without -v" cmp -s cv.csv c.csv
run curvature s.ply -o cv2.csv -v
check "-v after the subcommand works too" stages_ok "$ERR" read curvature write
run -v focal-mesh s.ply -o pv
check "-v focal-mesh: stage timings include the focal meshes" stages_ok "$ERR" read curvature "focal meshes" write
run -v generate sphere -o gv.ply
check "-v generate: a generate timing" stages_ok "$ERR" generate

# eval: every estimator on every analytic case (8 surfaces x 2 triangulations x 3 noise models)
run eval --suite standard --vertices 300 --csv ev.csv --markdown ev.md --export evx
check "eval: exit 0" test "$rc" -eq 0
check "eval: 48 cases x 16 estimators in the CSV" test "$(data_rows ev.csv)" -eq 768
check "eval: focal default with and without normals in every case" \
  test "$(grep -c ',focal default / \(file\|no\) normals,' ev.csv)" -eq 96
check "eval: the Markdown table has a row per case" test "$(grep -c '^| [a-z-]*, ' ev.md)" -eq 48
check "eval: exact on the clean sphere (relative H error below 1e-9)" \
  awk -F, '$1 == "sphere" && $3 == "clean" && $4 == "focal closed-form 1-ring / file normals" { found = 1; if (!($7 + 0 < 1e-9)) exit 1 } END { exit !found }' ev.csv
check "eval --export: an index of the 48 cases" test "$(data_rows evx/cases.csv)" -eq 48
check "eval --export: a mesh and a truth CSV per case" \
  test "$(ls evx/*.ply | wc -l)" -eq 48 -a "$(ls evx/*.truth.csv | wc -l)" -eq 48
check "eval --export: the mesh carries the (noisy) file normals" \
  grep -q "^property double nx" <(ply_header evx/sphere-regular-normal-noise.ply)
check "eval --export: truth columns with the interior flag" \
  test "$(head -n 1 evx/saddle-irregular-clean.truth.csv)" = "k1,k2,H,K,d1x,d1y,d1z,d2x,d2y,d2z,interior"
check "eval --export: the open saddle has vertices near its boundary" \
  awk -F, 'NR > 1 && $11 == 0 { found = 1 } END { exit !found }' evx/saddle-irregular-clean.truth.csv
run eval --markdown ev.txt
check "eval: a wrong report extension is a usage error" test "$rc" -eq 1
run eval --suite nonsense
check "eval: an unknown suite is a usage error" test "$rc" -eq 1

# eval --suite hard: the hard cases of issue 16 by category
run eval --suite hard --vertices 300 --csv evh.csv --markdown evh.md
check "eval --suite hard: exit 0" test "$rc" -eq 0
check "eval --suite hard: 41 cases x 16 estimators in the CSV" test "$(data_rows evh.csv)" -eq 656
check "eval --suite hard: every category in the CSV" test "$(cut -d, -f20 evh.csv | sort -u | \
  grep -c -x -e anisotropic -e 'graded density' -e coarse -e 'strong vertex noise' \
  -e 'strong normal noise' -e outliers -e 'near boundaries' -e creases)" -eq 8
check "eval --suite hard: a summary row per category and one for all" \
  test "$(grep -c '^| [a-z ]* | [0-9]* | [0-9]* | [0-9]* |' evh.md)" -eq 9
check "eval --suite hard: no undefined vertex of focal default on the creases" \
  awk -F, '$20 == "creases" && $4 ~ /^focal default/ { found = 1; if ($6 != 0) exit 1 } END { exit !found }' evh.csv

# eval --scan: smoothness of H on meshes without truth (paper Fig. 7)
run eval --scan s.ply --csv sc.csv --markdown sc.md --export scx
check "eval --scan: exit 0" test "$rc" -eq 0
check "eval --scan: a row per method (s.ply has normals: 8 methods)" test "$(data_rows sc.csv)" -eq 8
check "eval --scan: H keeps its sign on the sphere" \
  awk -F, 'NR > 1 { n++; if ($12 != 0) exit 1 } END { exit n != 8 }' sc.csv
check "eval --scan: coloured PLYs of H" \
  grep -q "^property uchar red" <(ply_header scx/s.focal-default-no-normals.ply)
run eval --scan no-such-mesh.off
check "eval --scan: a missing mesh is exit 2" test "$rc" -eq 2
run eval --scan s.ply --seed 3
check "eval --scan with --seed is a usage error" test "$rc" -eq 1

# ---------------------------------------------------------------------------------------------
# render: a PNG picture of a field (OpenGL on a headless EGL context; Mesa llvmpipe without a GPU)

# png_size FILE: "WIDTH HEIGHT" from the IHDR chunk (big-endian 32-bit at bytes 16 and 20),
# after checking the 8-byte PNG signature and that IHDR is the first chunk.
png_size() {
  local bytes
  bytes=$(od -An -tu1 -N24 "$1" 2>/dev/null | tr -s ' \n' ' ') || return 0
  awk -v b="$bytes" 'BEGIN {
    n = split(b, x, " ")
    if (n < 24 || x[1] != 137 || x[2] != 80 || x[3] != 78 || x[4] != 71) exit
    if (x[13] != 73 || x[14] != 72 || x[15] != 68 || x[16] != 82) exit  # "IHDR"
    printf "%d %d\n", ((x[17] * 256 + x[18]) * 256 + x[19]) * 256 + x[20],
                       ((x[21] * 256 + x[22]) * 256 + x[23]) * 256 + x[24]
  }'
}
run render s.ply -o r.png --size 320x240
check "render: exit 0" test "$rc" -eq 0
check "render: a PNG of the requested size 320x240" test "$(png_size r.png)" = "320 240"
check "render: says what it wrote" grep -q "^wrote r.png (320 x 240)" "$OUT"
run render s.ply -o rc.png --field class --directions d1 --focal-meshes --camera 30,20 --size 300x100 --orthographic
check "render --field class --directions d1 --focal-meshes: exit 0" test "$rc" -eq 0
check "render: --size 300x100 gives a 300 x 100 PNG" test "$(png_size rc.png)" = "300 100"
run render s.ply -o rr.png --field k2 --range -2,2 --size 64x64
check "render --range -2,2 --size 64x64 (the smallest): exit 0" test "$(png_size rr.png)" = "64 64"
expect_error "render --field bad: exit 1" 1 "--field" rb.png render s.ply -o rb.png --field curvedness
expect_error "render --size 10x10 (too small): exit 1" 1 "--size" rb.png render s.ply -o rb.png --size 10x10
expect_error "render --size 300 (no height): exit 1" 1 "--size" rb.png render s.ply -o rb.png --size 300
expect_error "render --camera 30 (no elevation): exit 1" 1 "--camera" rb.png render s.ply -o rb.png --camera 30
expect_error "render --range 2,1 (LO > HI): exit 1" 1 "--range" rb.png render s.ply -o rb.png --range 2,1
expect_error "render --range with --field class: exit 1" 1 "--range" rb.png render s.ply -o rb.png --field class --range -1,1
expect_error "render -o r.jpg (not PNG): exit 1" 1 "r.jpg" r.jpg render s.ply -o r.jpg
expect_error "render of a missing input: exit 2" 2 "missing.ply" rb.png render missing.ply -o rb.png
expect_error "render into a missing folder: exit 2, nothing written" 2 "rb.png" nofolder/rb.png render s.ply -o nofolder/rb.png
check "render: no temporary files left behind" bash -c '! ls -A | grep -q "\.tmp-"'

# ---------------------------------------------------------------------------------------------
# Issue 13: STL is welded, bytes that are not a mesh are errors, inputs must be regular files,
# focal-mesh writes both files or neither.
run generate sphere -o so.obj --vertices 500
# The OBJ sphere as ascii STL (facet corners written out, nothing shared); the numbers are the
# OBJ's shortest round-trip text, so welding by exact equality recovers the vertices.
awk '$1 == "v" { v[++n] = $2 " " $3 " " $4 }
     $1 == "f" { split($2, a, "/"); split($3, b, "/"); split($4, c, "/")
                 printf "facet normal 0 0 0\nouter loop\nvertex %s\nvertex %s\nvertex %s\nendloop\nendfacet\n", v[a[1]], v[b[1]], v[c[1]] }
     BEGIN { print "solid s" } END { print "endsolid s" }' so.obj >so.stl
SO_NV=$(grep -c '^v ' so.obj || true)
run curvature so.stl -o so-stl.csv
check "STL sphere: exit 0" test "$rc" -eq 0
check "STL sphere: one row per welded vertex ($SO_NV)" test "$(data_rows so-stl.csv)" -eq "$SO_NV"
# 500 vertices, normals from the positions: measured max |k - 1| about 0.02; 0.1 bounds it.
check_within "STL sphere: k1, k2 = 1 within 0.1 (not 0)" "$(max_dev so-stl.csv "1 2" 1)" 0.1
run info so.stl
check "info on STL: the welded vertex count and the corners" \
  bash -c 'grep -q "^vertices: *$1\$" "$2" && grep -q "^STL corners: *$3 " "$2"' _ "$SO_NV" "$OUT" "$(( 3 * $(grep -c '^f ' so.obj) ))"
run curvature so.stl -o so-apart.csv --no-weld
check "STL --no-weld: every row undefined, none flat" \
  bash -c '[[ $1 -eq 0 && $3 == "undefined=$2 " ]]' _ "$rc" "$(( 3 * $(grep -c '^f ' so.obj) ))" "$(classes so-apart.csv)"
run curvature so.stl -o so-tol.csv --weld-tolerance 1e-9
check "STL --weld-tolerance 1e-9: the same vertices" test "$(data_rows so-tol.csv)" -eq "$SO_NV"
expect_error "--no-weld with --weld-tolerance: exit 1" 1 "--weld" so-x.csv curvature so.stl -o so-x.csv --no-weld --weld-tolerance 1e-9
expect_error "--weld-tolerance -1: exit 1" 1 "--weld-tolerance" so-x.csv curvature so.stl -o so-x.csv --weld-tolerance -1
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >lone.obj
run curvature lone.obj -o lone.csv
check "a lone triangle without normals: undefined, not flat" \
  bash -c '[[ $1 -eq 0 && $2 == "undefined=3 " ]]' _ "$rc" "$(classes lone.csv)"
run curvature lone.obj -o lone-p.csv --paper
check "a lone triangle without normals, --paper: undefined" test "$(classes lone-p.csv)" = "undefined=3 "

head -c 3000 /dev/urandom >random.obj
printf 'hello\nworld\n' >words.obj
printf 'v 0 0 0\n\0\0\0' >nul.obj
printf '\177ELF\2\1\1\0' >elf.obj
printf '\211PNG\r\n\032\n' >png.obj
printf '<!DOCTYPE html>\n<html></html>\n' >page.obj
cp s.ply renamed_ply.obj
printf '\377\376v\0 \0001\0' >utf16.obj
for f in random words nul elf png page renamed_ply utf16; do
  expect_error "OBJ that is not OBJ ($f): exit 2" 2 "$f.obj" "fm-$f.focal1.ply" focal-mesh "$f.obj" -o "fm-$f"
done
check "OBJ that is not OBJ: no focal2 either" bash -c '! ls fm-*.focal2.ply 2>/dev/null'
expect_error "curvature of an empty OBJ mesh: exit 2" 2 "no vertices" w.csv curvature words.obj -o w.csv
printf 'ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n' >nov.ply
expect_error "PLY with 0 vertices: exit 2, no empty output" 2 "no vertices" nov.csv curvature nov.ply -o nov.csv

mkfifo fifo.obj
# A FIFO nobody writes to: an error at once, not a wait (timeout guards the test).
rc=0; timeout 10 "$FOCAL" info fifo.obj >"$OUT" 2>"$ERR" || rc=$?
check "FIFO input: exit 2 at once, named" bash -c '[[ $1 -eq 2 ]] && grep -q "^Error: fifo.obj.*FIFO" "$2"' _ "$rc" "$ERR"
ln -s /dev/zero zero.ply
rc=0; timeout 10 "$FOCAL" curvature zero.ply -o zero.csv >"$OUT" 2>"$ERR" || rc=$?
check "/dev/zero input: exit 2, not read until memory runs out" \
  bash -c '[[ $1 -eq 2 ]] && grep -q "^Error: zero.ply.*character device" "$2" && [[ ! -e zero.csv ]]' _ "$rc" "$ERR"

printf 'old\n' >fm.focal1.ply
mkdir -p fm.focal2.ply
run focal-mesh s.ply -o fm
check "focal-mesh whose 2nd file fails: exit 2, the existing 1st file untouched" \
  bash -c '[[ $1 -eq 2 && $(cat fm.focal1.ply) == old ]]' _ "$rc"
check "focal-mesh: no temporary or backup files left behind" bash -c '! ls -A | grep -q "\.tmp-"'

# Output paths (issue 13 item 6): never the input, a read-only file only with --force, a link
# written through to its file.
cp s.ply in6.ply
expect_error "curvature -o the input file: exit 1" 1 "is the input file" in6-x.csv curvature in6.ply -o in6.ply
check "... and the input is untouched" cmp -s s.ply in6.ply
ln -s in6.ply in6-link.ply
expect_error "curvature -o a link to the input: exit 1" 1 "is the input file" in6-x.csv curvature in6-link.ply -o in6.ply
check "... and the input is still untouched" cmp -s s.ply in6.ply
printf 'old\n' >ro.csv
chmod a-w ro.csv
run curvature s.ply -o ro.csv
check "a read-only output is refused: exit 1, kept" bash -c '[[ $1 -eq 1 && $(cat ro.csv) == old ]] && grep -q "^Error: .*read-only.*--force" "$2"' _ "$rc" "$ERR"
run curvature s.ply -o ro.csv --force
check "--force replaces a read-only output" bash -c '[[ $1 -eq 0 && $(head -1 ro.csv) == k1,* ]]' _ "$rc"
printf 'old\n' >ro.focal2.ply
chmod a-w ro.focal2.ply
expect_error "focal-mesh with a read-only 2nd output: exit 1, nothing written" 1 "read-only" ro.focal1.ply focal-mesh s.ply -o ro
printf 'old\n' >target.csv
ln -s target.csv link.csv
run curvature s.ply -o link.csv
check "an output that is a link is written through: the link stays, its file is replaced" \
  bash -c '[[ $1 -eq 0 && -L link.csv && $(head -1 target.csv) == k1,* ]]' _ "$rc"
ln -s missing-target.csv dangling.csv
expect_error "an output that is a link to nothing: exit 2" 2 "dangling.csv" missing-target.csv curvature s.ply -o dangling.csv

# Issue 13 items 3 and 8: high valence, messages.
awk 'BEGIN { n = 3000; for (i = 0; i < n; i++) { t = 6.283185307179586 * i / n
  printf "v %.17g %.17g %.17g\n", cos(t), sin(t), 0.1 * sin(3 * t) }
  printf "f"; for (i = 1; i <= n; i++) printf " %d", i; print "" }' >polygon3000.obj
run curvature polygon3000.obj -o polygon3000.csv
check "a 3000-corner polygon: exit 0, one row per vertex" \
  bash -c '[[ $1 -eq 0 && $(awk "END { print NR - 1 }" polygon3000.csv) -eq 3000 ]]' _ "$rc"
check "... and a warning naming the file and all 3000 crowded vertices" \
  grep -q "^Warning: polygon3000.obj: 3000 vertices have more than 1024 vertices within 2 rings" "$ERR"
run curvature polygon3000.obj -o polygon3000-2.csv --paper --rings 2
check "--paper --rings 2 on it: every vertex undefined, said so" \
  bash -c '[[ $1 -eq 0 && $(grep -c ",undefined$" polygon3000-2.csv) -eq 3000 ]] &&
    grep -q "^Warning: polygon3000.obj: 3000 vertices .*left undefined" "$2"' _ "$rc" "$ERR"
awk 'BEGIN { n = 2000; print "v 0 0 0"; print "v 1 0 0"
  for (i = 0; i < n; i++) { t = 6.283185307179586 * i / n; printf "v 0.5 %.17g %.17g\n", cos(t), sin(t) }
  for (i = 0; i < n; i++) printf "f 1 2 %d\n", i + 3 }' >fin2000.obj
run curvature fin2000.obj -o fin2000.csv
check "an edge shared by 2000 faces: exit 0, all 2002 vertices crowded, warned by name" \
  bash -c '[[ $1 -eq 0 && $(awk "END { print NR - 1 }" fin2000.csv) -eq 2002 ]] &&
    grep -q "^Warning: fin2000.obj: 2002 vertices have more than 1024 vertices within 2 rings" "$2"' _ "$rc" "$ERR"
printf 'v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\nf 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n' >octahedron.obj
run -v curvature octahedron.obj -o octahedron.csv
check "an octahedron (every vertex undefined): a warning, and -v says the empty H range in words" \
  bash -c '[[ $1 -eq 0 ]] && grep -q "^Warning: octahedron.obj: every vertex is undefined (6)" "$2" &&
    grep -q "H range: none" "$2" && ! grep -q "inf, -inf" "$2"' _ "$rc" "$ERR"
# (no such file: the error names it)
run info "$(printf 'new\nline.obj')"
check "a newline in a file name does not split the Error: line" \
  bash -c '[[ $1 -eq 2 && $(wc -l <"$2") -eq 1 ]] && grep -qF "Error: new\nline.obj: " "$2"' _ "$rc" "$ERR"
printf 'v 0 0 0\nv 1 0 1e-400\nv 0 1 1.#QNAN\nf 1 2 3\n' >msvc.obj
expect_error "OBJ 1.#QNAN: an error naming line and token" 2 "msvc.obj: line 3: '1.#QNAN' is not a number" msvc.csv curvature msvc.obj -o msvc.csv

echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
