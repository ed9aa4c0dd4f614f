"""Requirements of the external suite (issue 30 section 3), in the style of verification/README.md's table.

| id | the solvers shall … |
|---|---|
| XA-<scene>-<a>-<b> | (codes a, b) have Richardson limits of every compared quantity that agree within |
|                    | the sum of their GCI bands |
| XO-<scene>-<code>  | on a scene with an exact solution, have true H1-seminorm errors that converge at the |
|                    | code's theoretical order (CR, P1: 1; P2: 2): the least-squares order over the finest |
|                    | four of the five levels and the last two successive orders within ±0.15 (the band of |
|                    | the project's L² orders); only for codes of order ≤ the scene's ``xo_max_order`` |
|                    | and, on a near-incompressible scene (``Scene.locking``), only for the mixed codes |

On a near-incompressible scene (cep: λ/μ = 10⁴) the displacement-only conforming codes' error bounds
‖u − u_h‖_1 ≤ C(λ/μ) h^k have constants that grow with λ/μ (locking, Babuška–Suri 1992): conforming P1 sees
its asymptotic order 1 only where h√(λ/μ) ≪ 1 (h ≪ 0.01 here, below the finest h ≈ 0.022), so its three
finest levels are not in any asymptotic range and its Richardson limits are meaningless: getfem-P1 is left
out of XA and XO there and kept in the tables as the locking witness. Conforming P2 is also not uniform in λ
on these meshes (Scott–Vogelius would need degree ≥ 4) and converges pre-asymptotically (1.3); it stays in
XA (its bands are wide enough to be honest) but not in XO. The Taylor–Hood codes (inf–sup stable uniformly
in λ, ``skfem_mixed``) carry XO at order 2.

The lead wires :func:`evaluate` into the registry of ``tresca_py/verify``. Each entry: (id, requirement, passed,
detail, command).
"""
from __future__ import annotations

import math
from itertools import combinations

from .report import ENTRY, error_orders, limits
from .richardson import agree
from .suite import DISPLACEMENT_ONLY, ORDER

ORDER_BAND = 0.15


def evaluate(rows, scenes):
    out = []
    for sc in scenes:
        lims = limits(rows, sc.name)
        if sc.locking:  # the locking witness (see the module docstring)
            lims.pop("getfem-P1", None)
        for code in sc.xa_exclude:  # kept in the tables, out of XA for the reason in Scene.remark
            lims.pop(code, None)
        cmd = f"{ENTRY} --scene {sc.name}"
        for a, b in combinations(sorted(lims), 2):
            bad = [q for q in lims[a] if not agree(lims[a][q], lims[b][q])
                   and not (math.isnan(lims[a][q].value) and math.isnan(lims[b][q].value))]
            detail = "all agree" if not bad else "disagree: " + ", ".join(
                f"{q} ({lims[a][q].value:.6g}±{lims[a][q].gci:.2g} vs {lims[b][q].value:.6g}±{lims[b][q].gci:.2g})"
                for q in bad)
            out.append((f"XA-{sc.name}-{a}-{b}", f"limits of {a} and {b} agree within the sum of their GCI bands",
                        not bad, detail, cmd))
        for code, (succ, fit) in error_orders(rows, sc.name).items():
            p = ORDER[code]
            if p > sc.xo_max_order or (sc.locking and code in DISPLACEMENT_ONLY):
                continue
            ok = abs(fit - p) <= ORDER_BAND and all(abs(s - p) <= ORDER_BAND for s in succ[-2:])
            out.append((f"XO-{sc.name}-{code}", f"true H1 errors converge at order {p} ± {ORDER_BAND}", ok,
                        f"fit {fit:.3f}, successive " + ", ".join(f"{s:.3f}" for s in succ), cmd))
    return out
