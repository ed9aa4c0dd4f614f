"""Results files of interrupted runs open in every client (part of `make test`).

    .venv/bin/python verification/interrupted_runs.py

Requirement: the file of a run that was killed (SIGKILL, status "running"), of a run that stopped on a
solver failure (status "stopped: ..."), and of a killed run finished with --resume, each opens in VTK's
vtkHDFReader, meshio's XDMF reader and h5py, and each reader sees exactly the committed steps and frames
with the solver's values (scripts/check_results.py). Found necessary: VTK 9.7's reader corrupts its heap
when `Steps/Values` is longer than `NSteps`, which a killed run's file once had.

The kill lands mid-run: the uninterrupted run is timed first and the kill comes at half that time; the
check fails if the killed file is complete or holds no step (then the kill missed the run).
"""
import os
import signal
import subprocess
import sys
import time

import h5py

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "tresca-cr")
PY = sys.executable
EX51 = os.path.join(ROOT, "verification", "cases", "paper_example_5_1.toml")
FAILED = []


def check(ok, msg):
    print(("ok    " if ok else "FAIL  ") + msg, flush=True)
    if not ok:
        FAILED.append(msg)


def clients(h5, label):
    rc = subprocess.run([PY, os.path.join(ROOT, "scripts", "check_results.py"), h5], cwd=ROOT).returncode
    check(rc == 0, f"{label}: VTK, meshio and h5py read it (check_results.py exit {rc})")


def state(h5):
    with h5py.File(h5, "r") as f:
        return int(f["tresca/steps"].attrs["completed"]), str(f["tresca"].attrs["status"]), int(f["tresca"].attrs["steps"])


def main():
    out = os.path.join(ROOT, "out", "interrupted")
    os.makedirs(out, exist_ok=True)
    run = [BIN, "run", EX51, "--refine", "3", "--steps", "2000", "-q"]

    # 1. killed mid-run, then resumed
    h5 = os.path.join(out, "killed.h5")
    t = time.perf_counter()
    subprocess.run(run + ["-o", h5, "--force"], check=True, capture_output=True)
    whole = time.perf_counter() - t
    for attempt in range(5):
        p = subprocess.Popen(run + ["-o", h5, "--force"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(whole * 0.5)
        p.send_signal(signal.SIGKILL)
        p.wait()
        done, status, n = state(h5)
        if 0 < done < n + 1 and status == "running":
            break
        whole *= 1.5 if done == 0 else 0.7  # missed the run: retry with the kill later / earlier
    check(0 < done < n + 1 and status == "running", f"killed run: {done} of {n + 1} steps committed, status {status!r}")
    clients(h5, "killed run")
    r = subprocess.run(run + ["-o", h5, "--resume"], capture_output=True, text=True)
    done, status, n = state(h5)
    check(r.returncode == 0 and done == n + 1 and status == "completed", f"resumed run: {done} steps, status {status!r}")
    clients(h5, "resumed run")

    # 2. stopped on a solver failure at step 1
    scene = os.path.join(out, "fail.toml")
    with open(EX51) as f:
        text = f.read().replace('g_a = "0.0012"', 'g_a = "0.02"')
    text = text.replace('method = "ssn"', 'method = "uzawa"\nuzawa_step = 1e9\nmax_iter = 50')
    with open(scene, "w") as f:
        f.write(text)
    h5 = os.path.join(out, "stopped.h5")
    r = subprocess.run([BIN, "run", scene, "-q", "-o", h5, "--force"], capture_output=True, text=True)
    done, status, n = state(h5)
    check(r.returncode == 1 and done == 1 and status.startswith("stopped:"), f"stopped run: {done} step, status {status!r}")
    clients(h5, "stopped run")

    print(f"interrupted runs: {'all passed' if not FAILED else f'{len(FAILED)} FAILED'}")
    return 1 if FAILED else 0


if __name__ == "__main__":
    sys.exit(main())
