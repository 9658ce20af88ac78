#!/usr/bin/env bash
# Builds the point-cloud peers of docs/POINTS.md into build/points/: cgal_peer (CGAL 5.5
# Monge_via_jet_fitting, Debian libcgal-dev, header-only with GMP/MPFR) and pcl_peer (PCL 1.13,
# Debian libpcl-dev). Neither is a dependency of focal. `scripts/install-deps.sh bench` installs
# both packages.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=${1:-build/points}
mkdir -p "$out"
g++ -std=c++17 -O2 -DNDEBUG -DCGAL_EIGEN3_ENABLED -I/usr/include/eigen3 "$here/cgal_peer.cpp" \
  -o "$out/cgal_peer" -lgmp -lmpfr
# shellcheck disable=SC2046
g++ -std=c++17 -O2 -DNDEBUG $(pkg-config --cflags pcl_features) "$here/pcl_peer.cpp" \
  -o "$out/pcl_peer" $(pkg-config --libs pcl_features) -lpcl_search -lpcl_kdtree -lpcl_common
echo "built $out/cgal_peer and $out/pcl_peer"
