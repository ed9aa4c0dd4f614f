"""Backward Euler over a scene's time nodes with the exact friction step, and the results file."""
import math
import os
import time

import numpy as np

from tresca_py.common import git_commit
from tresca_py.errors import InputError
from tresca_py.skfem_cr.cr import Discretisation
from tresca_py.skfem_cr.friction import StepSolver, classify
from tresca_py.skfem_cr.floating import FloatingStepSolver
from tresca_py.skfem_cr.unilateral import UnilateralStepSolver, initial_state



def step_solver(disc, K):
    """The step solver of ``disc``: a floating body's (no Dirichlet part), with normal unknowns, or bilateral."""
    if len(disc.dirichlet) == 0:
        return FloatingStepSolver(disc, K)
    return UnilateralStepSolver(disc, K) if disc.normal_unknowns else StepSolver(disc, K)

def run(disc: Discretisation, K, load, errors=None, log=True, lifting=None):
    """Backward Euler over ``scene.times`` with the exact friction step (``friction.StepSolver``); returns the
    results dict.

    ``K``: canonical sparse a_h. ``load(t)``: the canonical load vector. ``errors(t, u)``: (energy error^2,
    h1^2, l2^2), the energy error including the jump terms (2 rho mu/h_e) int_e |[u_h]|^2 computed by the
    framework as an integral of squares (u^T J u would lose sqrt(eps) accuracy when the jumps vanish).
    ``lifting``: the boundary data's ``SkfemLifting`` (None without data): u = w + u_L, w solving the step with
    the load lⁿ + b_D(tₙ) − K u_Lⁿ (``tresca_py.skfem_cr.lifting``).
    """
    scene = disc.scene
    times = scene.times
    N = len(times) - 1
    C = len(disc.contact)
    t0 = time.perf_counter()
    stepper = step_solver(disc, K)
    res = dict(u=np.zeros((N + 1, len(disc.edges), 2)), slip=np.zeros((N + 1, C)), mu=np.zeros((N + 1, C)),
               dof=np.zeros((N + 1, C)), sigma_t=np.zeros((N + 1, C)), state=np.zeros((N + 1, C), dtype=np.int8),
               iterations=np.zeros(N + 1, dtype=np.int64), residual=np.zeros(N + 1),
               n_stick=np.zeros(N + 1, dtype=np.int64), n_slip=np.zeros(N + 1, dtype=np.int64),
               wall_time=np.zeros(N + 1), energy=np.zeros(N + 1), factor_time=time.perf_counter() - t0)
    if errors is not None:
        res["errors"] = {k: np.zeros(N + 1) for k in ("energy", "h1", "l2")}
    if disc.normal_unknowns:
        res["pressure"], res["gap"] = np.zeros((N + 1, C)), np.zeros((N + 1, C))
        res["status"] = np.zeros((N + 1, C), dtype=np.uint8)
    u = disc.interpolate(scene.u0, times[0])
    if lifting is not None:
        u = u + lifting.lift(times[0])
    if disc.normal_unknowns:
        res["gap"][0], res["status"][0] = initial_state(disc, u, times[0])
    for n, t in enumerate(times):
        tic = time.perf_counter()
        if n > 0:
            try:                                    # a load or data expression not finite at step n
                u = _step(stepper, disc, K, load(t), u, lifting, t, res, n)
            except InputError as err:
                raise InputError(f"step {n} (t = {t:.6g}): {err}") from None
        res["u"][n] = u.reshape(-1, 2)
        res["slip"][n] = np.sum(u.reshape(-1, 2)[disc.contact] * disc.tangent, axis=1)
        if n == 0:
            res["dof"][n] = res["slip"][n]          # u^0 = I_CR u0 holds s_e tau_e on contact edges
        res["n_slip"][n] = int(res["state"][n].sum())
        res["n_stick"][n] = C - res["n_slip"][n]
        res["energy"][n] = float(u @ (K @ u)) if lifting is None else lifting.energy(K, u, t)
        if errors is not None:
            for key, e2 in zip(("energy", "h1", "l2"), errors(t, u), strict=True):
                res["errors"][key][n] = math.sqrt(max(e2, 0.0))
        res["wall_time"][n] = time.perf_counter() - tic
        if log and (n == N or (N >= 10 and n % max(1, N // 10) == 0)):
            extra = f" err_E={res['errors']['energy'][n]:.4e}" if "errors" in res else ""
            print(f"step {n:5d}/{N} t={t:.6g} iters={res['iterations'][n]} "
                  f"slip={res['n_slip'][n]}/{C} a_h(u,u)={res['energy'][n]:.6e}{extra}", flush=True)
    return res


def _step(stepper, disc, K, load_t, u_prev, lifting, t, res, n):
    """Step n: the friction step (on w = u − u_L with data), its contact data stored in ``res``; returns uⁿ."""
    if disc.normal_unknowns:                        # the gap is a constraint (not lifted): u_L is zero on Γ_C
        u_l = 0.0 if lifting is None else lifting.lift(t)
        w, info = stepper.step(load_t if lifting is None else load_t + lifting.rhs(t) - K @ u_l, u_prev, t)
        u = w + u_l
        res["pressure"][n], res["gap"][n], res["status"][n] = info["pressure"], info["gap"], info["status"]
    elif lifting is None:
        u, info = stepper.step(load_t, u_prev)
    else:
        u_l = lifting.lift(t)
        w, info = stepper.step(load_t + lifting.rhs(t) - K @ u_l, u_prev)
        u = w + u_l
    mu = info["mu"]
    res["sigma_t"][n] = -mu / disc.lengths[disc.contact]
    res["mu"][n] = mu
    res["dof"][n] = info["dof"]
    res["state"][n] = info["state"] if "state" in info else classify(mu, info["ds"], info["d"], disc.weight)
    res["iterations"][n] = info["iterations"]
    res["residual"][n] = info["residual"]
    return u


# ----------------------------------------------------------------------------------------------
# output
# ----------------------------------------------------------------------------------------------
def write_results(path, disc: Discretisation, res, solver_name, extra_attrs=None):
    """Write the run as a results file of the one ``/tresca`` layout (``tresca_py.results.write``: atomic,
    with status, completed steps and step checksums; ``contact/mu`` = the friction force mu_e and
    ``contact/dof`` = the contact unknown s_e of the reduced vector r; no contact group without Gamma_C)."""
    from tresca_py import results
    scene = disc.scene
    contact = None
    if len(disc.contact):
        contact = results.Contact(disc.contact, disc.normal, disc.tangent, disc.gbar, res["slip"], res["sigma_t"],
                                  res["state"], res["mu"], res["dof"], res.get("pressure"), res.get("gap"),
                                  res.get("status"))
    r = results.Results(
        mesh=results.Mesh(disc.points, disc.triangles, disc.edges, disc.midpoints), times=scene.times,
        u=res["u"], energy=res["energy"], steps={k: res[k] for k in results.STEP_FIELDS}, contact=contact,
        errors=res.get("errors"),
        attrs={"scene": scene.text, "scene_path": os.path.abspath(scene.path), "title": scene.title,
               "version": "python-2", "git_commit": git_commit(), "solver": solver_name,
               "method": "primal active set on the condensed dual (exact)",
               "tol": float(scene.solver.get("tol", 1e-12)), "rho": scene.rho, "E": scene.E, "nu": scene.nu,
               "refine": int(scene.mesh["refine"]), "steps": len(scene.times) - 1,
               "factor_time": float(res.get("factor_time", 0.0)), **(extra_attrs or {})})
    results.write(path, r)
