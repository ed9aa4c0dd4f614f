"""The visualisation fields recomputed from ``/tresca`` (what ``src/output/fields.rs`` writes into the VTKHDF
and XDMF views), for the pictures (``tresca_py.render``) and the reader checks (``tresca_py.check``).

On triangle T with edges e_i opposite its vertices v_i, the CR field is linear and equals U_{e_i} at the
midpoint of e_i, so at the vertices U(v_j) = Σ_{i≠j} U_{e_i} − U_{e_j} (a broken P1 field, 3 points per
triangle). Its gradient gives ε, and plane strain gives σ = λ tr ε I + 2μ ε with σ_zz = λ tr ε; von Mises
is sqrt(½((σxx−σyy)² + (σyy−σzz)² + (σzz−σxx)²) + 3σxy²).
"""
import numpy as np

from tresca_py.elastic import lame


def vertex_values(u, te):
    """(S, T, 3, 2): the field at the triangles' vertices, from midpoint values u (S, E, 2) and the
    triangles' edges te (T, 3) (``Mesh.triangle_edges``)."""
    U = u[:, te, :]
    return U.sum(axis=2, keepdims=True) - 2.0 * U


def basis_gradients(points, triangles):
    """(T, 3, 2): the gradients of the three P1 basis functions of each triangle."""
    x = points[triangles]
    a2 = (x[:, 1, 0] - x[:, 0, 0]) * (x[:, 2, 1] - x[:, 0, 1]) - (x[:, 1, 1] - x[:, 0, 1]) * (x[:, 2, 0] - x[:, 0, 0])
    gl = np.zeros((len(triangles), 3, 2))
    for i in range(3):
        b, c = x[:, (i + 1) % 3], x[:, (i + 2) % 3]
        gl[:, i, 0] = (b[:, 1] - c[:, 1]) / a2
        gl[:, i, 1] = (c[:, 0] - b[:, 0]) / a2
    return gl


def stress(disp, gl, E, nu):
    """(σxx, σyy, σzz, σxy, von Mises), each (S, T), of the vertex values ``disp`` (S, T, 3, 2)."""
    G = np.einsum("stja,tjb->stab", disp, gl)
    lam, mu = lame(E, nu)
    exx, eyy, exy = G[..., 0, 0], G[..., 1, 1], 0.5 * (G[..., 0, 1] + G[..., 1, 0])
    tr = exx + eyy
    sxx, syy, szz, sxy = lam * tr + 2 * mu * exx, lam * tr + 2 * mu * eyy, lam * tr, 2 * mu * exy
    vm = np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2) + 3 * sxy ** 2)
    return sxx, syy, szz, sxy, vm


def of_steps(r, steps):
    """(vertex values (S, T, 3, 2), von Mises (S, T), σxx (S, T)) of the given steps of results ``r``."""
    m = r.mesh
    disp = vertex_values(r.u[steps], m.triangle_edges())
    sxx, _, _, _, vm = stress(disp, basis_gradients(m.points, m.triangles), float(r.attrs["E"]),
                              float(r.attrs["nu"]))
    return disp, vm, sxx


def contact_points(r):
    """The broken-mesh point (3t + j) of each of the 2C contact line points: the ends of Γ_C edge k as
    vertices of its one triangle, in the order (j+1, j+2) after the local vertex j opposite the edge."""
    te = r.mesh.triangle_edges()
    out = []
    for e in r.contact.edges:
        t, i = np.argwhere(te == e)[0]
        out += [3 * t + (i + 1) % 3, 3 * t + (i + 2) % 3]
    return np.array(out, dtype=np.int64)
