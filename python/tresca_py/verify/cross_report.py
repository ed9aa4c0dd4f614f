"""The report of ``verification/cross_check.py`` (``tresca_py.verify.cross_check``): the agreement and wall-time tables,
the notes on what the three codes share, and the Markdown file (requirements, tables, commands, versions)."""
import os

from tresca_py.verify.cross_runs import TOL, pair_ok, versions

NOTES = """## Notes

**What the three codes share.** They read the same scene expressions the same way and classify contact
edges by the same rule, so identical numbers and identical stick/slip sets can be required:

1. `signum(0) = +1` everywhere: Rust evaluates `f64::signum`; the Python reader (tresca_py/expr.py) writes
   `signum` as a Piecewise with value +1 at 0, which the dolfinx solvers translate to `ufl.conditional`.
2. Stick/slip: an edge slips at step n when |Δs_e| > 1e-9 max(|Δs|, |d|), in Rust (`friction::classify`) and
   in Python (`tresca_py.skfem_cr.friction.classify`, used by both Python solvers).
3. Constants: `PI`, `π`, `E`, `e`, `TAU`, `τ`, and lower-case `pi` read as `PI` by both readers
   (src/scene/expr/lint.rs, tresca_py/expr.py).

**Rounding amplification of derr.** |e_A - e_B| <= |||u_A - u_B||| (reverse triangle inequality), so the
relative difference of the true errors is up to du·|||u|||/e: the DOF vectors agree to about κ(a_h)·eps
(du grows about 5x per refinement: 3e-14, 2e-13, 1.3e-12, 6e-12, 3e-11 on mms_elastic refine 0..4), and
the L2 error shrinks 4x, so derr grows about 20x per refinement (3e-13, 7e-12, 2e-10, 4e-9, 7e-8 on
mms_elastic). The 1e-8 bound on derr therefore holds up to refine 3 only; the levels used here stay at
or below refine 2. Beyond that a bound on |e_A - e_B| / |||u||| is the meaningful one.

**Near incompressibility.** near_incompressible (ν = 0.4999) agrees to 1e-11, but with ν = 0.4999999
(E = 2(1+ν)) κ(a_h)·eps reaches about 1e-7: Rust differs from both Python codes by du 2e-8 (refine 1) and
1e-7 (refine 2), skfem from dolfinx by 2e-9 and 2e-8. Against a skfem solve with 5 steps of iterative
refinement the errors at refine 2 are: Rust 1.1e-7, dolfinx 1.8e-8, skfem (1 refinement step) 1.6e-9,
skfem without refinement 1.8e-8. The Python solvers do one step of iterative refinement after SuperLU;
the Rust solver (src/solve/cholesky/factor.rs, `Factor::solve_in_place` / `solve_many`) does none. A 1e-8
agreement is not a meaningful requirement there (assembly rounding alone moves dolfinx 1.8e-8 from skfem).

**Wall times.** The Python processes spend 1.5–3 s in start-up (imports; dolfinx form compilation on
first use, cached afterwards), so on these small meshes the whole-process times compare start-up costs;
the bracketed in-process times compare the solvers.
"""



def tables(cx, mpi_rows):
    """The agreement and wall-time tables (Markdown)."""
    codes = ["rust", "skfem", "dolfinx"] + (["dolfinx -n 2"] if mpi_rows else [])
    lines = [
        "Agreement (max over the time nodes; du, dE, derr relative; dsig relative to max ḡ; flags = differing "
        "stick/slip states summed over the nodes):",
        "",
        "| case | refine | N | pair | du | dE | dsig | derr | flags | ok |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row in cx.rows:
        r = row["r"]
        if row.get("outside"):
            lines.append(f"| {row['case']} | {row['refine']} | {row['steps']} | {row['pair']} | – | – | – | – | – | "
                         f"{row['outside']} |")
            continue
        if r is None:
            lines.append("| "
                         f"{row['case']} | "
                         f"{row['refine']} | {row['steps']} | {row['pair']} | – | – | – | – | – | FAIL |")
            continue
        derr = f"{r['derr']:.1e}" if r["has_errors"] else "–"
        lines.append("| "
                     f"{row['case']} | "
                     f"{row['refine']} | {row['steps']} | {row['pair']} | {r['du']:.1e} | {r['dE']:.1e} | "
                     f"{r['dsig']:.1e} | {derr} | {r['flags']} | {'PASS' if pair_ok(r) else 'FAIL'} |")
    for m in mpi_rows:
        r = m["r"]
        if r is None:
            lines.append(f"| {m['case']} | {m['refine']} | – | dolfinx–dolfinx -n 2 | – | – | – | – | – | FAIL |")
            continue
        derr = f"{r['derr']:.1e}" if r["has_errors"] else "–"
        lines.append(f"| {m['case']} | {m['refine']} | {r['n_times'] - 1} | dolfinx–dolfinx -n 2 | {r['du']:.1e} | "
                     f"{r['dE']:.1e} | {r['dsig']:.1e} | {derr} | {r['flags']} | {'PASS' if m['passed'] else 'FAIL'} |")
    lines += [
        "",
        "Wall time in seconds: whole process (start-up, scene, assembly, every step, true errors, output), "
        "in brackets the solver's own record (Rust: set-up + steps, without true errors and output; Python: "
        "assembly + steps + true errors, after imports and scene loading).",
        "",
        "| case | refine | N | edges | Γ_C edges | " + " | ".join(codes) + " |",
        "|---|---|---|---|---|" + "---|" * len(codes),
    ]
    for t in cx.timing:
        cells = []
        for c in codes:
            if c in t["wall"]:
                inn = t["inner"].get(c)
                cells.append(f"{t['wall'][c]:.2f}" + (f" ({inn:.3f})" if inn is not None else ""))
            else:
                cells.append("–")
        lines.append(
            f"| {t['case']} | {t['refine']} | {t['steps']} | {t['edges']} | {t['contact']} | "
            + " | ".join(cells)
            + " |"
        )
    return "\n".join(lines)


def write_markdown(cx, args, table, total):
    """The Markdown report at cx.md_path: the requirements of cx.hs, ``table``, the commands and the versions."""
    reqs, nfail = cx.hs.results, len(cx.hs.failed)
    self_cmd = cx.self_cmd
    ver = versions()
    md = [f"<!-- generated by verification/cross_check.py{' --quick' if args.quick else ''} -->",
          "# Cross-check: Rust, scikit-fem and dolfinx (issue 6)", "",
          f"`{self_cmd}{' --no-mpi' if args.no_mpi else ''}` — {len(reqs) - nfail}/{len(reqs)} requirements passed, "
          f"{total:.0f} s in all. Tolerance {TOL:g}; stick/slip sets must be identical.", "",
          "Stick/slip convention of all three codes (Rust `friction::classify`): an edge slips at step n when "
          "|μ_e| ≥ w_e(1 − 1e-9) and |Δs_e| > 1e-9·max(‖Δs‖∞, ‖d‖∞), Δs = d − Cμ the slip increment, d the "
          "increment without friction; state 0 and μ = 0 at step 0; σ_τ = −μ/|e|; exmex's signum(0) = 1.", "",
          "## Requirements", "", "| id | passed | measured |", "|---|---|---|"]
    md += [f"| {r.id} | {'PASS' if r.passed else 'FAIL'} | {r.measured} |" for r in reqs]
    md += [
        "",
        "## Tables",
        "",
        table,
        "",
        "## Commands",
        "",
        "Run from the repository root, one after the other:",
        "",
        "```",
    ]
    md += cx.commands
    md += ["```", "", NOTES, "## Versions", ""] + [f"- {k}: {v}" for k, v in ver.items()] + [""]
    os.makedirs(os.path.dirname(cx.md_path), exist_ok=True)
    with open(cx.md_path, "w") as fh:
        fh.write("\n".join(md))
