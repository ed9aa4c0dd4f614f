"""The energy audit recomputed from the stored fields, so that an audit edited in a results file is found even
when its checksums were recomputed: what the file allows of ``src/stepping/audit.rs``'s terms.

* ``friction_dissipation`` j_h(δuⁿ) = Σ_{e ⊂ Γ_C} |e| ḡ_e |sⁿ_e − sⁿ⁻¹_e| from ``contact/g``, ``contact/slip`` and the
  mesh (every run with Γ_C); on a Coulomb edge (``contact/coulomb`` not NaN) F̄_e |Pⁿ_e| in place of |e| ḡ_e, from
  ``contact/force``;
* ``boundary_work`` W_Γ: in a scene without boundary data (no ``u`` or ``gap`` key in its parts), where the file
  does not hold the loads that the external work needs, exactly 0, or with normal unknowns (a unilateral or
  Coulomb part) the work of the contact reaction, −Σ_e Pⁿ_e δuⁿ(m_e)·n_e, from ``contact/force``, ``u`` and
  ``contact/normal`` (``contact_work``);
* ``stored_energy`` Eⁿ = ½a_h(uⁿ, uⁿ) and ``euler_dissipation`` ½a_h(δuⁿ, δuⁿ) from ``u``, the mesh, E, ν and ρ:
  a_h(U, U) = Σ_T |T| σ(∇U):∇U + 2ρμ Σ_{e interior ∪ Γ_D} |J_e|²/3, where J_e is the jump of U at an end of e
  (on a Dirichlet edge the trace: the jump is linear along e and vanishes at its midpoint, so its mean square is
  |J_e|²/3, what the 2-point Gauss rule of ``src/fem/forms.rs`` gives). The Dirichlet edges are not stored; without
  Dirichlet data (no ``u`` key in the scene's dirichlet parts) they are the boundary edges off Γ_C whose ``u`` is
  exactly zero at every step, and their number is known from ``n_dofs`` = 2(E − D − C) + C (+ C with normal
  unknowns, one on every Γ_C edge then): when the two agree the
  set is exactly Γ_D (every Dirichlet edge is zero, so the zero edges include it, and there are no more of them).
  Otherwise (Dirichlet data, or a Neumann edge that stayed zero) the energy is not recomputed, and ``recompute``
  says so.

Tolerances, each a rounding bound of the two evaluations (the file's and this one) of the same sum of
nonnegative terms: the summation order, N ε of the sum (N terms: Higham's γ_N); each term's own rounding, a
few roundings of its factors (16 ε of the term); and the gradients, computed here from vertex values and there
from midpoint values, whose entries differ by the rounding of sums of three U's times |∇φ| (and of ∇φ from the
coordinates, relative ε |x|/h): their error on a term is bounded by ``magnitude`` below times 16 ε.
"""
import tomllib

import numpy as np

from tresca_py.elastic import lame
from tresca_py.fields import basis_gradients, vertex_values

EPS = np.finfo(float).eps
#: roundings of a term's factors and of its gradient entries (module docstring)
TERM_ROUNDINGS = 16.0


def friction(r):
    """j_h(δuⁿ) per step (0 at step 0) and its rounding bound, or None without Γ_C."""
    ct, m = r.contact, r.mesh
    if ct is None:
        return None
    ends = m.points[m.edges[ct.edges]]
    w = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1) * ct.g
    w = np.broadcast_to(w, ct.slip[1:].shape)
    if ct.coulomb is not None and ct.force is not None:
        cou = ~np.isnan(ct.coulomb)
        w = np.where(cou, np.nan_to_num(ct.coulomb) * np.abs(ct.force[1:]), w)
    terms = np.abs(np.diff(ct.slip, axis=0)) * w
    j = np.concatenate([[0.0], terms.sum(axis=1)])
    return j, (ct.slip.shape[1] + TERM_ROUNDINGS) * EPS * j


def contact_work(r):
    """W_Γ per step of a scene without boundary data (0 at step 0) and its rounding bound: −Σ_e Pⁿ_e δuⁿ(m_e)·n_e
    with normal unknowns, else exact zeros."""
    ct, n1 = r.contact, len(r.times)
    if ct is None or ct.force is None:
        return np.zeros(n1), np.zeros(n1)
    du = np.diff(r.u[:, ct.edges], axis=0)                      # (N, C, 2)
    terms = ct.force[1:, :, None] * du * ct.normal[None]
    w = np.concatenate([[0.0], -terms.sum(axis=(1, 2))])
    mag = np.concatenate([[0.0], np.abs(terms).sum(axis=(1, 2))])
    return w, (2 * ct.force.shape[1] + TERM_ROUNDINGS) * EPS * mag


def _parts(r):
    """The scene's ``[[boundary]]`` tables as stored in the file, or None when they cannot be read."""
    try:
        parts = tomllib.loads(r.attrs.get("scene", "")).get("boundary", [])
    except tomllib.TOMLDecodeError:
        return None
    return [p for p in parts if isinstance(p, dict)] if isinstance(parts, list) else None


def has_data(parts, kind, key):
    """True if a part of ``kind`` gives ``key`` (``u`` of a dirichlet part, ``gap`` of a contact part)."""
    return any(p.get("kind") == kind and key in p for p in parts)


def dirichlet_edges(r):
    """The Dirichlet edges (module docstring), or a sentence saying why they cannot be told from the file."""
    parts = _parts(r)
    if parts is None:
        return "the scene stored in the file cannot be read"
    if has_data(parts, "dirichlet", "u"):
        return "the scene imposes Dirichlet data, whose values along Γ_D the file does not hold"
    if "n_dofs" not in r.attrs:
        return "the file has no n_dofs"
    te = r.mesh.triangle_edges()
    E, C = len(r.mesh.edges), 0 if r.contact is None else len(r.contact.edges)
    count = np.bincount(te.ravel(), minlength=E)
    off = (count == 1)
    if C:
        off[r.contact.edges] = False
    zero = off & np.all(r.u == 0.0, axis=(0, 2))
    normal = C if r.contact is not None and r.contact.force is not None else 0    # one normal unknown an edge
    d = E - C - (int(r.attrs["n_dofs"]) - C - normal) // 2
    if int(zero.sum()) != d:
        return f"{int(zero.sum())} boundary edges off Γ_C stay zero, but the run had {d} Dirichlet edges"
    return np.flatnonzero(zero)


def _traces(r):
    """For every (triangle, local edge i): the edge, and the local vertex of its end with the lower index."""
    te, tri = r.mesh.triangle_edges(), r.mesh.triangles
    i = np.arange(3)
    a, b = tri[:, (i + 1) % 3], tri[:, (i + 2) % 3]
    end = np.where(a < b, (i + 1) % 3, (i + 2) % 3)
    return te, end


def energy(r, U, jumped):
    """½a_h(U, U) of the midpoint fields U (S, E, 2) with the jump term on the edges ``jumped`` (bool, E), and the
    magnitude of its rounding (module docstring), each (S,)."""
    m = r.mesh
    lam, mu = lame(float(r.attrs["E"]), float(r.attrs["nu"]))
    pen = 2.0 * float(r.attrs["rho"]) * mu
    te, end = _traces(r)
    gl = basis_gradients(m.points, m.triangles)
    x = m.points[m.triangles]
    area = 0.5 * np.abs((x[:, 1, 0] - x[:, 0, 0]) * (x[:, 2, 1] - x[:, 0, 1])
                        - (x[:, 1, 1] - x[:, 0, 1]) * (x[:, 2, 0] - x[:, 0, 0]))
    cond = 1.0 + np.max(np.abs(x), axis=(1, 2)) * np.max(np.linalg.norm(gl, axis=2), axis=1)
    disp = vertex_values(U, te)
    G = np.einsum("stja,tjb->stab", disp, gl)
    eps = 0.5 * (G + np.swapaxes(G, 2, 3))
    tr = eps[..., 0, 0] + eps[..., 1, 1]
    dens = lam * tr ** 2 + 2.0 * mu * np.sum(eps * eps, axis=(2, 3))
    Umag = np.linalg.norm(U[:, te, :], axis=3)
    gmag = 2.0 * np.einsum("sti,ti->st", Umag, np.linalg.norm(gl, axis=2)) * cond
    mag = np.sum(area * 2.0 * (lam + 2.0 * mu) * np.linalg.norm(G, axis=(2, 3)) * gmag, axis=1)
    trace = np.take_along_axis(disp, end[None, :, :, None], axis=2)
    first = np.zeros(te.size, bool)
    order = np.argsort(te.ravel(), kind="stable")
    first[order[np.r_[True, te.ravel()[order][1:] != te.ravel()[order][:-1]]]] = True
    sign = np.where(first, 1.0, -1.0).reshape(te.shape)
    J = np.zeros_like(U)
    np.add.at(J, (slice(None), te.ravel()), (trace * sign[None, :, :, None]).reshape(len(U), -1, 2))
    jj = np.sum(J[:, jumped] ** 2, axis=2)
    tmag = 3.0 * np.sum(Umag, axis=2)  # a trace is a sum of three midpoint values
    jmag = np.zeros(U.shape[:2])
    np.add.at(jmag, (slice(None), te.ravel()), np.repeat(tmag, 3, axis=1))
    mag += pen * np.sum(2.0 / 3.0 * np.sqrt(jj) * jmag[:, jumped], axis=1)
    e = 0.5 * (np.sum(area * dens, axis=1) + pen * np.sum(jj, axis=1) / 3.0)
    return e, 0.5 * mag


def recompute(r, a):
    """The audit's mismatches with what the stored fields give (messages), and notes on what was not recomputed.
    ``a``: the audit series of ``tresca_py.audit.read`` for the committed steps of results ``r``."""
    problems, notes = [], []

    def compare(name, value, bound):
        stored = a[name]
        bad = np.abs(stored - value) > bound
        if np.any(bad):
            n = int(np.argmax(bad))
            problems.append(f"energy audit: {name} at step {n} is {stored[n]:.6e}, but the stored fields give "
                            f"{value[n]:.6e} (rounding bound {bound[n]:.1e})")

    j = friction(r)
    if j is not None:
        compare("friction_dissipation", *j)
    parts = _parts(r)
    if parts is not None and not has_data(parts, "dirichlet", "u") and not has_data(parts, "contact", "gap"):
        # without boundary data the reactions do no work (the audit adds exact zeros), but the contact reaction
        compare("boundary_work", *contact_work(r))
    d = dirichlet_edges(r)
    if isinstance(d, str):
        notes.append(f"stored and Euler energies not recomputed: {d}")
        return problems, notes
    jumped = np.bincount(r.mesh.triangle_edges().ravel(), minlength=len(r.mesh.edges)) == 2
    jumped[d] = True
    terms = len(r.mesh.triangles) + int(jumped.sum())
    for name, U in (("stored_energy", r.u), ("euler_dissipation", np.diff(r.u, axis=0, prepend=r.u[:1]))):
        e, mag = energy(r, U, jumped)
        compare(name, e, (terms + TERM_ROUNDINGS) * EPS * e + TERM_ROUNDINGS * EPS * mag)
    return problems, notes
