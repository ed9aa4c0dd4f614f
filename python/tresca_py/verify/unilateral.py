"""U1–U8 of ``make verify``. U1–U4: the scikit-fem solver's unilateral contact (issue 40) converges to the manufactured
Signorini–Tresca and Signorini–Coulomb solutions (tresca_py.mms.signorini) with the predicted orders, energy 1 and
L² 2, over five levels (refine 0..4, or 1..5 where refine 0 is pre-asymptotic; N = 8: backward Euler is exact at
the nodes for these cases, so the error is spatial), with every step solved to a natural residual ≤ 1e-12 and the
written per-edge pressure and gap satisfying the discrete Signorini conditions; and (U4) order 1 in k of the time
error where the slip stops abruptly (mms_signorini_stop). U5–U8: tresca-cr itself on the same cases, levels
and N, through ``tresca-cr study`` and the harness of the bilateral rows (``studies.h_study``, ``studies.k_study``,
which checks order 1 in k at refine 3 against N = 4096); U7 shows that the Coulomb solver (semismooth Newton) reaches
the manufactured solution with the same orders, not merely some fixed point.

    .venv/bin/python scripts/skfem_solve.py verification/cases/mms_signorini_moving.toml --refine k -o OUT.h5
"""
import os

import numpy as np

from tresca_py import results
from tresca_py.common import PY, case, cmdline, run
from tresca_py.verify import studies
from tresca_py.verify.harness import out_dir
from tresca_py.verify.studytools import plot, rate_ok, req, table_md

#: (requirement id, case, what it shows, first refinement level): five levels from it (four with --quick); the
#: near-incompressible case's L² error is pre-asymptotic at refine 0 (successive order 1.59 there, 1.81, 1.92,
#: 1.97 after), so its levels start at refine 1
CASES = (("U1-skfem-signorini", "mms_signorini_moving", "Signorini–Tresca with moving contact/separation and "
          "stick/slip points", 0),
         ("U2-skfem-signorini-incompressible", "mms_signorini_incompressible", "near-incompressible Signorini–"
          "Tresca (λ/μ = 10⁴), without locking", 1),
         ("U3-skfem-coulomb", "mms_signorini_coulomb", "Signorini–Coulomb, threshold F p with the exact pressure", 0))
STEPS = 8
#: the natural residual every step must reach (the solver is exact up to rounding: ~1e-15 measured)
KKT_TOL = 1e-12


def discrete_signorini(r):
    """max over steps and edges of (−p, gap, |p gap|) relative to the pressure scale and the largest |gap|
    (each ≤ 1e-12: P ≥ 0, u_n − ḡ ≤ 0, P (u_n − ḡ) = 0 by the exact active-set solution)."""
    c = r.contact
    p, g = c.pressure[1:], c.gap[1:]
    ps, gs = max(np.max(np.abs(p)), 1e-300), max(np.max(np.abs(g)), 1e-300)
    return max(np.max(-p) / ps, np.max(g) / gs, np.max(np.abs(p * g)) / (ps * gs))


def level(name, refine, steps=STEPS):
    """Run the scikit-fem solver on case ``name`` at ``refine``; the row of the level's table."""
    out = os.path.join(out_dir(), "unilateral", f"{name}_r{refine}.h5")
    os.makedirs(os.path.dirname(out), exist_ok=True)
    cmd = [PY, "scripts/skfem_solve.py", case(name), "--refine", str(refine), "--steps", str(steps), "-o", out, "-q",
           "--force"]
    run(cmd)
    r = results.read(out)
    m = r.mesh
    h = float(np.max(np.linalg.norm(m.points[m.edges[:, 1]] - m.points[m.edges[:, 0]], axis=1)))
    return dict(refine=refine, steps=steps, h=h, k=float(r.times[1] - r.times[0]), paper_dofs=2 * len(m.edges),
                energy_max=float(np.max(r.errors["energy"])), h1_max=float(np.max(r.errors["h1"])),
                l2_max=float(np.max(r.errors["l2"])), residual=float(np.max(r.steps["residual"])),
                signorini=discrete_signorini(r), states=np.bincount(r.contact.status[-1], minlength=3).tolist()), cmd


def convergence(name, levels):
    """The rows of case ``name`` at refinements ``levels`` and the orders: (rows, (ok_e, m_e), (ok_l, m_l), cmd)."""
    rows, cmd = [], None
    for k in levels:
        row, cmd = level(name, k)
        rows.append(row)
    h = [r["h"] for r in rows]
    return rows, rate_ok(h, [r["energy_max"] for r in rows], 1, 0.1), \
        rate_ok(h, [r["l2_max"] for r in rows], 2, 0.15), cmd


def energy_differences(name, refine, steps, ref):
    """max over the nodes of N = steps[0] of |||u_N − u_ref||| (a_h's energy norm, the same mesh) for every N of
    ``steps`` against the N = ``ref`` solution: the time error at this h."""
    from tresca_py.scene import load_scene
    from tresca_py.skfem_cr.assemble import SkfemProblem
    from tresca_py.skfem_cr.cr import Discretisation
    K = SkfemProblem(Discretisation(load_scene(case(name), refine=refine))).K
    u = {}
    for n in list(steps) + [ref]:
        out = os.path.join(out_dir(), "unilateral", f"{name}_r{refine}_N{n}.h5")
        os.makedirs(os.path.dirname(out), exist_ok=True)
        run([PY, "scripts/skfem_solve.py", case(name), "--refine", str(refine), "--steps", str(n), "-o", out, "-q",
             "--force"])
        u[n] = results.read(out).u.reshape(n + 1, -1)
    coarse = steps[0]
    out = []
    for n in steps:
        d = [u[n][i * n // coarse] - u[ref][i * ref // coarse] for i in range(1, coarse + 1)]
        out.append(max(float(np.sqrt(v @ (K @ v))) for v in d))
    return out


def k_study(hs, quick=False):
    """U4: mms_signorini_stop at refine 2, N = 4^j (θ = frac(N/3) = 1/3 fixed): time error order 1 ± 0.1 in k."""
    name, refine, steps = "mms_signorini_stop", 2, [4, 16, 64, 256]
    ref = 1024 if quick else 4096
    e = energy_differences(name, refine, steps, ref)
    k = [1.0 / n for n in steps]
    ok, m = rate_ok(k, e, 1, 0.1)
    cmd = (f".venv/bin/python scripts/skfem_solve.py verification/cases/{name}.toml --refine {refine} --steps N "
           f"(N = {', '.join(map(str, steps))}; reference N = {ref})")
    md = (f"<!-- generated by verification/run_all.py: {cmd} -->\n## {name}: time error of the scikit-fem solver at "
          f"refine {refine}, max over the nodes of N = 4 of |||u_N − u_ref||| (N = {ref})\n\n"
          "| N | k | error | order |\n|---|---|---|---|\n")
    md += "".join(f"| {n} | {1 / n:.4e} | {x:.4e} | "
                  + ("-" if i == 0 else f"{np.log(e[i - 1] / x) / np.log(4):.3f}") + " |\n"
                  for i, (n, x) in enumerate(zip(steps, e, strict=True)))
    hs.write(f"k_skfem_{name}.md", md)
    req(hs, "U4-skfem-signorini-k", "converge with order 1 ± 0.1 in k when the slip stops abruptly on a unilateral "
        "contact part (scikit-fem, time error at fixed h)", ok, m, cmd, f"reference/k_skfem_{name}.md")


def study(hs, quick=False):
    """Record U1–U4 (energy and L² orders, KKT and discrete Signorini per level; the order in k)."""
    for rid, name, what, first in CASES:
        levels = range(first, first + (4 if quick else 5))
        rows, (ok_e, m_e), (ok_l, m_l), cmd = convergence(name, levels)
        cmd = cmdline(cmd[:7]).replace(f"--refine {levels[-1]}", "--refine k")     # without -o OUT -q
        ref = f"h_skfem_{name}"
        md = table_md(ref, f"{name}: scikit-fem, true errors (max over the time nodes), N = {STEPS}", rows,
                      ["energy_max", "h1_max", "l2_max"])
        md += "\n| refine | max natural residual | discrete Signorini defect | stick / slip / separated at T |\n"
        md += "|---|---|---|---|\n" + "".join(f"| {int(r['refine'])} | {r['residual']:.1e} | {r['signorini']:.1e} | "
                                            f"{' / '.join(map(str, r['states']))} |\n" for r in rows)
        hs.write(f"{ref}.md", f"<!-- generated by verification/run_all.py: {cmd} -->\n" + md)
        plot(hs, ref, f"{name} (scikit-fem)", [r["h"] for r in rows],
             [("energy", [r["energy_max"] for r in rows]), ("L2", [r["l2_max"] for r in rows])], "h", [1, 2])
        kkt = max(r["residual"] for r in rows)
        sig = max(r["signorini"] for r in rows)
        exact = f"; max natural residual {kkt:.1e}, discrete Signorini defect {sig:.1e}"
        solved = kkt <= KKT_TOL and sig <= KKT_TOL
        req(hs, rid + "-energy", f"converge in h on {what} (scikit-fem): energy order 1 ± 0.1", ok_e and solved,
            m_e + exact, cmd, f"reference/{ref}.md")
        req(hs, rid + "-L2", f"converge in h on {what} (scikit-fem): L² order 2 ± 0.15", ok_l and solved, m_l + exact,
            cmd, f"reference/{ref}.md")
    k_study(hs, quick)
    rust_study(hs, quick)


#: tresca-cr's rows: (requirement id, case, reference name, what it shows, first refinement level), as CASES
RUST_CASES = tuple((rid.replace("U1-skfem", "U5-rust").replace("U2-skfem", "U6-rust").replace("U3-skfem", "U7-rust"),
                    name, f"h_rust_{name}", what, first) for rid, name, what, first in CASES)


def rust_study(hs, quick=False):
    """Record U5–U8: tresca-cr's true errors and orders in h on the cases of U1–U3 (energy 1 ± 0.1, L² 2 ± 0.15) and
    its order 1 ± 0.1 in k on mms_signorini_stop."""
    for rid, name, ref, what, first in RUST_CASES:
        levels = [(k, STEPS) for k in range(first, first + (4 if quick else 5))]
        studies.h_study(hs, rid, f"verification/cases/{name}.toml", ref, levels, 1, 2,
                        f"converge in h on {what} (tresca-cr)")
    # always against N = 4096: --quick's N = 1024 is 4 N_max, and for an exact O(k) time error C θ k the difference
    # C θ (k − k_ref) then gives a last successive order log 5 / log 4 = 1.16 (measured 1.163), outside the band
    studies.k_study(hs, False, "mms_signorini_stop", "U8-rust-signorini-k")
