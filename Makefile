# tresca-cr: `make verify` (the verification suite) and `make test` (the tests). Both install what they
# need, idempotently: Debian packages (HDF5, pkg-config), the Rust release build, and a Python 3.12 venv
# with the pinned versions of requirements.txt.

SHELL := /bin/bash
VENV  := .venv
PY    := $(VENV)/bin/python
BIN   := target/release/tresca-cr
# Python 3.12: pyenv's build first (its shim only works when 3.12 is selected), then a system one.
PY312 := $(shell for p in $$(pyenv root 2>/dev/null)/versions/3.12*/bin/python3.12 /usr/local/bin/python3.12 /usr/bin/python3.12; do \
           [ -x "$$p" ] && "$$p" -c 'import sys' 2>/dev/null && echo "$$p" && break; done)

.PHONY: all deps paraview build venv test verify bench clean-out

all: build

# Debian packages: HDF5 headers for the hdf5-metno crate (apt needs an index update on a fresh machine).
deps:
	@if ! pkg-config --exists hdf5 2>/dev/null; then \
	  echo "installing libhdf5-dev pkg-config"; \
	  (apt-get update -qq && apt-get install -y -qq libhdf5-dev pkg-config) >/dev/null || \
	  (sudo apt-get update -qq && sudo apt-get install -y -qq libhdf5-dev pkg-config) >/dev/null; \
	fi

# Debian's ParaView 5.11 (pvpython) and a virtual X server, for verification/paraview_check.py (make verify).
paraview:
	@if ! command -v pvpython >/dev/null 2>&1 || ! command -v xvfb-run >/dev/null 2>&1; then \
	  echo "installing paraview python3-paraview xvfb xauth"; \
	  (apt-get update -qq && apt-get install -y -qq --no-install-recommends paraview python3-paraview xvfb xauth) >/dev/null || \
	  (sudo apt-get update -qq && sudo apt-get install -y -qq --no-install-recommends paraview python3-paraview xvfb xauth) >/dev/null; \
	fi

build: deps
	cargo build --release --locked

$(VENV)/.stamp: requirements.txt
	@test -n "$(PY312)" || { echo "error: Python 3.12 not found (pyenv install 3.12.1)"; exit 1; }
	$(PY312) -m venv $(VENV)
	$(VENV)/bin/pip install -q --upgrade pip
	$(VENV)/bin/pip install -q -r requirements.txt
	touch $@

venv: $(VENV)/.stamp

test: build venv
	cargo test --release --locked
	$(PY) verification/python_tests.py

verify: build venv paraview
	$(PY) verification/run_all.py

bench: build venv
	$(PY) verification/bench.py
