# tresca-cr: `make verify` (the verification suite) and `make test` (the tests). Both install what they
# need, idempotently: CMake (for the static HDF5 build), the Rust release build, and a Python 3.12 venv
# with the pinned versions of requirements.txt.

SHELL := /bin/bash
VENV  := .venv
PY    := $(VENV)/bin/python
BIN   := target/release/tresca-cr
# Python 3.12: pyenv's build first (its shim only works when 3.12 is selected), then a system one.
PY312 := $(shell for p in $$(pyenv root 2>/dev/null)/versions/3.12*/bin/python3.12 /usr/local/bin/python3.12 /usr/bin/python3.12; do \
           [ -x "$$p" ] && "$$p" -c 'import sys' 2>/dev/null && echo "$$p" && break; done)

.PHONY: all deps paraview getfem build venv lint test verify reference bench bench-env bench-factorisation clean-out

all: build

# HDF5 is compiled from source and linked statically (Cargo.toml: hdf5-metno's `static` feature; Debian's
# shared libhdf5 pulled 37 libraries and cost ~8 ms of every process start). Its CMake project needs
# CMake >= 3.26 and Debian bookworm has 3.25, so a pinned CMake from PyPI goes into a small venv,
# .tools/, which .cargo/config.toml names to the `cmake` crate (CMAKE). The C compiler and make that
# it also needs come with the Rust toolchain's linker set-up (build-essential).
CMAKE_VERSION := 3.31.6
TOOLS := .tools
TOOLS_PY := $(or $(PY312),python3)

deps: $(TOOLS)/.cmake-$(CMAKE_VERSION)

$(TOOLS)/.cmake-$(CMAKE_VERSION):
	@echo "installing cmake $(CMAKE_VERSION) into $(TOOLS)"
	rm -rf $(TOOLS)
	$(TOOLS_PY) -m venv $(TOOLS)
	$(TOOLS)/bin/pip install -q cmake==$(CMAKE_VERSION)
	$(TOOLS)/bin/cmake --version >/dev/null
	touch $@

# Debian's ParaView 5.11 (pvpython) and a virtual X server, for verification/paraview_check.py (make verify).
paraview:
	@if ! command -v pvpython >/dev/null 2>&1 || ! command -v xvfb-run >/dev/null 2>&1; then \
	  echo "installing paraview python3-paraview xvfb xauth"; \
	  (apt-get update -qq && apt-get install -y -qq --no-install-recommends paraview python3-paraview xvfb xauth) >/dev/null || \
	  (sudo apt-get update -qq && sudo apt-get install -y -qq --no-install-recommends paraview python3-paraview xvfb xauth) >/dev/null; \
	fi

# Debian's GetFEM 5.4 (python3-getfem) for verification/external/run.py (make verify). It imports under the
# system interpreter /usr/bin/python3 only (the python3 on PATH may be pyenv's).
getfem:
	@if ! /usr/bin/python3 -c 'import getfem' >/dev/null 2>&1; then \
	  echo "installing python3-getfem"; \
	  (apt-get update -qq && apt-get install -y -qq --no-install-recommends python3-getfem) >/dev/null || \
	  (sudo apt-get update -qq && sudo apt-get install -y -qq --no-install-recommends python3-getfem) >/dev/null; \
	fi

build: deps
	cargo build --release --locked

$(VENV)/.stamp: requirements.txt python/pyproject.toml
	@test -n "$(PY312)" || { echo "error: Python 3.12 not found (pyenv install 3.12.1)"; exit 1; }
	$(PY312) -m venv $(VENV)
	$(VENV)/bin/pip install -q --upgrade pip
	$(VENV)/bin/pip install -q -r requirements.txt
	$(VENV)/bin/pip install -q --no-deps --no-build-isolation -e python
	touch $@

venv: $(VENV)/.stamp

# The lint half of `make test` (CI): formatting, clippy with warnings as errors, ruff on the Python
# (config python/pyproject.toml [tool.ruff]), every path and Rust name the documentation and comments name
# exists, and the crate's import graph has no circle and no upward import (scripts/import_graph.py).
lint: venv
	cargo fmt --check
	cargo clippy --release --all-targets --locked -- -D warnings
	$(VENV)/bin/ruff check --config python/pyproject.toml python scripts verification
	$(PY) verification/check_doc_paths.py
	$(PY) scripts/import_graph.py --check

# `make test` leaves the study-sized tests (Rust `#[ignore = "study-sized …"]`, pytest marker `study`) to
# `make verify` (requirement T1). clippy runs in the release profile (`--release`) so that it reuses the
# release build's build-script outputs (HDF5's CMake build) instead of building them again for `dev`.
# pytest runs on one worker per CPU of the process's affinity (pytest-xdist `-n auto`, the count from
# python/tests/conftest.py; PYTEST_JOBS=0 for one process, no workers), a test file's tests on one worker
# (`--dist loadfile`: its module-scoped runs are made once); `-ra` (pyproject.toml) still lists the failures.
PYTEST_JOBS ?= auto
test: build venv getfem
	$(MAKE) --no-print-directory lint
	cargo test --release --locked
	$(PY) -m pytest python/tests -q -m "not study" -n $(PYTEST_JOBS) --dist loadfile

# make verify writes under out/verify/ only (a clean clone stays clean); make reference publishes what it
# staged in out/verify/reference/ into the tracked reference/ and regenerates verification/README.md's table.
# The studies run on a pool of 2 worker processes (VERIFY_JOBS=N to change; run_all.py --jobs N).
VERIFY_JOBS ?= 2
verify: build venv paraview getfem
	$(PY) verification/run_all.py --jobs $(VERIFY_JOBS)

reference: venv
	$(PY) -m tresca_py.verify.harness publish

# Timings live here only (no pass/fail of make verify or make test depends on a time).
bench: build venv bench-env
	$(PY) verification/bench/report.py
	$(PY) verification/planner.py --costs
	$(PY) verification/bench/costmodel.py --write reference/performance.md
	$(PY) verification/bench/contact.py --write reference/performance.md
	$(MAKE) bench-factorisation

# The factorisation bench (issue 32): tresca-cr's set-up against CHOLMOD (scikit-sparse 0.4.16, built against
# Debian's libsuitesparse-dev: SuiteSparse 5.12; 0.5.0 does not build against it), MKL PARDISO (pypardiso)
# and MUMPS (petsc4py of the dolfinx wheel) on the same matrices. These live in a bench-only venv,
# .venv-bench, which `make test` and `make verify` never create.
BENCH_VENV := .venv-bench
BENCH_REQ  := verification/bench/requirements-bench.txt

$(BENCH_VENV)/.stamp: requirements.txt $(BENCH_REQ)
	@test -n "$(PY312)" || { echo "error: Python 3.12 not found (pyenv install 3.12.1)"; exit 1; }
	@test -f /usr/include/suitesparse/cholmod.h || \
	  (apt-get update -qq && apt-get install -y -qq -o DPkg::Lock::Timeout=600 libsuitesparse-dev) >/dev/null || \
	  (sudo apt-get update -qq && sudo apt-get install -y -qq -o DPkg::Lock::Timeout=600 libsuitesparse-dev) >/dev/null
	$(PY312) -m venv $(BENCH_VENV)
	$(BENCH_VENV)/bin/pip install -q --upgrade pip
	$(BENCH_VENV)/bin/pip install -q -r requirements.txt
	SUITESPARSE_INCLUDE_DIR=/usr/include/suitesparse $(BENCH_VENV)/bin/pip install -q -r $(BENCH_REQ)
	$(BENCH_VENV)/bin/pip install -q --no-deps --no-build-isolation -e python
	touch $@

bench-env: $(BENCH_VENV)/.stamp

# Only the factorisation section: exports Example 5.1's reduced stiffness (refine 6, 7, 8 by default) and
# sets it up with the four solvers, interleaved. FACTOR_REFINES="6 7" for a shorter run.
FACTOR_REFINES ?= 6 7 8
bench-factorisation: build bench-env
	cargo build --release --locked --example export_matrix
	$(BENCH_VENV)/bin/python verification/bench/factorisation.py --refine $(FACTOR_REFINES) --write reference/performance.md
