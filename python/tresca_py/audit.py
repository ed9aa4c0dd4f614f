"""The per-step energy audit of a run, as ``src/stepping/audit.rs`` writes it under ``/tresca/steps``.

Taking v = uⁿ⁻¹ and v = 2uⁿ − uⁿ⁻¹ in the step's variational inequality gives, with δuⁿ = uⁿ − uⁿ⁻¹,

    a_h(uⁿ, δuⁿ) + j_h(δuⁿ) = (lⁿ, δuⁿ) + W_Γⁿ,

and a_h(uⁿ, δuⁿ) = ½a_h(uⁿ,uⁿ) − ½a_h(uⁿ⁻¹,uⁿ⁻¹) + ½a_h(δuⁿ,δuⁿ). The file holds per step
``external_work`` (lⁿ, δuⁿ), ``boundary_work`` W_Γⁿ (the reactions' work on imposed data, 0 without it),
``stored_energy`` ½a_h(uⁿ,uⁿ), ``friction_dissipation`` j_h(δuⁿ), ``euler_dissipation`` ½a_h(δuⁿ,δuⁿ) and
``balance_residual`` = ΔE + D + j − W − W_Γ. A wrong slip direction or friction force breaks the balance
(the Rust test ``tests/library/energy_audit.rs`` shows it can fail).

Checks, each with its reason:
* the stored residual is the residual of the stored terms (1e-12 of the largest term: sums of a few f64
  numbers of that size);
* |residual| ≤ (``BALANCE_REL`` + :func:`rounding`) × the largest work of a step: the balance is exact for the
  exact step solution; the solver stops at a natural residual ``tol`` (1e-12 in every scene of
  verification/) relative to the step's forces, which 1e-9 bounds; the rounding of the direct solve grows
  with the unknowns and with λ/μ, and j_h multiplies the rounding of stuck slips by g_a (:func:`rounding`:
  1.9e-9 and 7.7e-9 measured on the λ/μ = 10⁴ scene cep at 6 048 and 24 384 unknowns, 3.8e-2 with
  g_a = 10¹² on Example 5.1, where 1e-9 alone failed);
* j_h(δuⁿ) ≥ 0 and ½a_h(δuⁿ,δuⁿ) ≥ 0 (down to rounding of the work scale), and step 0 has no work.
"""
import h5py
import numpy as np

from .results import ResultsError

SERIES = ("external_work", "boundary_work", "stored_energy", "friction_dissipation", "euler_dissipation",
          "balance_residual")
BALANCE_REL = 1e-9
IDENTITY_REL = 1e-12
#: the unit roundoff of f64
EPS = 2.0 ** -53


def read(path, completed):
    """{name: the first ``completed`` values} of the audit series, or None for a file without them (a run of
    an older version or of the Python solvers); ResultsError for a series that is not a 1-D numeric dataset
    of at least ``completed`` values (a group, strings, 2-D, short)."""
    with h5py.File(path, "r") as f:
        g = f["tresca/steps"]
        if not all(k in g for k in SERIES):
            return None
        return {k: _series(path, g, k, completed) for k in SERIES}


def _series(path, g, k, completed):
    """The first ``completed`` values of the audit series ``k`` of the group ``g``, checked (see ``read``)."""
    ds = g.get(k)
    where = f"{path}: tresca/steps/{k}"
    if not isinstance(ds, h5py.Dataset):
        raise ResultsError(f"{where} is {type(ds).__name__.lower()}, not a dataset of the energy audit")
    if ds.dtype.kind not in "fiu":
        raise ResultsError(f"{where} holds {ds.dtype} values, the energy audit wants numbers (float64)")
    if ds.ndim != 1 or ds.shape[0] < completed:
        raise ResultsError(f"{where} has shape {ds.shape}, the energy audit wants one value for each of the "
                           f"{completed} completed steps")
    return np.asarray(ds[:completed], dtype=float)


def rounding(path, scale):
    """The rounding allowance of the balance relative to ``scale`` (the largest work of a step): the solve's
    term γ_N (λ+2μ)/μ plus the friction term 4ε max|u| Σ_e ḡ_e|e| / scale; 0 for a file without the
    attributes and datasets these need.

    Solve: γ_N = Nε/(1 − Nε) (Higham's constant for sums of N terms), N the run's unknowns (``n_dofs``),
    (λ+2μ)/μ = 2(1−ν)/(1−2ν) in plane strain. The direct solve is backward stable, so each step's equations
    hold up to a residual r with |r| ≤ γ |K||u|, and the balance residual is r·δu, bounded by
    γ_N |δu|ᵀ|K||u|; the absolute form exceeds the work by the ratio of the largest stiffness, the bulk
    term's (λ+2μ), to the shear modulus μ that the work of a nearly divergence-free field carries. Measured
    on cep (λ/μ = 10⁴, Dirichlet data on three sides): 2.1e-11, 1.0e-10, 4.6e-10, 1.9e-9, 7.7e-9 at
    84–24 384 unknowns (×4 per refinement, as N), against allowances 9.3e-11 … 2.7e-8; 10× smaller λ gave
    ≈ 50× smaller residuals at 6 048 unknowns.

    Friction: j_h(δu) = Σ_e ḡ_e|e| |δu_τ,e| is evaluated on stored values whose stick components are zero
    only to the rounding of u (each of uⁿ, uⁿ⁻¹ within 2ε max|u|), which j_h multiplies by the bound:
    with g_a = 10⁶ and 10¹² on Example 5.1 (stability's case) the residual was 4e-8 and 3.8e-2 of the
    work, against allowances 3.8e-7 and 0.37 (the balance cannot resolve more than ε |u| ∫g_a there)."""
    with h5py.File(path, "r") as f:
        g = f["tresca"]
        if "n_dofs" not in g.attrs or "nu" not in g.attrs:
            return 0.0
        n, nu = int(g.attrs["n_dofs"]), float(g.attrs["nu"])
        friction = 0.0
        if scale > 0 and all(k in g for k in ("u", "contact/g", "contact/edges", "mesh/edges", "mesh/points")):
            ends = g["mesh/points"][:][g["mesh/edges"][:][g["contact/edges"][:]]]
            bound = float(np.sum(np.abs(g["contact/g"][:]) * np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)))
            friction = 4.0 * EPS * float(np.max(np.abs(g["u"][:]))) * bound / scale
    gamma = n * EPS / (1.0 - n * EPS)
    return gamma * 2.0 * (1.0 - nu) / (1.0 - 2.0 * nu) + friction


def largest_work(a):
    """The largest work of a step, |(lⁿ,δuⁿ)| + |W_Γⁿ| + j_h(δuⁿ): the scale of the balance."""
    return float(np.max(np.abs(a["external_work"]) + np.abs(a["boundary_work"]) + a["friction_dissipation"]))


def problems(a, allowance=0.0):
    """The audit's violations as messages (empty when the balance holds); ``allowance``: the run's
    :func:`rounding`, added to ``BALANCE_REL`` and to ``IDENTITY_REL``: the stored residual is formed from
    matrix-free sums over the unknowns (a_h(uⁿ,δuⁿ), src/stepping/audit.rs), the identity here from the stored
    energies, and the two differ by the rounding of those sums, which grows like N ε (observed: 2.9e-12 of
    the terms at 49,280 unknowns, coulomb_block refine 5)."""
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
    if err > (IDENTITY_REL + allowance) * terms:
        out.append(f"energy audit: balance_residual differs from ΔE + D + j − W − W_Γ by {err:.3e} "
                   f"(terms up to {terms:.3e})")
    res = float(np.max(np.abs(a["balance_residual"])))
    bound = BALANCE_REL + allowance
    if scale > 0 and res > bound * scale:
        n = int(np.argmax(np.abs(a["balance_residual"])))
        out.append(f"energy audit: the balance fails at step {n}: |residual| {res:.3e} > {bound:.3g} × the "
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
