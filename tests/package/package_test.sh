#!/usr/bin/env bash
# Installs a focal build tree into a scratch prefix, then configures, builds and runs the consumer
# project next to this script against that prefix: find_package(focal) and focal::focal must work
# from the installed files alone.
#
# Usage: package_test.sh CMAKE BUILD_DIR SCRATCH_DIR [CXX_COMPILER]
set -euo pipefail

if [[ $# -lt 3 || $# -gt 4 ]]; then
  echo "usage: $0 CMAKE BUILD_DIR SCRATCH_DIR [CXX_COMPILER]" >&2
  exit 2
fi
cmake=$1
build_dir=$2
scratch=$3
cxx=${4:-}
here=$(cd "$(dirname "$0")" && pwd)

[[ -n $scratch && $scratch != / ]] || { echo "refusing to use '$scratch' as scratch folder" >&2; exit 2; }
rm -rf "$scratch"
mkdir -p "$scratch"
prefix=$scratch/prefix

echo "== cmake --install $build_dir --prefix $prefix"
"$cmake" --install "$build_dir" --prefix "$prefix" >"$scratch/install.log"
config=$(find "$prefix" -name focalConfig.cmake -print -quit)
[[ -n $config ]] || { echo "focalConfig.cmake was not installed" >&2; exit 1; }
config_dir=$(dirname "$config")
for f in "$prefix/include/focal/focal.h" "$config_dir/focalConfigVersion.cmake" "$config_dir/focalTargets.cmake"; do
  [[ -f $f ]] || { echo "not installed: $f" >&2; exit 1; }
done
echo "   $config"

echo "== configure the consumer against $prefix"
# Only the scratch prefix (and the system) may provide focal: the build tree must not leak in.
"$cmake" -S "$here" -B "$scratch/consumer" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" -DFOCAL_EXPECTED_PREFIX="$prefix" \
  -DCMAKE_FIND_PACKAGE_NO_PACKAGE_REGISTRY=ON \
  ${cxx:+-DCMAKE_CXX_COMPILER="$cxx"}

echo "== build the consumer"
"$cmake" --build "$scratch/consumer"

echo "== run the consumer"
"$scratch/consumer/focal_package_test"

if [[ -x $prefix/bin/focal ]]; then
  echo "== the installed focal command"
  "$prefix/bin/focal" --version
fi
