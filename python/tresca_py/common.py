"""Shared helpers of the verification scripts: paths, running the binary, observed orders, relative
differences. Each script imports what it needs from here (``from tresca_py.common import ...``); none defines its
own copy.

Observed orders: for errors e_i at sizes x_i (mesh size h or time step k) the successive order is
    p_i = log(e_{i-1}/e_i) / log(x_{i-1}/x_i),
and the fitted order is the least-squares slope of log e against log x (the Rust crate computes the same in
``src/study/orders.rs``).

Relative differences: ``rel_diff(a, b)`` is the max-norm difference relative to the larger max norm of the
two (symmetric; 0 for two zero vectors); ``rel_to(a, ref)`` is relative to the reference ``ref`` alone.
"""
import math
import os
import resource
import shlex
import subprocess
import sys
import time

import numpy as np

# python/tresca_py/common.py -> the repository root (the package is installed editable from python/)
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.path.join(ROOT, "target", "release", "tresca-cr")
PY = sys.executable
MPIRUN = os.path.join(os.path.dirname(PY), "mpirun")
REF = os.path.join(ROOT, "reference")
CASES = os.path.join(ROOT, "verification", "cases")
SCRIPTS = os.path.join(ROOT, "scripts")


def case(name):
    """Path of the scene ``verification/cases/NAME.toml``."""
    return os.path.join(CASES, f"{name}.toml")


def run(cmd, check=True, **kw):
    """Run ``cmd`` from the repository root, capturing text output; returns (CompletedProcess, seconds).
    With ``check`` a non-zero exit raises RuntimeError carrying the command and both outputs."""
    t = time.perf_counter()
    p = subprocess.run([str(c) for c in cmd], cwd=ROOT, capture_output=True, text=True, **kw)
    if check and p.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd))} failed ({p.returncode}):\n{p.stdout}\n{p.stderr}")
    return p, time.perf_counter() - t


def git_commit():
    """The repository's commit (a results file's ``git_commit`` attribute), "unknown" outside a clone."""
    try:
        out = subprocess.run(["git", "-C", os.path.dirname(os.path.abspath(__file__)), "rev-parse", "HEAD"],
                             capture_output=True, text=True, timeout=5)
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return out.stdout.strip() or "unknown"


def short_path(p):
    """``p`` relative to the repository root when it lies inside it (for printed commands)."""
    p = str(p)
    return os.path.relpath(p, ROOT) if os.path.isabs(p) and p.startswith(ROOT) else p


def cmdline(cmd):
    """A command as a copyable shell line, with paths inside the repository made relative."""
    return " ".join(shlex.quote(short_path(c)) for c in cmd)


def observed_order(e_a, e_b, x_a, x_b):
    """log(e_a/e_b) / log(x_a/x_b)."""
    return math.log(e_a / e_b) / math.log(x_a / x_b)


def orders(x, e):
    """(successive orders, least-squares fitted order) of errors e at sizes x."""
    succ = [observed_order(e[i - 1], e[i], x[i - 1], x[i]) for i in range(1, len(e))]
    lx, le = [math.log(v) for v in x], [math.log(v) for v in e]
    mx, me = sum(lx) / len(lx), sum(le) / len(le)
    fit = sum((a - mx) * (b - me) for a, b in zip(lx, le, strict=True)) / sum((a - mx) ** 2 for a in lx)
    return succ, fit


def rel_diff(a, b):
    """max|a − b| / max(max|a|, max|b|): symmetric relative difference (0 when both vanish)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    scale = max(float(np.max(np.abs(a), initial=0.0)), float(np.max(np.abs(b), initial=0.0)))
    diff = float(np.max(np.abs(a - b), initial=0.0))
    return diff / scale if scale > 0 else diff


def rel_to(a, ref):
    """max|a − ref| / max|ref| (max|a − ref| when ref vanishes): relative error against a reference."""
    a, ref = np.asarray(a, dtype=float), np.asarray(ref, dtype=float)
    diff = float(np.max(np.abs(a - ref), initial=0.0))
    scale = float(np.max(np.abs(ref), initial=0.0))
    return diff / scale if scale > 0 else diff


def strip_exact(text):
    """A scene's text without its ``[exact]`` table (a run of it costs what a user's run costs: no true
    errors are evaluated)."""
    out, skip = [], False
    for line in text.splitlines():
        if line.startswith("["):
            skip = line.strip() == "[exact]"
        if not skip:
            out.append(line)
    return "\n".join(out) + "\n"


def load1():
    """The 1-minute load average (recorded next to timings: the machine may be shared)."""
    return float(open("/proc/loadavg").read().split()[0])


def child_cpu():
    """CPU seconds (user + sys) used so far by this process's finished children: the difference around a
    subprocess is its CPU time."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime
