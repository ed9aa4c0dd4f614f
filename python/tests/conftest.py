"""Shared fixtures of the Python tests: paths, the Rust binary, and solver runs cached per session (each
solver runs each scene once; the tests that compare or inspect its results share the file)."""
import os
import subprocess
import sys

import pytest

from tresca_py.common import BIN, CASES, MPIRUN, ROOT

PY = sys.executable
SCRIPTS = os.path.join(ROOT, "scripts")


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_auto_num_workers(config):
    """`-n auto` (pytest-xdist, `make test`): one worker per CPU this process may run on (its affinity, as
    `taskset` or a container's cpuset sets it), not the machine's count that xdist takes from psutil.
    PYTEST_XDIST_AUTO_NUM_WORKERS, when set, still wins (None hands over to xdist's own hook)."""
    if os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS"):
        return None
    return len(os.sched_getaffinity(0))


def run(cmd, **kw):
    """Run a command from the repository root; returns the CompletedProcess (text, captured)."""
    return subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, **kw)


@pytest.fixture(scope="session")
def rust_bin():
    """The release binary (make test builds it first); its absence is a failure, not a skip."""
    assert os.path.exists(BIN), f"{BIN} missing: cargo build --release"
    return BIN


@pytest.fixture(scope="session")
def scenes(tmp_path_factory):
    """Scene files by name: the generated manufactured scenes (tresca_py.mms), Example 5.1 on the paper's
    n = 8 mesh, and verification/cases/{cyclic,trapezoid}.toml."""
    from generated_scenes import generated_scenes
    d = tmp_path_factory.mktemp("scenes")
    paths = {}
    for name, text in generated_scenes().items():
        paths[name] = str(d / f"{name}.toml")
        with open(paths[name], "w") as fh:
            fh.write(text)
    with open(os.path.join(CASES, "paper_example_5_1.toml")) as fh:
        ex51 = fh.read()
    assert "cells = [2, 2]" in ex51, "paper_example_5_1.toml changed: update this fixture"
    paths["example51"] = str(d / "example51.toml")
    with open(paths["example51"], "w") as fh:
        fh.write(ex51.replace("cells = [2, 2]", "cells = [8, 8]"))
    for name in ("cyclic", "trapezoid"):
        paths[name] = os.path.join(CASES, f"{name}.toml")
    return paths


@pytest.fixture(scope="session")
def solve(tmp_path_factory, scenes, rust_bin):
    """solve(solver, scene_name, mpi=0) -> results file; solver in skfem | dolfinx | rust; cached."""
    out_dir = tmp_path_factory.mktemp("results")
    done = {}

    def _solve(solver, name, mpi=0):
        key = (solver, name, mpi)
        if key not in done:
            out = str(out_dir / f"{name}_{solver}{'_np' + str(mpi) if mpi else ''}.h5")
            if solver == "rust":
                cmd = [rust_bin, "run", scenes[name], "-o", out, "-q", "--force"]
            else:
                cmd = ([MPIRUN, "-n", str(mpi)] if mpi else []) + \
                    [PY, os.path.join(SCRIPTS, f"{solver}_solve.py"), scenes[name], "-o", out, "-q"]
            p = run(cmd)
            assert p.returncode == 0, f"{' '.join(cmd)} failed:\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}"
            done[key] = out
        return done[key]
    return _solve
