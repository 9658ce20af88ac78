# The two commands: `make test` and `make demo`. Each installs what is missing, configures and
# builds before it runs.
PRESET ?= release
BUILD_DIR := build/$(PRESET)
JOBS ?= $(shell nproc)
# WERROR=ON: compiler warnings are errors (CI); the same build folder, so `make demo` after
# `make test` with the same WERROR rebuilds nothing.
WERROR ?= OFF
# The Python environment of the bindings' build and tests (python/): nanobind, NumPy and pytest
# from PyPI in a venv, so that the extension is built in the same CMake build as the library (one
# library build) and the `python` ctest runs pytest on it. Users install with `pip install .`.
# The packages are listed in python/requirements-test.txt (a change there updates the venv).
VENV := build/venv
PYTHON := $(VENV)/bin/python

.PHONY: all deps deps-demo venv configure build test demo bench docs install clean format

all: build

deps:
	@bash scripts/install-deps.sh

deps-demo:
	@bash scripts/install-deps.sh demo

venv: $(VENV)/.ready

$(VENV)/.ready: python/requirements-test.txt | deps
	@python3 -m venv $(VENV)
	@$(PYTHON) -m pip install -q --disable-pip-version-check -r python/requirements-test.txt
	@touch $@

configure: deps venv
	@cmake --preset $(PRESET) -DFOCAL_BUILD_PYTHON=ON -DPython_EXECUTABLE=$(CURDIR)/$(PYTHON) \
	  -DFOCAL_WERROR=$(WERROR) >/dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

test: build
	@ctest --test-dir $(BUILD_DIR) --output-on-failure -j $(JOBS)

demo: deps-demo build
	@bash scripts/demo.sh $(BUILD_DIR)/cli/focal

# Benchmarks (bench/, docs/PERFORMANCE.md): the stages with Google Benchmark, then whole runs
# of the focal command from 10K to 10M vertices, and the peers, then 1 vs 2 threads on a quiet
# and a loaded machine (bench/threads_under_load.sh, issue 20). About 25 minutes on 2 cores.
bench:
	@bash scripts/install-deps.sh bench
	@cmake --preset bench >/dev/null
	@cmake --build build/bench -j $(JOBS)
	@build/bench/bench/focal_kernels_bench --benchmark_repetitions=3 \
	  --benchmark_report_aggregates_only=true --benchmark_out=build/bench/kernels.json
	@bash bench/run_bench.sh build/bench | tee build/bench/whole-runs.md
	@bash bench/threads_under_load.sh build/bench | tee build/bench/threads-under-load.md

# The API reference from the headers (Doxyfile: include/focal, warnings on stderr), in
# build/docs/html. Needs no build of the library.
docs:
	@bash scripts/install-deps.sh docs
	@mkdir -p build/docs
	@doxygen Doxyfile

install: build
	@cmake --install $(BUILD_DIR) --prefix $(or $(PREFIX),/usr/local)

format:
	@clang-format -i $$(git ls-files '*.h' '*.cpp' '*.cu')

clean:
	@rm -rf build
