"""The Python part of `make test` (must finish in < 4 minutes on 2 cores).

    .venv/bin/python verification/python_tests.py [--no-mpi]

1. scripts/test_python_solvers.py --quick --no-cases: expression/mesh/box-QP unit checks, patch tests,
   skfem == dolfinx on generated and example scenes, the variational inequality from the stored results,
   dolfinx serial == mpirun -n 2, bad-input messages, skfem == Rust on the example scenes;
2. results file read by real clients: VTK's vtkHDFReader, meshio (XDMF) and h5py, values checked against
   the solver's (scripts/check_results.py on a fresh Example 5.1 run);
   and verification/interrupted_runs.py: the same for the files of a killed, a stopped and a resumed run;
   and verification/paraview_check.py --skip-missing: ParaView's three XDMF readers (pvpython) on a finished,
   a killed and a resumed run, and a rendered picture (skipped with a message where pvpython is absent);
3. verification/cross_check.py --quick: Rust == scikit-fem == dolfinx (1e-8, identical stick/slip sets) on
   every scene of verification/cases at one mesh level, plus one mpirun -n 2 case
   (report out/cross_check_quick.md, requirements out/cross_check_quick.json).

Exits non-zero if either fails.
"""
import argparse
import os
import subprocess
import sys
import time

from tresca_py.common import PY, ROOT  # noqa: E402
BUDGET = 240.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-mpi", action="store_true", help="skip the mpirun -n 2 checks")
    args = ap.parse_args()
    mpi = ["--no-mpi"] if args.no_mpi else []
    if not os.path.exists(os.path.join(ROOT, "target", "release", "tresca-cr")):
        sys.exit("error: target/release/tresca-cr missing (cargo build --release)")
    os.makedirs(os.path.join(ROOT, "out"), exist_ok=True)
    h5 = os.path.join("out", "test_clients.h5")
    steps = [
        ("results file for the client check", [os.path.join(ROOT, "target", "release", "tresca-cr"), "run",
                                               "verification/cases/paper_example_5_1.toml", "--refine", "2", "--steps", "160",
                                               "-q", "-o", h5, "--force"]),
        ("VTK / meshio / h5py read the results file", [PY, "scripts/check_results.py", h5]),
        ("files of killed, stopped and resumed runs", [PY, "verification/interrupted_runs.py"]),
        ("ParaView opens finished, killed and resumed runs", [PY, "verification/paraview_check.py", "--skip-missing"]),
        ("Python solver checks", [PY, "scripts/test_python_solvers.py", "--quick", "--no-cases"] + mpi),
        ("cross-check Rust / scikit-fem / dolfinx", [PY, "verification/cross_check.py", "--quick",
                                                      "--json", "out/cross_check_quick.json"] + mpi),
    ]
    t0 = time.perf_counter()
    failed = []
    for label, cmd in steps:
        print(f"== {label}: {' '.join(os.path.relpath(c, ROOT) if c == PY else c for c in cmd)}", flush=True)
        t = time.perf_counter()
        rc = subprocess.run(cmd, cwd=ROOT).returncode
        print(f"== {label}: {'ok' if rc == 0 else f'FAILED (exit {rc})'} in {time.perf_counter() - t:.0f} s\n", flush=True)
        if rc != 0:
            failed.append(label)
    total = time.perf_counter() - t0
    print(f"Python tests: {len(steps) - len(failed)}/{len(steps)} passed in {total:.0f} s"
          + (f" (over the {BUDGET:.0f} s budget)" if total > BUDGET else ""))
    if failed:
        print("failed: " + ", ".join(failed))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
