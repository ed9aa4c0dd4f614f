"""T1: the study-sized tests that ``make test`` leaves out, run by ``make verify`` (README, Quick start).

Rust: the tests marked ``#[ignore = "study-sized …"]``, in the test binaries :func:`rust_binaries` finds
them in (the other ignored tests, timings that print and check nothing, stay out). Python: the tests marked
``study`` (python/pyproject.toml), which ``make test`` deselects with ``-m "not study"``.
"""
import os
import re
import subprocess

from tresca_py.common import PY, ROOT, cmdline
from tresca_py.verify.studytools import req

STUDY = '#[ignore = "study-sized'
#: a bare ``#[ignore]`` or one whose reason is not study-sized
OTHER_IGNORE = re.compile(r'#\[ignore(\]| = "(?!study-sized))')


def binary_of(rel):
    """The cargo test binary a file under tests/ belongs to: tests/NAME.rs and every file of tests/NAME/
    (a tests/NAME/main.rs binary, or the modules of tests/NAME.rs); None for tests/common/."""
    parts = rel.split("/")
    name = parts[1][:-3] if len(parts) == 2 else parts[1]
    return None if name == "common" else name


def rust_binaries(root=ROOT):
    """The test binaries holding study-sized tests, sorted. A binary that holds them and also other ignored
    tests is an error: ``--ignored`` would run those too."""
    files = {}
    for d, _, names in os.walk(os.path.join(root, "tests")):
        for n in names:
            if n.endswith(".rs"):
                rel = os.path.relpath(os.path.join(d, n), root).replace(os.sep, "/")
                with open(os.path.join(root, rel), encoding="utf-8") as f:
                    files.setdefault(binary_of(rel), []).append(f.read())
    study = sorted(b for b, texts in files.items() if b and any(STUDY in t for t in texts))
    for b in study:
        if any(OTHER_IGNORE.search(t) for t in files[b]):
            raise ValueError(f"test binary {b} holds study-sized and other ignored tests: `--ignored` would run both")
    return study


def tail(p, n=600):
    return (p.stdout + p.stderr).strip()[-n:]


def run(hs):
    """Record T1-rust and T1-python."""
    for name in rust_binaries():
        cmd = ["cargo", "test", "--release", "--locked", "--test", name, "--", "--ignored"]
        p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
        print(p.stdout[-3000:])
        summary = [ln for ln in p.stdout.splitlines() if ln.startswith("test result")]
        req(hs, f"T1-study-tests-rust-{name}", f"The study-sized Rust tests of the test binary `{name}` shall pass",
            p.returncode == 0 and bool(summary), summary[-1] if summary else tail(p), cmdline(cmd), "—")
    cmd = [PY, "-m", "pytest", "python/tests", "-q", "-m", "study", "-p", "no:cacheprovider"]
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    print(p.stdout[-3000:])
    last = (p.stdout.strip().splitlines() or ["(no output)"])[-1]
    req(hs, "T1-study-tests-python", "The Python tests marked `study` shall pass", p.returncode == 0, last,
        cmdline(cmd), "—")
