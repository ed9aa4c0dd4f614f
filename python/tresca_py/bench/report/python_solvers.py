"""Section 2: the same problem run by scripts/skfem_solve.py and scripts/dolfinx_solve.py, as ratios
to the Rust times of section 1, their results compared with the Rust ones."""
import os

import h5py

from tresca_py.bench.report.measure import EX51, fmt_t, max_du, med
from tresca_py.bench.timing import timed
from tresca_py.common import PY, ROOT, load1


def python_section(b):
    if b.args.no_python:
        return
    print("== 2. scikit-fem and dolfinx", flush=True)
    b.md += ["## 2. The same problem with the independent Python solvers", "",
             "`python scripts/{skfem,dolfinx}_solve.py paper_example_5_1.toml -o OUT.h5 --refine k --steps N -q`. "
             "\"process\" = whole process (interpreter start, imports, JIT for dolfinx, solve, write); "
             "\"own total\" = the script's own `total_time` attribute (assembly + factorisation + steps, "
             "without imports and writing). Ratios: Python process / Rust written-in-full process "
             "(both write a results file), and own total / Rust solve-only process (conservative: the Rust time "
             "includes process start). "
             "\"max du\": `scripts/compare.py` between the Rust and the Python results file "
             "(relative, max over time nodes) — equal accuracy means the same discrete solution.", "",
             "| n | N | solver | process (median) | own total | ratio process/Rust written | "
             "ratio own/Rust solve-only | max du vs Rust | load |", "|---|---|---|---|---|---|---|---|---|"]
    for k in b.levels:
        for name in ["skfem", "dolfinx"]:
            python_row(b, k, name)
    b.md.append("")


def python_row(b, k, name):
    """One row of section 2: a Python solver on Example 5.1 at refine k against the Rust runs of section 1."""
    N = 40 * 2 ** k
    rust_h5 = os.path.join(b.tmp, f"ex51_{k}_ssn.h5")
    out = os.path.join(b.tmp, f"{name}_{k}.h5")
    cmd = [PY, os.path.join(ROOT, "scripts", f"{name}_solve.py"), EX51, "-o", out,
           "--refine", str(k), "--steps", str(N), "-q"]
    walls, owns, loads = [], [], []
    for _ in range(b.R):
        loads.append(load1())
        walls.append(timed(cmd).wall)
        with h5py.File(out, "r") as f:
            owns.append(float(f["tresca"].attrs["total_time"]))
    du = max_du(rust_h5, out)
    w, o = med(walls), med(owns)
    rw, rs = b.ex[(k, "ssn", "write")].wall, b.ex[(k, "ssn", "solve")].wall
    b.py[(k, name)] = (w, o, w / rw, o / rs, du)
    b.md.append(f"| {2 * 2 ** k} | {N} | {name} | {fmt_t(w)} | {fmt_t(o)} | {w / rw:.1f}× | {o / rs:.1f}× | "
                f"{du:.1e} | {min(loads):.2f}-{max(loads):.2f} |")
    b.csvrows.append(dict(section="python", refine=k, steps=N, solver=name, mode="write", wall=w,
                          cli_wall=o, load=f"{min(loads):.2f}-{max(loads):.2f}"))
    print(b.md[-1], flush=True)
