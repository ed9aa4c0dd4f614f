"""The per-step energy audit of a run, as ``src/stepping/audit.rs`` writes it under ``/tresca/steps``.

Taking v = uⁿ⁻¹ and v = 2uⁿ − uⁿ⁻¹ in the step's variational inequality gives, with δuⁿ = uⁿ − uⁿ⁻¹,

    a_h(uⁿ, δuⁿ) + j_h(δuⁿ) = (lⁿ, δuⁿ) + W_Γⁿ,

and a_h(uⁿ, δuⁿ) = ½a_h(uⁿ,uⁿ) − ½a_h(uⁿ⁻¹,uⁿ⁻¹) + ½a_h(δuⁿ,δuⁿ). The file holds per step
``external_work`` (lⁿ, δuⁿ), ``boundary_work`` W_Γⁿ (the reactions' work on imposed data, 0 without it),
``stored_energy`` ½a_h(uⁿ,uⁿ), ``friction_dissipation`` j_h(δuⁿ), ``euler_dissipation`` ½a_h(δuⁿ,δuⁿ) and
``balance_residual`` = ΔE + D + j − W − W_Γ. A wrong slip direction or friction force breaks the balance
(the Rust test ``tests/energy_audit.rs`` shows it can fail).

Checks, each with its reason:
* the stored residual is the residual of the stored terms (1e-12 of the largest term: sums of a few f64
  numbers of that size);
* |residual| ≤ ``BALANCE_REL`` × the largest work of a step: the balance is exact for the exact step solution;
  the solver stops at a natural residual ``tol`` (1e-12 in every scene of verification/) relative to the
  step's forces, and a_h is evaluated in f64 with a relative rounding of cond(K)·ε ≈ 1e-16·1e6 on the
  near-incompressible scenes (measured 2e-11); 1e-9 bounds both, 10⁴× above the largest observed;
* j_h(δuⁿ) ≥ 0 and ½a_h(δuⁿ,δuⁿ) ≥ 0 (down to rounding of the work scale), and step 0 has no work.
"""
import h5py
import numpy as np

SERIES = ("external_work", "boundary_work", "stored_energy", "friction_dissipation", "euler_dissipation",
          "balance_residual")
BALANCE_REL = 1e-9
IDENTITY_REL = 1e-12


def read(path, completed):
    """{name: the first ``completed`` values} of the audit series, or None for a file without them (a run of
    an older version or of the Python solvers)."""
    with h5py.File(path, "r") as f:
        g = f["tresca/steps"]
        if not all(k in g for k in SERIES):
            return None
        return {k: np.asarray(g[k][:completed], dtype=float) for k in SERIES}


def largest_work(a):
    """The largest work of a step, |(lⁿ,δuⁿ)| + |W_Γⁿ| + j_h(δuⁿ): the scale of the balance."""
    return float(np.max(np.abs(a["external_work"]) + np.abs(a["boundary_work"]) + a["friction_dissipation"]))


def problems(a):
    """The audit's violations as messages (empty when the balance holds)."""
    out = []
    if any(not np.all(np.isfinite(v)) for v in a.values()):
        return ["energy audit: a series holds NaN or Inf"]
    if len(a["stored_energy"]) < 2:
        return out
    scale = largest_work(a)
    terms = max(scale, float(np.max(np.abs(a["stored_energy"]))))
    ident = (np.diff(a["stored_energy"]) + a["euler_dissipation"][1:] + a["friction_dissipation"][1:]
             - a["external_work"][1:] - a["boundary_work"][1:])
    err = float(np.max(np.abs(ident - a["balance_residual"][1:])))
    if err > IDENTITY_REL * terms:
        out.append(f"energy audit: balance_residual differs from ΔE + D + j − W − W_Γ by {err:.3e} "
                   f"(terms up to {terms:.3e})")
    res = float(np.max(np.abs(a["balance_residual"])))
    if scale > 0 and res > BALANCE_REL * scale:
        n = int(np.argmax(np.abs(a["balance_residual"])))
        out.append(f"energy audit: the balance fails at step {n}: |residual| {res:.3e} > {BALANCE_REL:g} × the "
                   f"largest work of a step {scale:.3e}")
    for k in ("friction_dissipation", "euler_dissipation"):
        if float(np.min(a[k])) < -IDENTITY_REL * terms:
            out.append(f"energy audit: {k} is negative ({float(np.min(a[k])):.3e})")
    first = [k for k in SERIES if k != "stored_energy" and a[k][0] != 0.0]
    if first:
        out.append(f"energy audit: step 0 has nonzero {', '.join(first)}")
    return out


def summary(a):
    """One line: the largest |residual| against the largest work of a step."""
    res, scale = float(np.max(np.abs(a["balance_residual"]))), largest_work(a)
    rel = res / scale if scale > 0 else 0.0
    return f"energy balance: max |residual| {res:.2e} ({rel:.1e} of the largest work of a step)"
