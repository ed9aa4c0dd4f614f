"""Section 3: a step against its floor (one pair of triangular solves with the reused factor) and the
factorisation."""
import os

from tresca_py.bench.report.measure import EX51, Rec, fmt_t, med
from tresca_py.common import BIN


def floor_scene(tmp):
    """Example 5.1's mesh and material without the contact part, non-separable traction on the left."""
    text = open(EX51).read()
    text = text.replace('kind = "contact"\ng_a = "0.0012"', 'kind = "neumann"')
    text = text.replace('traction = ["0.02*(5-y)*t", "-0.01*t"]',
                        'traction = ["0.02*(5-y)*sin(7*t*y)", "-0.01*cos(5*t*y)*t"]')
    assert 'kind = "contact"' not in text and "sin(7*t*y)" in text
    path = os.path.join(tmp, "floor_5_1.toml")
    open(path, "w").write(text)
    return path


def floor_section(b):
    print("== 3. floor: triangular solves with the reused factor", flush=True)
    fscene = floor_scene(b.tmp)
    b.md += ["## 3. A step against its floor (one pair of triangular solves) and the factorisation", "",
             "Floor scene: Example 5.1's mesh, material and Dirichlet side, the contact side made traction-free "
             "and the left traction made non-separable in time (`0.02*(5-y)*sin(7*t*y)`, `-0.01*cos(5*t*y)*t`), so "
             "load superposition does not apply and every step = assembly of the (boundary-only) load + one pair "
             "of triangular solves L Lᵀ x = l with the factor reused + the finiteness check: the cost of the cheapest "
             "possible step on that mesh. (The written generated scene is `floor_5_1.toml` in the bench temp dir; "
             "see `floor_scene()`.)", "",
             "| n | N | unknowns | floor per step (solve-only) | floor step compute (h5 median) | "
             "Ex. 5.1 ssn per step (solve-only) | Ex. 5.1 step compute (h5) | ratio 5.1/floor | factorisation | load |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for k in b.levels:
        N = 40 * 2 ** k
        rs = Rec([BIN, "run", fscene, "--refine", str(k), "--steps", str(N), "-q"], b.R)
        h5 = os.path.join(b.tmp, f"floor_{k}.h5")
        rw = Rec([BIN, "run", fscene, "--refine", str(k), "--steps", str(N), "-q", "-o", h5, "--force"], b.R, h5=h5)
        e_s, e_w = b.ex[(k, "ssn", "solve")], b.ex[(k, "ssn", "write")]
        fl = med(rw.step_walls)
        b.md.append(f"| {2 * 2 ** k} | {N} | {rs.info['unknowns']} | {fmt_t(rs.per_step)} | {fmt_t(fl)} | "
                    f"{fmt_t(e_s.per_step)} | {fmt_t(med(e_w.step_walls))} | {med(e_w.step_walls) / fl:.2f} | "
                    f"{fmt_t(rs.setup[2])} | {rs.load} |")
        b.csvrows.append(dict(section="floor", refine=k, steps=N, dofs=rs.info["unknowns"], mode="solve",
                              wall=rs.wall, per_step=rs.per_step, setup_fact=rs.setup[2], load=rs.load))
        print(b.md[-1], flush=True)
    b.md += ["", "Example 5.1's loads are proportional (g = t·g₁), so its steps do not solve with the factor at all: "
             "u_f = Σ c_j K⁻¹b_j (superposition) and u = u_f − K⁻¹Eμ with K⁻¹Eμ = P L⁻ᵀ[0; L_cc⁻¹μ], one backward "
             "half-solve, reused while μ repeats; a step is O(n·rank) dense work, that half-solve when μ changes, and "
             "the O(n_c²)-per-iteration friction QP.", ""]
