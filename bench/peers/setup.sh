#!/usr/bin/env bash
# Creates bench/peers/.venv with the pinned peers of requirements.txt (from PyPI, needs network
# once; about 400 MB). Python 3.11 was used for the numbers in docs/ACCURACY.md.
#   bench/peers/setup.sh [python3]
set -euo pipefail
cd "$(dirname "$0")"
python=${1:-python3}
"$python" -m venv .venv
.venv/bin/pip install --quiet --upgrade pip
.venv/bin/pip install --quiet -r requirements.txt
.venv/bin/python -c "import igl, pymeshlab, trimesh, rtree, pyvista, vtk, numpy, matplotlib, trueform"
echo "peers installed in bench/peers/.venv:"
.venv/bin/pip freeze | grep -iE '^(libigl|pymeshlab|trimesh|rtree|scipy|pyvista|vtk|numpy|matplotlib|trueform)=='
