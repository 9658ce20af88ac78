# The helpers of the focal command's shell tests (cloud_cli_test.sh, robust_cli_test.sh,
# smooth_cli_test.sh), sourced with the test's arguments FOCAL_BINARY SCRATCH_DIR: the binary as
# an absolute path in $FOCAL, the scratch folder emptied and made the working directory, check
# NAME COMMAND... (one line per check, counted in $passed / $failed), run ARGS... (focal's stdout
# in $OUT, stderr in $ERR, exit status in $rc).
# shellcheck shell=bash disable=SC2034
set -euo pipefail
[[ $# -eq 2 ]] || { echo "usage: $0 FOCAL_BINARY SCRATCH_DIR" >&2; exit 2; }
FOCAL=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
SCRATCH=$2
[[ -n $SCRATCH && $SCRATCH != / ]] || { echo "refusing to use '$SCRATCH'" >&2; exit 2; }
rm -rf "$SCRATCH" && mkdir -p "$SCRATCH" && cd "$SCRATCH"
OUT=$PWD/.stdout
ERR=$PWD/.stderr
passed=0
failed=0
check() {
  local name=$1
  shift
  if "$@"; then printf 'ok    %s\n' "$name"; passed=$((passed + 1)); else
    printf 'FAIL  %s -- %s\n' "$name" "$(head -c 300 "$ERR")"; failed=$((failed + 1)); fi
}
rc=0
run() { rc=0; "$FOCAL" "$@" >"$OUT" 2>"$ERR" || rc=$?; }
