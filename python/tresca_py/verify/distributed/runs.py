"""The processes of the distributed checks: the distributed script's command line, a run that turns a
hang into a failed process, the results file's attributes, per-rank peak RSS, and the agreement tolerance."""
import os
import re
import subprocess

import h5py

from tresca_py.common import MPIRUN, PY, ROOT
from tresca_py.common import run as common_run


SCRIPT = os.path.join(ROOT, "scripts", "dolfinx_distributed.py")

# Agreement tolerance: the same 1e-8 as the cross-check (X…): far above the rounding of two direct
# solvers on these condition numbers (observed ~1e-13) and far below any discretisation effect.
TOL = 1e-8

RANKS = (1, 2, 3)


def run(cmd, timeout=600):
    """tresca_py.common.run without raising: a hang (e.g. one rank waiting for a dead one) becomes a failed
    process after `timeout` s."""
    try:
        return common_run(cmd, check=False, timeout=timeout)
    except subprocess.TimeoutExpired as e:
        out = e.stdout.decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or "")
        return subprocess.CompletedProcess(cmd, -9, out, f"timed out after {timeout} s"), float(timeout)


def dist_cmd(scene, out, refine, steps, ranks, timed=False, extra=()):
    base = [SCRIPT, scene, "-o", out, "-q", "--refine", str(refine)] + (["--steps", str(steps)] if steps else [])
    pre = [MPIRUN, "-n", str(ranks)]
    if timed:
        pre += ["/usr/bin/time", "-f", "RSS %M KB wall %e s"]
    return pre + [PY] + base + list(extra)


def attrs(path):
    with h5py.File(path, "r") as f:
        return dict(f["tresca"].attrs)


def parse_rss(stderr):
    """Per-rank peak RSS (MB) from the `/usr/bin/time -f "RSS %M KB ..."` lines, one per rank."""
    return [int(m) / 1024.0 for m in re.findall(r"RSS (\d+) KB", stderr)]
