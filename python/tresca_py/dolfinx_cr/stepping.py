"""The dolfinx re-implementation's backward-Euler loop and its results file (no code shared with the scikit-fem
one; what the two share is listed in verification/README.md).

Step n: with the boundary data's lifting u_Lⁿ (``CrEdges.lifting``; zero without data) the unknown part w of
uⁿ = wⁿ + u_Lⁿ solves the friction step (``TaoStepSolver``) with the load

    lⁿ + b_D(tₙ) − K u_Lⁿ,   b_D(t; v) = Σ_{e ⊂ Γ_D} (2ρμ/h_e) ∫_e u_D(t)·v   (3-point Gauss),

the stabilisation's jump on Γ_D being measured against u_D. The energy written is a_h(u,u) without data and
a_h(u,u) − 2b_D(u) + c(t) with them (the Dirichlet jump u − u_D; c(t) = Σ (2ρμ/h_e) ∫_e |u_D|²). An edge of Γ_C
slips when its friction force is at the bound, |μ_e| ≥ w_e(1 − 1e-9), and its slip increment is not rounding,
|Δs_e| > 1e-9 max(‖Δs‖∞, ‖d‖∞): the rule of the Rust solver (``friction::classify``), so the stick/slip sets
of the three codes can be compared exactly.
"""
import math
import os
import time

import numpy as np

from tresca_py import results
from tresca_py.common import git_commit
from tresca_py.dolfinx_cr.unilateral import SEPARATED, initial_state
from tresca_py.errors import InputError

#: the two 1e-9 of the stick/slip rule (module docstring): a force within 1e-9 of the bound is at it, an
#: increment below 1e-9 of the step's largest increment is rounding
AT_BOUND, MOVED = 1e-9, 1e-9


def slipping(mu, ds, d, w):
    """The stick/slip rule of the module docstring, True = slip."""
    if mu.size == 0:
        return np.zeros(0, dtype=bool)
    floor = MOVED * max(np.abs(ds).max(), np.abs(d).max())
    return np.logical_and(np.abs(mu) >= (1.0 - AT_BOUND) * w, np.abs(ds) > floor)


class Series:
    """The per-step arrays of a run (rank 0)."""

    def __init__(self, edges, n_times, with_errors):
        nc = len(edges.contact)
        self.u = np.zeros((n_times, len(edges.edges), 2))
        normal = ("pressure", "gap") if edges.normal_unknowns else ()
        self.contact = {k: np.zeros((n_times, nc)) for k in ("slip", "sigma_t", "mu", "dof") + normal}
        self.state = np.zeros((n_times, nc), dtype=np.int8)
        self.status = np.zeros((n_times, nc), dtype=np.uint8) if edges.normal_unknowns else None
        self.steps = {"iterations": np.zeros(n_times, dtype=np.int64), "residual": np.zeros(n_times),
                      "n_stick": np.zeros(n_times, dtype=np.int64), "n_slip": np.zeros(n_times, dtype=np.int64),
                      "wall_time": np.zeros(n_times)}
        self.energy = np.zeros(n_times)
        self.errors = {k: np.zeros(n_times) for k in ("energy", "h1", "l2")} if with_errors else None
        self.factor_time = 0.0


def _record(series, edges, n, u, info):
    """Store step n's displacement u (full) and, after step 0, the friction step's ``info``."""
    series.u[n] = u.reshape(-1, 2)
    s = np.einsum("ec,ec->e", series.u[n][edges.contact], edges.tangent)
    series.contact["slip"][n] = s
    if info is None:
        series.contact["dof"][n] = s
        return
    slip = slipping(info["mu"], info["ds"], info["d"], edges.weight)
    series.state[n] = slip
    if series.status is not None:
        series.status[n] = np.where(info["separated"], SEPARATED, slip)
        series.contact["pressure"][n], series.contact["gap"][n] = info["pressure"], info["gap"]
    series.contact["mu"][n] = info["mu"]
    series.contact["sigma_t"][n] = -info["mu"] / edges.lengths[edges.contact]
    series.contact["dof"][n] = info["dof"]
    series.steps["iterations"][n], series.steps["residual"][n] = info["iterations"], info["residual"]
    series.steps["n_slip"][n] = int(slip.sum())


def backward_euler(edges, prob, stepper_class, comm, log):
    """Backward Euler over the scene's time nodes (collective); the ``Series`` on rank 0, None elsewhere."""
    scene, root = edges.scene, comm.rank == 0
    times, K = scene.times, prob.K
    data = scene.has_boundary_data
    series = Series(edges, len(times), scene.exact_u is not None) if root else None
    stepper = u = None
    if root:
        tic = time.perf_counter()
        stepper = stepper_class(edges, K)
        series.factor_time = time.perf_counter() - tic
    for n, t in enumerate(times):
        tic = time.perf_counter()
        try:
            load = prob.load(t) if n else None
            b_d = prob.data_vector(t) if data else None
            u_l = edges.lifting(t) if data else None      # on every rank: a bad `gap` stops them all
        except InputError as err:
            raise InputError(f"step {n} (t = {t:.6g}): {err}") from None
        c_d = prob.data_norm(t) if data else 0.0
        if root:
            if n == 0:
                u, info = edges.interpolate(scene.u0, t), None
                if series.status is not None:
                    series.contact["gap"][0], series.status[0] = initial_state(edges, u, t)
            else:
                rhs = load if u_l is None else load + b_d - K @ u_l
                u, info = stepper.step(rhs, u, t)
            if u_l is not None:
                u = u + u_l
            _record(series, edges, n, u, info)
            series.steps["n_stick"][n] = len(edges.contact) - series.steps["n_slip"][n]
            au = float(u @ (K @ u))
            series.energy[n] = au if b_d is None else au - 2.0 * float(b_d @ u) + c_d
        _errors(prob, comm, series, n, t, u)
        if root:
            series.steps["wall_time"][n] = time.perf_counter() - tic
            _log(log, series, edges, n, len(times) - 1, t)
    return series


def _errors(prob, comm, series, n, t, u):
    """The true errors of step n (collective; the scene has [exact] on every rank or on none)."""
    if prob.err_forms is None:
        return
    e = prob.errors(t, comm.bcast(u, root=0))
    if series is not None:
        for k, v in zip(("energy", "h1", "l2"), e, strict=True):
            series.errors[k][n] = math.sqrt(max(v, 0.0))


def _log(log, series, edges, n, N, t):
    if log and (n == N or (N >= 10 and n % max(1, N // 10) == 0)):
        err = "" if series.errors is None else f" err_E={series.errors['energy'][n]:.4e}"
        print(f"step {n:5d}/{N} t={t:.6g} iters={series.steps['iterations'][n]} "
              f"slip={series.steps['n_slip'][n]}/{len(edges.contact)} a_h(u,u)={series.energy[n]:.6e}{err}",
              flush=True)


def save(path, edges, series, attrs):
    """The run as a results file of the ``/tresca`` layout (``tresca_py.results.write``)."""
    scene = edges.scene
    contact = None
    if len(edges.contact):
        c = series.contact
        contact = results.Contact(edges.contact, edges.normal, edges.tangent, edges.gbar, c["slip"], c["sigma_t"],
                                  series.state, c["mu"], c["dof"], c.get("pressure"), c.get("gap"), series.status)
    mesh = results.Mesh(edges.points, edges.triangles, edges.edges, edges.midpoints)
    base = {"scene": scene.text, "scene_path": os.path.abspath(scene.path), "title": scene.title,
            "version": "python-2", "git_commit": git_commit(), "solver": "dolfinx",
            "tol": float(scene.solver.get("tol", 1e-12)), "rho": scene.rho, "E": scene.E, "nu": scene.nu,
            "refine": int(scene.mesh["refine"]), "steps": len(scene.times) - 1,
            "factor_time": float(series.factor_time)}
    results.write(path, results.Results(mesh=mesh, times=scene.times, u=series.u, energy=series.energy,
                                        steps=series.steps, contact=contact, errors=series.errors,
                                        attrs={**base, **attrs}))
