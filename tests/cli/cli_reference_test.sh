#!/usr/bin/env bash
# docs/CLI.md is what scripts/cli_reference.sh writes from this build's `focal` help, byte for
# byte. When an option or a help text changes, regenerate it:
#   bash scripts/cli_reference.sh build/release/cli/focal > docs/CLI.md
#
# Usage: cli_reference_test.sh FOCAL_BINARY SOURCE_DIR SCRATCH_DIR. Prints the difference and
# exits 1 when they differ.
set -euo pipefail
[[ $# -eq 3 ]] || { echo "usage: $0 FOCAL_BINARY SOURCE_DIR SCRATCH_DIR" >&2; exit 2; }
focal=$1
source_dir=$2
scratch=$3
[[ -n $scratch && $scratch != / ]] || { echo "refusing to use '$scratch'" >&2; exit 2; }
rm -rf "$scratch" && mkdir -p "$scratch"

bash "$source_dir/scripts/cli_reference.sh" "$focal" >"$scratch/CLI.md"
# The script's output must not depend on the run: a second run gives the same bytes.
bash "$source_dir/scripts/cli_reference.sh" "$focal" >"$scratch/CLI.again.md"
if ! cmp -s "$scratch/CLI.md" "$scratch/CLI.again.md"; then
  echo "FAIL: scripts/cli_reference.sh gives different output on two runs"
  diff "$scratch/CLI.md" "$scratch/CLI.again.md" | head -20
  exit 1
fi
if ! cmp -s "$scratch/CLI.md" "$source_dir/docs/CLI.md"; then
  echo "FAIL: docs/CLI.md is not the output of scripts/cli_reference.sh for this build; run"
  echo "  bash scripts/cli_reference.sh $focal > docs/CLI.md"
  diff -u "$source_dir/docs/CLI.md" "$scratch/CLI.md" | head -60
  exit 1
fi
echo "PASS: docs/CLI.md is the reference generated from focal -h"
