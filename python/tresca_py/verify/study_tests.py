"""T1: the study-sized tests that ``make test`` leaves out, run by ``make verify`` (README, Quick start).

Rust: the tests marked ``#[ignore = "study-sized …"]`` in the test binaries of :data:`RUST_BINARIES` (the
other ignored tests, timings that print and check nothing, stay out). Python: the tests marked ``study``
(python/pyproject.toml), which ``make test`` deselects with ``-m "not study"``.
"""
import subprocess

from tresca_py.common import PY, ROOT, cmdline
from tresca_py.verify.studytools import req

#: the integration-test binaries holding study-sized tests (``#[ignore = "study-sized …"]``)
RUST_BINARIES = ("expr_exactness",)


def tail(p, n=600):
    return (p.stdout + p.stderr).strip()[-n:]


def run(hs):
    """Record T1-rust and T1-python."""
    for name in RUST_BINARIES:
        cmd = ["cargo", "test", "--release", "--locked", "--test", name, "--", "--ignored"]
        p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
        print(p.stdout[-3000:])
        summary = [ln for ln in p.stdout.splitlines() if ln.startswith("test result")]
        req(hs, f"T1-study-tests-rust-{name}", f"The study-sized Rust tests of tests/{name}.rs shall pass",
            p.returncode == 0 and bool(summary), summary[-1] if summary else tail(p), cmdline(cmd), "—")
    cmd = [PY, "-m", "pytest", "python/tests", "-q", "-m", "study", "-p", "no:cacheprovider"]
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    print(p.stdout[-3000:])
    last = (p.stdout.strip().splitlines() or ["(no output)"])[-1]
    req(hs, "T1-study-tests-python", "The Python tests marked `study` shall pass", p.returncode == 0, last,
        cmdline(cmd), "—")
