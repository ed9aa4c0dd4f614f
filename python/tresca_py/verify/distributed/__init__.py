"""The distributed dolfinx + PETSc/MUMPS route (issue 16): agreement (D1) and memory spreading (D2).

    .venv/bin/python verification/distributed.py [--memory] [--bin target/release/tresca-cr]
                                                 [--json out/distributed.json] [--md reference/distributed.md]

D1 (quick, about 8 min on 2 cores): every cross-check scene (verification/cases/*.toml and the generated expression
scenes of verification/cross_check.py) at its quick level, plus a Gmsh scene (verification/cases/lshape.msh,
refine 1, contact on its floor; once more with boundary data), is solved by the Rust binary and by
scripts/dolfinx_distributed.py under `mpirun -n 1`, `-n 2` and `-n 3` (3 is oversubscribed on 2 cores);
each distributed run is compared with the Rust run by scripts/compare.py: DOF vectors, energies, σ_τ and
true errors within 1e-8 relative at every time node, identical stick/slip sets. The boundary-data scenes
(``DATA_CASES``: dirichlet `u`, contact `gap`) are among them; D1 fails if one of them is not run.

D2 (--memory, ~6 min): Example 5.1 at refine 8 (1,574,912 unknowns, 512 contact edges, 3 steps) under
`mpirun -n 1` and `-n 2`, each rank wrapped in `/usr/bin/time -f "RSS %M"`: the peak resident memory of
the largest rank at -n 2 must be at most 0.6 x the -n 1 peak; the two runs must agree to 1e-8.  Set-up
and per-step times and the MUMPS statistics (factor entries, flops) are recorded, and they feed the
scaling model written into the report.  Without --memory the last D2 measurement
(reference/distributed_memory.json) is reported as such, not re-measured.

Prints PASS/FAIL per requirement with the measured numbers, writes the requirement list (JSON, merged by
verification/run_all.py) and reference/distributed.md, and exits 1 if a requirement fails.
"""
import argparse
import os
import sys
import time

from tresca_py.common import MPIRUN, ROOT
from tresca_py.verify.distributed.agreement import check_d1
from tresca_py.verify.distributed.memory import check_d2
from tresca_py.verify.distributed.report import write_report
from tresca_py.verify.distributed.solvers import solver_compare, solver_table
from tresca_py.verify.harness import Harness, out_dir


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--memory", action="store_true", help="also run D2 (1.57M unknowns at -n 1 and -n 2, ~6 min)")
    ap.add_argument("--with-rust", action="store_true", help="with --memory: also run the Rust binary on the big case")
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "tresca-cr"),
                    help="the Rust binary (default target/release/tresca-cr)")
    ap.add_argument("--json", default=os.path.join(ROOT, "out", "distributed.json"), help="requirement list")
    ap.add_argument("--md", default=os.path.join(ROOT, "reference", "distributed.md"), help="Markdown report")
    ap.add_argument("--memory-json", help="with --memory: where the measurement goes (default "
                    "reference/distributed_memory.json; make verify stages it under out/verify/reference/)")
    ap.add_argument("--work", default=os.path.join(ROOT, "out", "distributed"), help="directory for results files")
    ap.add_argument("--solver-compare", action="store_true",
                    help="only measure MUMPS against CG + GAMG (reference/distributed_solvers.json, ~3 min) and exit")
    args = ap.parse_args(argv)
    if args.solver_compare:
        os.makedirs(args.work, exist_ok=True)
        print("\n".join(solver_table(solver_compare(args.work))))
        return 0
    if not os.path.exists(args.bin):
        sys.exit(f"error: Rust binary {args.bin} missing (cargo build --release, or give --bin)")
    if not os.path.exists(MPIRUN):
        sys.exit(f"error: {MPIRUN} missing (the venv's mpich wheel provides it)")
    os.makedirs(args.work, exist_ok=True)
    t_start = time.perf_counter()
    hs = Harness(out=os.path.join(out_dir(), "distributed_harness"))
    self_cmd = ".venv/bin/python verification/distributed.py"

    rows, commands = check_d1(hs, args, self_cmd)
    meas = check_d2(hs, args, self_cmd)
    return write_report(hs, args, self_cmd, rows, commands, meas, time.perf_counter() - t_start)
