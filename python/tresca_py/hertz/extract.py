"""What a Hertz run is checked on, from its results file: the force per unit length P, the contact half-width and
peak pressure against Hertz's a(P), p₀(P), and the pressure profile's error.

Γ_C's edges facing the plane (outward normal n_y < −½; the symmetry axis has n = (−1, 0)) carry the pressure
p_e = P_e/|e| at the last step. With x₀ ≤ x₁ the ends of an edge's projection on the plane:

* P = 2 Σ_e |e| p_e |n_y|  (the vertical reaction on the plane, both halves of the cylinder);
* a_moment = 2 √(M₂/M₀), M_k = Σ_e |e| p_e x_e^k at the midpoints (Hertz: ∫p x² = a² ∫p/4), a smooth functional
  of the pressure; a_edge = x₁ of the outermost pressed edge (p_e > 0), within one edge of the discrete zone's end;
* p₀_h = max_e p_e (the first edge, whose Hertz mean is p₀ (1 − O(h²/a²)));
* δ = −(mean of u_y over the cut y = R, by edge length): the approach of the loaded cut (the load's work P δ/2 is
  the compliance, a functional converging like the energy);
* the profile error e_e = p_e − (Hertz mean over [x₀, x₁]) over every facing edge, relative to p₀:
  L∞ = max |e_e|/p₀ and L² = √(Σ |e| e_e² / a)/p₀.
"""
from dataclasses import dataclass

import numpy as np

from tresca_py import results
from tresca_py.hertz import formulas


@dataclass(frozen=True)
class Check:
    P: float
    a: float          # Hertz half-width a(P)
    p0: float         # Hertz peak p₀(P)
    a_moment: float
    a_edge: float
    p0_h: float
    linf: float
    l2: float
    h_c: float        # longest pressed edge (the mesh size in the contact zone)
    edges: int        # pressed edges
    delta: float      # approach of the cut y = R

    def deviations(self):
        """Relative deviations from Hertz: (a_moment, a_edge, p₀) each / Hertz − 1."""
        return self.a_moment / self.a - 1, self.a_edge / self.a - 1, self.p0_h / self.p0 - 1


def facing_edges(r):
    """(x0, x1, length, |n_y|, pressure) of the Γ_C edges of results ``r`` that face the plane y = 0."""
    c = r.require_contact("the Hertz check")
    if c.pressure is None:
        raise results.ResultsError(f"{r.path}: no /tresca/contact/pressure (the Hertz check needs a unilateral part)")
    keep = c.normal[:, 1] < -0.5
    ends = r.mesh.points[r.mesh.edges[c.edges[keep]]]
    x = np.sort(ends[:, :, 0], axis=1)
    length = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)
    order = np.argsort(x[:, 0])
    return (x[order, 0], x[order, 1], length[order], np.abs(c.normal[keep, 1])[order],
            c.pressure[-1][keep][order])


def approach(r, R):
    """−(length-weighted mean of u_y over the edges of the cut y = R) at the last step; NaN without such edges."""
    m = r.mesh
    ends = m.points[m.edges]
    on_cut = np.all(np.abs(ends[:, :, 1] - R) <= 1e-12 * R, axis=1)
    if not on_cut.any():
        return float("nan")
    length = np.linalg.norm(ends[on_cut, 1] - ends[on_cut, 0], axis=1)
    uy = r.u[-1].reshape(-1, 2)[on_cut, 1]
    return -float(np.sum(length * uy) / np.sum(length))


def check(path, R, E, nu):
    """The :class:`Check` of the results file ``path`` (cylinder of radius R, material E, ν)."""
    return check_results(results.read(path), R, E, nu)


def check_results(r, R, E, nu):
    """The :class:`Check` of results ``r`` (a :class:`tresca_py.results.Results`)."""
    x0, x1, length, ny, p = facing_edges(r)
    if not np.any(p > 0):
        raise ValueError(f"{r.path}: no pressed contact edge (p_e > 0): the cylinder does not touch the plane")
    P = 2.0 * float(np.sum(length * p * ny))
    a = formulas.half_width(P, R, E, nu)
    p0 = formulas.peak_pressure(P, a)
    xm = 0.5 * (x0 + x1)
    m0, m2 = np.sum(length * p), np.sum(length * p * xm * xm)
    err = p - formulas.edge_means(x0, x1, a, p0)
    pressed = p > 0
    return Check(P=P, a=a, p0=p0, a_moment=2.0 * float(np.sqrt(m2 / m0)), a_edge=float(np.max(x1[pressed])),
                 p0_h=float(np.max(p)), linf=float(np.max(np.abs(err)) / p0),
                 l2=float(np.sqrt(np.sum(length * err * err) / a) / p0), h_c=float(np.max(length[pressed])),
                 edges=int(np.sum(pressed)), delta=approach(r, R))
