"""The external suite: every scene at every level with every code; rows of compared quantities.

Codes: GetFEM P1 and P2 (a subprocess under /usr/bin/python3, JSON in and out), the scikit-fem P2 Nitsche
solver (in process) and tresca-cr (``tresca-cr run``; its column is empty for scenes it cannot read yet).
All codes of a scene use the same time steps (the backward-Euler problem at that k is the common limit).
"""
from __future__ import annotations

import importlib.util
import json
import math
import os
import shutil
import subprocess
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np

from . import hertz, problem, quantities, skfem_mixed, skfem_nitsche, skfem_signorini, tresca

GETFEM_PYTHON = "/usr/bin/python3"
CODES = ("getfem-P1", "getfem-P2", "skfem-P2-nitsche", "getfem-TH", "skfem-TH-nitsche", "tresca-cr")
#: theoretical H1 order of each code (CR and P1: 1, P2 and Taylor–Hood P2/P1: 2 where the regularity allows)
ORDER = {"getfem-P1": 1, "getfem-P2": 2, "skfem-P2-nitsche": 2, "getfem-TH": 2, "skfem-TH-nitsche": 2,
         "tresca-cr": 1}
#: the displacement-only codes, whose error constants grow with λ/μ (locking); the mixed (TH) variants do not
DISPLACEMENT_ONLY = ("getfem-P1", "getfem-P2", "skfem-P2-nitsche")
DEFAULT_CODES = ("getfem-P1", "getfem-P2", "skfem-P2-nitsche", "tresca-cr")


@dataclass(frozen=True)
class Scene:
    """A scene with its levels (refine values) for the CR and P1 codes; the P2 codes run one level lower
    (``P2_SHIFT``), so that every code's finest level has about the same number of unknowns."""
    name: str
    path: str
    levels: tuple
    steps: int
    note: str = ""
    #: the highest code order whose true errors at these steps are spatial: at N = 4, mms_front's exact
    #: solution misses the backward-Euler inclusion on the strip the trailing front crosses in a step, a
    #: time error (≈ 4e-4 in H1) that the P2 codes' spatial error reaches at 32 cells (their order 1.36 there
    #: becomes 1.88 with N = 16: reference/external.md)
    xo_max_order: int = 2
    #: the codes run on this scene
    codes: tuple = DEFAULT_CODES
    #: λ/μ ≥ 10³: the displacement-only codes are locking witnesses (no XO; getfem-P1 out of XA), see README
    locking: bool = False
    #: the manufactured stick margin closes cubically at the fronts: the endpoints' theoretical order is k/3
    cubic_front: bool = False
    #: codes kept in the tables but left out of XA, with the reason in ``remark`` (printed under the scene)
    xa_exclude: tuple = ()
    remark: str = ""
    #: the compared quantities (``quantities``); Hertz compares its own
    quantities: tuple = quantities.QUANTITIES
    #: the solution's regularity caps every code's theoretical order (Hertz: u ∈ H^{5/2−ε}, order ≤ 3/2)
    order_cap: float = math.inf
    #: levels that are new meshes: level ↦ (scene path, h) written into the work directory (``hertz``);
    #: None: the levels are ``refine`` values of ``path``
    mesh_levels: Callable | None = None

    def levels_of(self, code):
        return tuple(r + P2_SHIFT for r in self.levels) if ORDER[code] == 2 else self.levels


P2_SHIFT = -1
SCENES = (
    Scene("ex51", "verification/cases/paper_example_5_1.toml", (1, 2, 3, 4, 5), 4,
          "Example 5.1 (proportional load: N = 4 steps instead of the paper's 40)"),
    Scene("mms_front", "verification/cases/mms_front.toml", (0, 1, 2, 3, 4), 4,
          "manufactured, moving stick-slip fronts (its energy error does not depend on N, scene note)",
          xo_max_order=1, cubic_front=True),
    Scene("cep", "verification/external/scenes/cep_tresca.toml", (1, 2, 3, 4, 5), 1,
          "Chouly-Ern-Pignet Tresca, lambda/mu = 1e4, nonzero Dirichlet data",
          codes=DEFAULT_CODES[:3] + ("getfem-TH", "skfem-TH-nitsche", "tresca-cr"), locking=True),
    Scene("imposed", "verification/external/scenes/imposed_normal.toml", (1, 2, 3, 4, 5), 1,
          "static, imposed normal displacement -0.1 on Gamma_C"),
    Scene("mms_rotated", "verification/cases/mms_rotated.toml", (0, 1, 2, 3, 4), 4,
          "manufactured, rotated square (contact side not axis-aligned)", cubic_front=True),
    Scene("pentagon", "verification/external/scenes/pentagon_tresca.toml", (1, 2, 3, 4, 5), 1,
          "Chouly-Ern-Pignet solution at lambda = 3 on a Gmsh pentagon (12 triangles, red-refined), "
          "Dirichlet data on two sides, Neumann on one"),
) + (
    # unilateral contact (issue 40 item 5): the GetFEM codes use Coulomb_friction_coupled_projection, the
    # scikit-fem code skfem_signorini; a scene is one more entry here, Scene(name, path, levels, steps, note), and
    # then shows in `run.py --scene NAME`, the tables and make verify (Hertz: levels that are new meshes).
    Scene("sig_moving", "verification/cases/mms_signorini_moving.toml", (0, 1, 2, 3, 4), 8,
          "manufactured Signorini-Tresca, moving contact/separation and stick/slip points", cubic_front=True),
    Scene("sig_coulomb", "verification/cases/mms_signorini_coulomb.toml", (0, 1, 2, 3, 4), 8,
          "manufactured Signorini-Coulomb, threshold F p, moving fronts", cubic_front=True,
          codes=("getfem-P2", "skfem-P2-nitsche", "tresca-cr"),
          remark="getfem-P1 is not run here: its Newton on the Coulomb coupled projection does not converge at "
                 "64×64 cells (step 1: residual 1e-4·r0 after 40 iterations with each line search basic, "
                 "simplest, systematic; getfem-P2 needs up to 82 iterations at 32×32 cells)"),
    Scene("coulomb_block", "verification/cases/coulomb_block.toml", (1, 2, 3, 4, 5), 8,
          "Coulomb block (F = 0.3) pressed and sheared at once by its Dirichlet top on a rigid foundation",
          xa_exclude=("getfem-P1",),
          remark="getfem-P1 is out of XA: its θ = 0 Nitsche stick zone carries slip increments above the "
                 "threshold (h/|Γ_C|)² max|δu_τ|, so its stick–slip endpoints are not found (NaN at refine 3, "
                 "one short zone elsewhere); its other quantities are in the table"),
    Scene("hertz", "verification/cases/hertz_a10.toml", (0, 1, 2, 3, 4), 1,
          "Hertz, a/R = 0.1: quarter cylinder on a rigid plane, frictionless, the cut pushed down by delta",
          quantities=("h1_norm", "energy", "normal_force", "max_pressure", quantities.HALF_WIDTH), order_cap=1.5,
          mesh_levels=partial(hertz.level_scene, "hertz_a10"),
          remark="levels are the Hertz study's new meshes (tresca_py.hertz.mesh, arc vertices on the circle; P2 "
                 "codes one level lower), not `refine`; the cut y = R is pushed down by delta = 0.015 (Dirichlet), "
                 "not loaded by P (a floating body: GetFEM's and scikit-fem's first Newton tangent, with no contact "
                 "point active at u = 0, would be singular in the vertical translation); every code imposes "
                 "u·n ≤ y R/(R − y) along each polygon edge's own normal. No exact solution, so no XO row: Hertz's "
                 "formulas are not the limit (the half-space model's own error, ≈ 1.5 % in a at a/R = 0.1, "
                 "reference/hertz.md). ∫σ_τ, u·τ, the stick ends and the slip are not compared: frictionless, and "
                 "Γ_C is curved; half_width = 2√(∫p x²/∫p) (Hertz: a); theoretical orders capped at 3/2 "
                 "(Signorini: u ∈ H^{5/2−ε}); tresca-cr's `study --csv` is not run (its levels refine one mesh)"),
)


def unilateral(prob):
    """Whether a problem's contact part is unilateral (u·n ≤ g) rather than bilateral (u·n = g)."""
    return any(p["kind"] == "contact" and p.get("law") == "unilateral" for p in prob["parts"])


def getfem_available():
    return Path(GETFEM_PYTHON).exists() and subprocess.run(
        [GETFEM_PYTHON, "-c", "import getfem"], capture_output=True).returncode == 0


def run_getfem(prob, work):
    """Solve one problem with GetFEM in a subprocess; the raw result dict."""
    work.mkdir(parents=True, exist_ok=True)
    tag = f"getfem_{'TH' if prob.get('mixed') else 'P' + str(prob['degree'])}_r{prob['refine']}"
    pin, pout = work / f"{tag}_problem.json", work / f"{tag}_result.json"
    pin.write_text(json.dumps(prob))
    script = importlib.util.find_spec("tresca_py.external.getfem_solver").origin
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")  # as the venv side (run.py)
    proc = subprocess.run([GETFEM_PYTHON, script, str(pin), str(pout)], capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        raise RuntimeError(f"GetFEM P{prob['degree']} on {prob['scene']} refine {prob['refine']}: "
                           f"{proc.stderr.strip()[-600:]}")
    return json.loads(pout.read_text())


def tresca_reads(binary, path):
    """Whether this tresca-cr binary accepts the scene (``tresca-cr check``), with its message if not."""
    proc = subprocess.run([str(binary), "check", str(path)], capture_output=True, text=True)
    return proc.returncode == 0, (proc.stderr or proc.stdout).strip().splitlines()[-1:] or [""]


def _levels(sc: Scene, code, work, cache):
    """(refine, problem dict, scene path for tresca-cr) per level of a code; mesh levels generated once."""
    k = 1 if code == "getfem-P1" else 2
    for r in sc.levels_of(code):
        if sc.mesh_levels is None:
            if "" not in cache:
                cache[""] = problem.load(sc.path)
            yield r, problem.at_level(cache[""], r, sc.steps, degree=k), sc.path, r
            continue
        if r not in cache:
            path, h = sc.mesh_levels(work, r)
            cache[r] = (problem.load(path), path, h)
        scene, path, h = cache[r]
        prob = problem.at_level(scene, 0, sc.steps, degree=k)
        prob["h"], prob["refine"] = h, r  # the level's nominal size (``hertz``); the level names GetFEM's files
        yield r, prob, path, 0


def solve_level(code, prob, work, binary, path, refine, steps, level):
    """The raw result of one code on one level's problem (``level``: the row's level, names tresca-cr's file)."""
    if code.startswith("getfem"):
        return run_getfem(prob, work)
    if code == "skfem-P2-nitsche":
        return skfem_nitsche.solve(prob, skfem_signorini.SignoriniSolver if unilateral(prob) else skfem_nitsche.Solver)
    if code == "skfem-TH-nitsche":
        return skfem_nitsche.solve(prob, skfem_mixed.MixedSolver)
    pts = np.asarray(prob["points"])
    contact = next(p for p in prob["parts"] if p["kind"] == "contact")
    symmetric = any(p["kind"] == "symmetry" for p in prob["parts"])  # its edges are among tresca-cr's contact edges
    mids = pts[np.asarray(contact["segments"])].mean(axis=1) if symmetric else None
    return tresca.run_level(binary, path, refine, steps, work, prob["probes"],
                            prob["gamma_n"] * (prob["lam"] + 2 * prob["mu"]), mids, f"tresca_{level}")


def run_scene(sc: Scene, codes, out_dir, binary, log=print):
    """Rows (dicts) for one scene: code, level, h, dofs, wall, quantities, errors; and notes on skipped codes."""
    work = Path(out_dir) / sc.name
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    rows, notes, cache = [], [], {}
    use_tresca = "tresca-cr" in codes
    if use_tresca:
        ok, msg = tresca_reads(binary, sc.path)
        if not ok:
            use_tresca = False
            notes.append(f"tresca-cr: this binary cannot read the scene yet ({msg[0]}); its column stays empty")
    use_getfem = any(c.startswith("getfem") for c in codes)
    if use_getfem and not getfem_available():
        raise RuntimeError(f"{GETFEM_PYTHON} cannot import getfem: run `make getfem`")
    for code in (c for c in codes if c in sc.codes):
        if code == "tresca-cr" and not use_tresca:
            continue
        for r, prob, path, refine in _levels(sc, code, work, cache):
            prob["mixed"] = "-TH" in code
            t0 = time.perf_counter()
            raw = solve_level(code, prob, work, binary, path, refine, sc.steps, f"r{r}")
            raw["h"] = prob["h"]
            row = quantities.summarise(raw, prob["probes"])
            row.update({"scene": sc.name, "code": code, "refine": r, "steps": sc.steps,
                        "process_s": time.perf_counter() - t0})
            rows.append(row)
            log(f"  {sc.name:12s} {code:17s} refine {r:2d}  dofs {row['dofs']:7d}  wall {row['wall_s']:7.3f} s  "
                f"H1 {row['h1_norm']:.6e}" + (f"  err_H1 {row['err_h1_semi']:.3e}" if "err_h1_semi" in row else ""),
                flush=True)
    if use_tresca and sc.mesh_levels is None:
        tresca.study_csv(binary, sc.path, sc.levels, sc.steps, work / "tresca_study.csv")
    return rows, notes
