"""The factorisation bench (issue 32): Example 5.1's reduced stiffness set up by tresca-cr and its peers.

For each refinement the matrix is exported once (probes/export_matrix.rs), then every round runs, each
as a process of its own and in an order rotated from round to round (so a drift of the shared machine's
speed affects all alike): tresca-cr from the scene (`export_matrix SCENE R --time`: mesh and space,
assembly with the ordering and symbolic factorisation beside it, numeric factorisation), CHOLMOD
(scikit-sparse, supernodal, AMD and METIS orderings), MKL PARDISO (pypardiso) and MUMPS (petsc4py), the
last four from the exported matrix (`tresca_py.bench.peers`). Each reports its phases, nnz(L) and the
flops of its factorisation; the process's CPU time and peak RSS are recorded with the 1-minute load.
The machine's dense-kernel rate is measured by a dense Cholesky factorisation (numpy/OpenBLAS, one
thread and all threads).
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

SOLVERS = ["tresca-cr", "cholmod", "cholmod-metis", "pardiso", "mumps"]


def load1():
    return float(open("/proc/loadavg").read().split()[0])


def run_json(cmd, env=None):
    """Run `cmd` (one JSON line on stdout) under /usr/bin/time: (its JSON, wall, peak RSS bytes)."""
    t0 = time.perf_counter()
    p = subprocess.run(["/usr/bin/time", "-f", "RSS %M"] + cmd, capture_output=True, text=True, env=env)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{p.stderr}")
    rss = int(p.stderr.strip().splitlines()[-1].split()[1]) * 1024
    return json.loads(p.stdout.strip().splitlines()[-1]), wall, rss


def command(solver, root, scene, refine, directory, python):
    exe = os.path.join(root, "target", "release", "examples", "export_matrix")
    if solver == "tresca-cr":
        return [exe, scene, str(refine), "--time"]
    return [python, "-m", "tresca_py.bench.peers", solver, directory]


def normalise(solver, out):
    """{analysis, factorisation, total} wall seconds of a result and their CPU seconds (`_cpu`; all threads);
    tresca-cr's analysis is everything before the numeric factorisation (mesh, space, assembly with the
    ordering and symbolic factorisation), and its CPU is the process's (no split by phase)."""
    if solver == "tresca-cr":
        pre = out["space"] + out["assembly"]
        return dict(analysis=pre, factorisation=out["factorisation"], total=pre + out["factorisation"],
                    analysis_cpu=float("nan"), factorisation_cpu=float("nan"), total_cpu=out["cpu"])
    if "total" in out:
        return {k: out[k] for k in ("analysis", "factorisation", "total", "analysis_cpu", "factorisation_cpu",
                                    "total_cpu")}
    return dict(analysis=out["analysis"], factorisation=out["factorisation"],
                total=out["analysis"] + out["factorisation"], analysis_cpu=out["analysis_cpu"],
                factorisation_cpu=out["factorisation_cpu"], total_cpu=out["analysis_cpu"] + out["factorisation_cpu"])


def bench(root, scene, refines, rounds, python, log=print, solvers=SOLVERS):
    rows = []
    with tempfile.TemporaryDirectory(prefix="factorisation_") as tmp:
        exe = os.path.join(root, "target", "release", "examples", "export_matrix")
        for r in refines:
            d = os.path.join(tmp, f"K{r}")
            subprocess.run([exe, scene, str(r), d], check=True)
            for k in range(rounds):
                order = solvers[k % len(solvers):] + solvers[:k % len(solvers)]
                for s in order:
                    load = load1()
                    out, wall, rss = run_json(command(s, root, scene, r, d, python))
                    row = dict(refine=r, round=k, solver=s, **normalise(s, out), nnz_l=out.get("nnz_l"),
                               flops=out.get("flops"), process_cpu=out.get("cpu"), process_wall=wall, peak_rss=rss,
                               load=load)
                    rows.append(row)
                    log(json.dumps(row))
            subprocess.run(["rm", "-rf", d])
    return rows


def dense_rates(python, n=4000):
    one = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")
    r1, _, _ = run_json([python, "-m", "tresca_py.bench.peers", "dense", str(n)], env=one)
    ra, _, _ = run_json([python, "-m", "tresca_py.bench.peers", "dense", str(n)])
    return r1["rate"], ra["rate"]


def table(rows, rate1):
    """Markdown: per refinement and solver the medians over rounds."""
    out = ["| refine | rounds | solver | analysis wall (CPU) s | factorisation wall (CPU) s | total wall (CPU) s | "
           "nnz(L) | flops | rate by CPU (flops/s) | of the 1-thread dense rate | peak RSS | load |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    key = sorted({(r["refine"], r["solver"]) for r in rows}, key=lambda x: (x[0], SOLVERS.index(x[1])))
    for refine, s in key:
        rs = [r for r in rows if r["refine"] == refine and r["solver"] == s]

        def med(f, rs=rs):
            return statistics.median([r[f] for r in rs]) if all(r[f] is not None for r in rs) else float("nan")

        fl = med("flops")
        # the factorisation's CPU (MUMPS and tresca-cr: the whole set-up's, an upper bound)
        fc = next((c for c in (med("factorisation_cpu"), med("total_cpu")) if c == c), float("nan"))
        rate = fl / fc if fc else float("nan")
        pair = lambda f: f"{med(f):.2f} ({med(f + '_cpu'):.2f})"  # noqa: E731
        out.append(f"| {refine} | {len(rs)} | {s} | {pair('analysis')} | {pair('factorisation')} | {pair('total')} | "
                   f"{med('nnz_l'):.3g} | {fl:.3g} | {rate:.3g} | {rate / rate1:.2f} | "
                   f"{med('peak_rss') / 1e9:.2f} GB | {med('load'):.1f} |")
    return "\n".join(out)


HEADING = "## 7. Factorisation at scale (issue 32)"


def section(rows, rate1, rate_all, refines, rounds):
    """The markdown section of reference/performance.md."""
    tre = [r for r in rows if r["solver"] == "tresca-cr"]
    refine_args = " ".join(map(str, refines))
    return f"""{HEADING}

Example 5.1's reduced stiffness (the unknowns of V_h, u·n = 0 on Γ_C eliminated) at refine
{", ".join(map(str, refines))}, set up by each solver in a process of its own, {rounds} interleaved rounds
(the order rotated each round), medians.
tresca-cr: `target/release/examples/export_matrix SCENE R --time` (mesh and space, assembly with the ordering and
symbolic factorisation beside it, numeric factorisation; its "analysis" is everything before the numeric
factorisation, its CPU the whole process's); the others from the matrix written by `export_matrix SCENE R DIR`:
CHOLMOD 5.12 supernodal (scikit-sparse 0.4.16, Debian libsuitesparse-dev; AMD and METIS orderings), MKL PARDISO
(pypardiso 0.4.7, analysis = phase 11, factorisation = phase 22), MUMPS (petsc4py 3.25, PC cholesky, one
set-up). Wall times in seconds, CPU seconds of all threads in parentheses: the machine was shared (the load column
is the 1-minute load average on its 2 cores), so the CPU times are the comparable figures. flops = Σ_j c_j² over
the columns of L (tresca-cr, CHOLMOD; PARDISO and MUMPS report their own counts, iparm(19) and RINFOG(3)); the
rate is flops / CPU seconds of the factorisation (tresca-cr and MUMPS: of the whole set-up, a lower bound).
Dense-kernel floor: numpy (OpenBLAS) Cholesky of order 4000, {rate1:.3g} flop/s by CPU time on one thread
({rate_all:.3g} with all threads, busy-waiting included).

Command: `make bench-env && .venv-bench/bin/python verification/bench/factorisation.py --refine {refine_args}
--rounds {rounds}`

{table(rows, rate1)}

tresca-cr's orderings: AMD below 200,000 unknowns, nested dissection by coordinate bisection from there
(`solve::cholesky::ordering`); {len(tre)} tresca-cr set-ups in this table.
"""


def write_section(path, text, heading=HEADING):
    """Replace the section that starts with `heading` in `path` (or append it)."""
    old = open(path).read() if os.path.exists(path) else ""
    if heading not in old:
        open(path, "w").write(old.rstrip("\n") + "\n\n" + text)
        return
    head, rest = old.split(heading, 1)
    nxt = rest.find("\n## ")
    tail = "\n" + rest[nxt + 1:] if nxt >= 0 else ""
    open(path, "w").write(head + text + tail)


def main(argv=None):
    import argparse
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--refine", type=int, nargs="+", default=[6, 7, 8])
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--scene", default="verification/cases/paper_example_5_1.toml")
    ap.add_argument("--solvers", nargs="+", default=SOLVERS, choices=SOLVERS)
    ap.add_argument("--json", default=None, help="write the rows here")
    ap.add_argument("--from-json", default=None, help="report the rows of an earlier --json instead of running")
    ap.add_argument("--write", default=None, help="put the section into this markdown file (reference/performance.md)")
    a = ap.parse_args(argv)
    if a.from_json:
        d = json.load(open(a.from_json))
        rows, rate1, rate_all = d["rows"], d["dense_rate_1"], d["dense_rate_all"]
    else:
        rate1, rate_all = dense_rates(sys.executable)
        print(f"dense Cholesky n = 4000: {rate1:.3g} flops/s on one thread, {rate_all:.3g} on all", flush=True)
        rows = bench(os.getcwd(), a.scene, a.refine, a.rounds, sys.executable, solvers=a.solvers)
    if a.json:
        json.dump(dict(rows=rows, dense_rate_1=rate1, dense_rate_all=rate_all), open(a.json, "w"), indent=1)
    refines = sorted({r["refine"] for r in rows})
    rounds = max(r["round"] for r in rows) + 1
    text = section(rows, rate1, rate_all, refines, rounds)
    print(text)
    if a.write:
        write_section(a.write, text)
