#!/usr/bin/env bash
# focal from Python against the peers' Python APIs (bench/python/bench.py), and the pyvista and
# Open3D interop recipes of docs/PYTHON.md (too large for the test venv; a failing recipe fails
# this script). Uses bench/peers/.venv (bench/peers/setup.sh) plus trueform and open3d, and the
# extension of a build with FOCAL_BUILD_PYTHON (make build: build/release).
#   bash bench/python/run.sh [BUILD_DIR]        about 20 minutes on 2 shared cores
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${1:-build/release}
py=bench/peers/.venv/bin/python
[[ -x $py ]] || bash bench/peers/setup.sh
# Pinned like bench/peers/requirements.txt: the numbers in docs/PYTHON.md are of these versions.
$py -m pip install --quiet -r bench/python/requirements.txt
export PYTHONPATH=$PWD/$build/python
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cgal_data=/usr/share/doc/libcgal-dev/data.tar.gz
meshes=()
if [[ -f $cgal_data ]]; then
  tar -xzf "$cgal_data" -O data/meshes/bunny00.off >"$work/bunny00.off"
  meshes+=("$work/bunny00.off")
else
  echo "no $cgal_data (Debian package libcgal-demo): the bunny is skipped" >&2
fi

echo "## Interop recipes run here (pyvista, open3d)"
(cd python/tests && $py -c "
import pathlib, tempfile, interop_recipes
for name in ('pyvista', 'open3d'):
    with tempfile.TemporaryDirectory() as d:
        interop_recipes.run(name, pathlib.Path(d))
        print('recipe', name, 'ran and matched focal on the same arrays')
")
echo
echo "## Overhead"
$py bench/python/bench.py overhead
echo
echo "## Accuracy"
$py bench/python/bench.py accuracy
echo
echo "## Timing"
# Above 200K vertices the peers that take many minutes there are left out.
$py bench/python/bench.py timing "${meshes[@]}" torus:1e5 torus:1e6 --skip-large \
  "trimesh ball measures / pi r^2" "pymeshlab APSS" "pymeshlab normal cycles"
