"""Compare two binaries on one command line by alternating their runs (A, B, A, B, ...) and printing the
median and minimum process wall time of each: on a shared VM whose speed drifts by up to 1.7x within
minutes, only runs interleaved like this compare two builds fairly (:func:`tresca_py.bench.timing.timed`,
as bench.py times; output discarded, exit status not checked). A benchmark tool: nothing of `make verify`
or `make test` uses it.

    .venv/bin/python verification/interleave.py 21 OLD_BINARY NEW_BINARY -- \\
        run verification/cases/mms_stop.toml --refine 4 --steps 16 -q
"""
import os
import statistics
import sys

from tresca_py.bench.timing import timed


def interleave(n, a, b, args):
    """Wall seconds of ``n`` alternating runs of ``a args`` and ``b args``: {binary: [seconds, ...]}."""
    walls = {a: [], b: []}
    for _ in range(n):
        for binary in (a, b):
            walls[binary].append(timed([binary] + list(args), check=False).wall)
    return walls


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) < 4 or argv[3] != "--":
        print(__doc__)
        return 2
    n, a, b, args = int(argv[0]), argv[1], argv[2], argv[4:]
    walls = interleave(n, a, b, args)
    for binary in (a, b):
        w = walls[binary]
        print(f"{os.path.basename(binary):24s} median {statistics.median(w) * 1e3:8.1f} ms  min {min(w) * 1e3:8.1f} ms")
    print(f"1-min load average at the end: {os.getloadavg()[0]:.2f}")
    return 0
