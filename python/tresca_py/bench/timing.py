"""Timing a process, for `make bench` only (no requirement of `make verify` or `make test` depends on a
time): wall seconds, CPU seconds (user + sys of the child, from getrusage) and optionally its peak RSS and
its --json summary.
"""
import os
import re
import subprocess
import tempfile
import time
from typing import NamedTuple, Optional

from tresca_py.common import ROOT, child_cpu
from tresca_py.verify import summary as cli_summary

TIME = "/usr/bin/time"


class Timed(NamedTuple):
    """One timed process: wall and CPU (user + sys) seconds, peak RSS in KB (with ``mem``), and the CLI's
    --json summary (``summary``: for a tresca-cr command)."""
    wall: float
    cpu: float
    rss: Optional[int]
    summary: Optional[dict]


def timed(cmd, env=None, mem=False, summary=False, check=True):
    """Run cmd from the repository root (with ``summary``: a tresca-cr command, given --json into a temporary
    file, read back). ``check``: a non-zero exit (other than a plan's refusal, 3) raises RuntimeError."""
    cmd = [str(c) for c in cmd]
    js = None
    if summary:
        fd, js = tempfile.mkstemp(prefix="tresca-bench-", suffix=".json")
        os.close(fd)
        os.remove(js)  # a name no other process takes (mkstemp); the command creates the file itself
        cmd = list(cmd) + ["--json", js]
    if mem:
        cmd = [TIME, "-f", "MAXRSS %M"] + cmd  # our own format for /usr/bin/time's report on stderr
    c0 = child_cpu()
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=ROOT)
    wall = time.perf_counter() - t0
    cpu = child_cpu() - c0
    if check and p.returncode not in (0, 3):
        raise RuntimeError(f"{' '.join(map(str, cmd))} failed ({p.returncode}):\n{p.stdout}\n{p.stderr}")
    rss = None
    if mem:
        m = re.search(r"MAXRSS (\d+)", p.stderr)
        rss = int(m.group(1)) if m else None
    s = None
    if js:
        s = cli_summary.load(js) if os.path.exists(js) and os.path.getsize(js) else None
        if os.path.exists(js):
            os.remove(js)
    return Timed(wall, cpu, rss, s)
