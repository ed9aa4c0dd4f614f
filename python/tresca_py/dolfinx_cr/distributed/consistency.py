"""Boundary data that do not fit together are refused before anything is solved, by the one rule and
tolerance of the Python solvers (``tresca_py.scene_data``, as src/fem/lifting/consistency.rs): the Dirichlet
and Γ_C edges that the ranks own (O(√n) of them) are gathered to rank 0, which checks them; the verdict goes
to every rank. The tolerance's scale, the largest |u₀| at a mesh vertex, is reduced over every rank's owned
vertices.
"""
import numpy as np
from mpi4py import MPI

from tresca_py.dolfinx_cr.distributed.mesh import agree
from tresca_py.errors import InputError
from tresca_py.scene_data import check_boundary_data


def oriented_edges(prob, A, B, pb):
    """The owned Dirichlet and Γ_C edges as (first points, second points, global vertex pairs, parts), each
    Γ_C edge counter-clockwise (its outward normal n = (d_y, −d_x) for d = b − a, as ``scene_data`` reads it;
    the orientation of a Dirichlet edge is not used there)."""
    kind = np.array([b.kind for b in prob.scene.boundaries] + ["interior"])[pb]
    sel = np.flatnonzero((kind == "dirichlet") | (kind == "contact"))
    normal = np.zeros((len(pb), 2))
    normal[prob.con_lb] = prob.normal
    a, b, ev, nrm = A[sel], B[sel], prob.edges_vertices[sel], normal[sel]
    d = b - a
    flip = (kind[sel] == "contact") & (d[:, 1] * nrm[:, 0] - d[:, 0] * nrm[:, 1] < 0)
    return (np.where(flip[:, None], b, a), np.where(flip[:, None], a, b),
            np.where(flip[:, None], ev[:, ::-1], ev), pb[sel])


def check(prob, A, B, pb):
    """Collective: Fail on every rank naming the first mismatch (module doc). ``A``, ``B``: the owned edges'
    end points, ``pb``: their boundary parts (-1 inside)."""
    comm, scene = prob.comm, prob.scene
    parts = comm.gather(oriented_edges(prob, A, B, pb), root=0)
    msg, u0_max = None, 0.0
    try:
        pts = prob.points
        u0_max = float(np.max(np.abs(scene.u0(pts[:, 0], pts[:, 1], scene.times[0])), initial=0.0))
    except InputError as e:
        msg = str(e)
    agree(comm, msg)
    u0_max = comm.allreduce(u0_max, op=MPI.MAX)
    if comm.rank == 0:
        a, b, ev, part = (np.concatenate([p[k] for p in parts]) for k in range(4))
        ids, local = np.unique(ev.ravel(), return_inverse=True)
        local = local.reshape(-1, 2)
        points = np.zeros((len(ids), 2))
        points[local[:, 0]], points[local[:, 1]] = a, b
        try:
            check_boundary_data(scene, points, local, part, u0_max=u0_max)
        except InputError as e:
            msg = str(e)
    agree(comm, msg)
