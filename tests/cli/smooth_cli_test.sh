#!/usr/bin/env bash
# Tests of `focal smooth`: a noisy sphere (mesh and cloud) smoothed towards radius 1, rows and
# faces kept, --normals, a clean sphere left as it is, and the error contract.
#
# Usage: smooth_cli_test.sh FOCAL_BINARY SCRATCH_DIR. Prints one line per check, then
# "N passed, M failed"; exits 1 when any check failed. The helpers are harness.sh's.
# shellcheck disable=SC2016
# shellcheck source=harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"
below() { awk -v x="$1" -v b="$2" 'BEGIN { exit !(x ~ /^[-+0-9.eE]+$/ && x + 0 <= b + 0) }'; }
# rms_radius FILE: RMS of |p| - 1 over the vertex lines of an ascii OFF file (after the counts).
rms_radius() {
  awk 'NR == 2 { n = $1 } NR > 2 && NR <= n + 2 { r = sqrt($1 * $1 + $2 * $2 + $3 * $3) - 1;
    s += r * r; m++ } END { if (m == 0) print "bad"; else printf "%.6g\n", sqrt(s / m) }' "$1"
}
# rms_radius_xyz FILE: the same over the lines of an .xyz file.
rms_radius_xyz() {
  awk '{ r = sqrt($1 * $1 + $2 * $2 + $3 * $3) - 1; s += r * r; m++ }
    END { if (m == 0) print "bad"; else printf "%.6g\n", sqrt(s / m) }' "$1"
}

run generate sphere --triangulation irregular --vertices 3000 --position-noise 0.3 --seed 2 \
  --no-normals -o noisy.off
check "generate a noisy sphere" test "$rc" -eq 0
run smooth noisy.off -o smooth.off
check "smooth: exit 0, nothing on stderr" bash -c '[[ $1 -eq 0 && ! -s $2 ]]' _ "$rc" "$ERR"
before=$(rms_radius noisy.off)
after=$(rms_radius smooth.off)
# Measured (library test, seeds 1-3): the RMS radial error falls to 0.2-0.3 of the input's.
check "smoothed sphere: RMS |r - 1| at most 0.5 x the noisy input's ($before -> $after)" \
  below "$after" "$(awk -v b="$before" 'BEGIN { print 0.5 * b }')"
check "smooth keeps the vertex and face counts" bash -c 'diff <(sed -n 2p noisy.off) <(sed -n 2p smooth.off)'
check "smooth keeps the faces" bash -c 'diff <(tail -n +3 noisy.off | awk "NF == 4") <(tail -n +3 smooth.off | awk "NF == 4")'
run smooth noisy.off -o smooth.ply --normals --iterations 2
check "--normals --iterations 2: PLY with normals" bash -c '[[ $1 -eq 0 ]] && grep -aq "property double nx" smooth.ply' _ "$rc"

run generate sphere --triangulation irregular --vertices 3000 --no-normals -o clean.off
run smooth clean.off -o clean-smooth.off
check "a clean sphere is written as it was read" bash -c '[[ $1 -eq 0 ]] && cmp -s clean.off clean-smooth.off' _ "$rc"

run generate sphere --cloud --vertices 3000 --position-noise 0.5 --no-normals -o cloud.xyz
run smooth cloud.xyz -o cloud-smooth.xyz
check "smooth a cloud: exit 0, one row per point" \
  bash -c '[[ $1 -eq 0 && $(wc -l <cloud.xyz) -eq $(wc -l <cloud-smooth.xyz) ]]' _ "$rc"
before=$(rms_radius_xyz cloud.xyz)
after=$(rms_radius_xyz cloud-smooth.xyz)
check "smoothed cloud: RMS |r - 1| at most 0.3 x the input's ($before -> $after)" \
  below "$after" "$(awk -v b="$before" 'BEGIN { print 0.3 * b }')"

run smooth cloud.xyz -o x.xyz --rings 2
check "--rings on a cloud: exit 2, says use --k" bash -c '[[ $1 -eq 2 ]] && grep -q "^Error: .*--k" "$2"' _ "$rc" "$ERR"
run smooth noisy.off -o x.off --k 16
check "--k on a mesh: exit 2" test "$rc" -eq 2
run smooth missing.off -o x.off
check "missing input: exit 2, Error: line" bash -c '[[ $1 -eq 2 ]] && grep -q "^Error: " "$2"' _ "$rc" "$ERR"
run smooth noisy.off -o x.csv
check "-o .csv: exit 1 (not a mesh format)" test "$rc" -eq 1
run smooth noisy.off -o noisy.off
check "-o the input: exit 1" test "$rc" -eq 1

printf '%d passed, %d failed\n' "$passed" "$failed"
[[ $failed -eq 0 ]]
