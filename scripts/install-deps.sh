#!/usr/bin/env bash
# Installs the Debian packages focal needs, only those missing; idempotent.
#   scripts/install-deps.sh          build and test dependencies
#   scripts/install-deps.sh demo     also the scanned meshes used by `make demo`
#   scripts/install-deps.sh bench    also Google Benchmark, GNU time and the bunny (`make bench`),
#                                    CGAL and PCL (point-cloud peers, bench/points/)
#   scripts/install-deps.sh fuzz     also clang with libFuzzer and its OpenMP (scripts/fuzz.sh)
#   scripts/install-deps.sh docs     also Doxygen and Graphviz (`make docs`: the API reference)
set -euo pipefail

# python3-venv and python3-dev: the venv of the Python bindings' build and tests (`make test`
# creates build/venv and installs nanobind, NumPy and pytest into it from PyPI) and the headers
# the extension compiles against.
# libnanoflann-dev: the header-only kd-tree of point-cloud neighbourhoods (src/points/).
# libegl-dev, libopengl-dev and Mesa (libegl-mesa0, libgl1-mesa-dri): headless OpenGL for
# rasterised G-buffers and `focal render`; libpng-dev writes its pictures.
packages=(cmake ninja-build g++ make pkg-config libeigen3-dev libcli11-dev libgtest-dev libgmock-dev
          libegl-dev libopengl-dev libegl-mesa0 libgl1-mesa-dri libpng-dev python3-venv python3-dev
          libnanoflann-dev)
if [[ "${1:-}" == "demo" ]]; then
  packages+=(libcgal-demo)
elif [[ "${1:-}" == "bench" ]]; then
  packages+=(libbenchmark-dev time libcgal-demo libcgal-dev libpcl-dev)
elif [[ "${1:-}" == "fuzz" ]]; then
  # libFuzzer and the sanitizer runtimes of clang are in libclang-rt-14-dev, which clang only
  # recommends; libomp-dev is clang's OpenMP (the library links it).
  packages+=(clang libclang-rt-14-dev libomp-dev)
elif [[ "${1:-}" == "docs" ]]; then
  # Doxygen reads include/focal (Doxyfile); Graphviz's dot draws its include graphs.
  packages+=(doxygen graphviz)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[[ ${#missing[@]} -eq 0 ]] && exit 0

echo "focal: installing Debian packages: ${missing[*]}"
sudo=""
[[ $(id -u) -ne 0 ]] && sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
# apt-get update once: only when the package lists are missing or older than a day.
if [[ -z "$(find /var/lib/apt/lists -maxdepth 1 -name '*Packages*' -mtime -1 2>/dev/null | head -1)" ]]; then
  $sudo apt-get update -qq
fi
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
