"""Compare two binaries on one command line by alternating their runs (A, B, A, B, ...) and printing the
median and minimum process wall time of each: on a shared VM whose speed drifts by up to 1.7x within
minutes, only runs interleaved like this compare two builds fairly (the same recipe as bench.py's `timed`:
time.perf_counter around subprocess.run, output discarded).

    .venv/bin/python verification/interleave.py 21 OLD_BINARY NEW_BINARY -- run verification/cases/mms_stop.toml --refine 4 --steps 16 -q
"""
import os
import statistics
import subprocess
import sys
import time

if len(sys.argv) < 5 or sys.argv[4] != "--":
    sys.exit(__doc__)
n, a, b, args = int(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[5:]
walls = {a: [], b: []}
for _ in range(n):
    for binary in (a, b):
        t = time.perf_counter()
        subprocess.run([binary] + args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        walls[binary].append(time.perf_counter() - t)
for binary in (a, b):
    w = walls[binary]
    print(f"{os.path.basename(binary):24s} median {statistics.median(w) * 1e3:8.1f} ms  min {min(w) * 1e3:8.1f} ms")
print(f"1-min load average at the end: {os.getloadavg()[0]:.2f}")
