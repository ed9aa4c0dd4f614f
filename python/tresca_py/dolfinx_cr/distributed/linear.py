"""The linear algebra of the distributed solver on K_r: its factorisation (MUMPS Cholesky, or CG + GAMG for
comparison) and the condensed contact operator C = E^T K_r^{-1} E gathered to rank 0."""
import ctypes
import functools
import sys

import dolfinx_solver  # noqa: F401  (loads libmpi for the wheel; must precede dolfinx)
import dolfinx.fem.petsc
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc


@functools.cache
def petsc_lib():
    """The wheel's libpetsc through ctypes, for the two calls petsc4py does not wrap."""
    lib = ctypes.CDLL(str(dolfinx.fem.petsc.get_petsc_lib()))
    for name in ("MatProductClear", "MatMumpsGetInverseTranspose"):
        getattr(lib, name).restype = ctypes.c_int
    lib.MatProductClear.argtypes = [ctypes.c_void_p]
    lib.MatMumpsGetInverseTranspose.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    return lib


def factorise_relaxed(prob, Kr, args):
    """MUMPS' workspace is sized from its analysis estimate + ICNTL(14) %; with parallel dynamic scheduling
    the estimate can fall short (INFOG(1) = -9, seen intermittently on a tiny mesh at 3 ranks): then factorise
    again with a larger relaxation, as the MUMPS guide advises. Returns (ksp, MUMPS statistics dict)."""
    comm = prob.comm
    for relax in (30, 100, 400):
        ksp, info = factorise(prob, Kr, args, relax)
        if args.ksp != "mumps" or info[0] not in (-8, -9, -11, -12, -13, -14, -15, -17, -20):
            break
        if comm.rank == 0:
            print(f"note: MUMPS workspace too small (INFOG(1) = {info[0]}) with ICNTL(14) = {relax} %; "
                  "factorising again", file=sys.stderr, flush=True)
        ksp.destroy()
    stats = {}
    if args.ksp == "mumps":
        F = ksp.getPC().getFactorMatrix()
        if info[0] < 0:      # PETSc records a failed MUMPS factorisation without raising
            raise RuntimeError(f"MUMPS factorisation failed: INFOG(1) = {info[0]}, INFOG(2) = {info[1]} "
                               "(see the MUMPS users' guide)")
        e29 = F.getMumpsInfog(29)       # entries in the factor (negative: millions)
        stats = {"factor_entries": float(-e29 * 1e6 if e29 < 0 else e29),
                 "flops": float(F.getMumpsRinfog(3)),
                 "mem_max_rank_mb": int(F.getMumpsInfog(21)), "mem_total_mb": int(F.getMumpsInfog(22)),
                 "ordering": int(F.getMumpsInfog(7)), "icntl14": relax}
    return ksp, stats


def factorise(prob, Kr, args, relax):
    """KSP on K_r: MUMPS Cholesky (set up = factorised) or CG + GAMG.  Returns (ksp, MUMPS INFOG(1:2))."""
    comm = prob.comm
    ksp = PETSc.KSP().create(comm)
    ksp.setOptionsPrefix("tresca_")
    ksp.setOperators(Kr)
    opts = PETSc.Options()
    info = (0, 0)
    if args.ksp == "mumps":
        ksp.setType("preonly")
        pc = ksp.getPC()
        pc.setType("cholesky")
        pc.setFactorSolverType("mumps")
        pc.setFactorSetUpSolverType()
        F = pc.getFactorMatrix()
        if args.mumps_analysis == "parallel":
            F.setMumpsIcntl(28, 2)      # parallel analysis
            F.setMumpsIcntl(29, 1)      # PT-Scotch (the MUMPS of the wheel has no ParMETIS)
        else:
            F.setMumpsIcntl(28, 1)      # sequential analysis on the host
            F.setMumpsIcntl(7, 5)       # METIS nested dissection
        F.setMumpsIcntl(14, relax)      # workspace relaxation (%)
        ksp.setFromOptions()
        ksp.setUp()
        info = (F.getMumpsInfog(1), F.getMumpsInfog(2))
    else:
        ksp.setType("cg")
        ksp.getPC().setType("gamg")
        ksp.setTolerances(rtol=1e-13, atol=0.0, max_it=10000)
        ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
        # near null space: rigid motions in the rotated unknowns, constrained entries zero
        xy = prob.midpoints
        modes = []
        for fx, fy in ((np.ones(len(xy)), np.zeros(len(xy))), (np.zeros(len(xy)), np.ones(len(xy))),
                       (-xy[:, 1], xy[:, 0])):
            vv = np.stack([fx, fy], 1)
            vv[prob.con_lb] = np.stack([np.sum(vv[prob.con_lb] * prob.tangent, 1), np.zeros(len(prob.con_lb))], 1)
            vv = vv.ravel()
            vv[prob.cons_local] = 0.0
            w = Kr.createVecRight()
            w.array[:] = vv
            modes.append(w)
        Kr.setNearNullSpace(PETSc.NullSpace().create(vectors=modes, comm=comm))
        opts["tresca_pc_gamg_threshold"] = 0.01
        ksp.setFromOptions()
        ksp.setUp()
    return ksp, info


def condense(prob, log):
    comm, nc = prob.comm, prob.n_c
    prob.condense_path = "none (no contact edges)"
    if nc == 0:
        return np.zeros((0, 0)) if comm.rank == 0 else None
    Cm = np.zeros((nc, nc)) if comm.rank == 0 else None
    my = 2 * prob.con_lb
    prob.condense_path = prob.args.condense if prob.args.ksp == "mumps" else "ksp"
    if prob.args.ksp == "mumps" and prob.args.condense == "inverse":
        return condense_inverse(prob)
    if prob.args.ksp == "mumps":
        nb = max(1, min(nc, prob.args.rhs_block))
        F = prob.ksp.getPC().getFactorMatrix()
        nloc, N = prob.Kr.getLocalSize()[0], prob.Kr.getSize()[0]
        for c0 in range(0, nc, nb):
            c1 = min(nc, c0 + nb)
            Bm = PETSc.Mat().createDense(((nloc, N), (None, c1 - c0)), comm=comm)
            Bm.setUp()
            Xm = PETSc.Mat().createDense(((nloc, N), (None, c1 - c0)), comm=comm)
            Xm.setUp()
            arr = Bm.getDenseArray()
            arr[:] = 0.0
            # column k of this block: unit vector at the contact unknown of contact edge c0 + k
            mine = np.arange(prob.c_offset, prob.c_offset + len(my))
            sel = (mine >= c0) & (mine < c1)
            arr[my[sel], mine[sel] - c0] = 1.0
            Bm.assemble()
            F.matSolve(Bm, Xm)
            prob.n_solves += c1 - c0
            rows = Xm.getDenseArray()[my, :].copy()
            Bm.destroy()
            Xm.destroy()
            parts = comm.gather(rows, root=0)
            if comm.rank == 0:
                Cm[:, c0:c1] = np.concatenate(parts, axis=0)
    else:
        e = prob.Kr.createVecRight()
        x = prob.Kr.createVecRight()
        for k in range(nc):
            e.set(0.0)
            if prob.c_offset <= k < prob.c_offset + len(my):
                e.array[my[k - prob.c_offset]] = 1.0
            prob.solve(e, x)
            col = prob.gather_contact(x)
            if comm.rank == 0:
                Cm[:, k] = col
    return 0.5 * (Cm + Cm.T) if comm.rank == 0 else None


def condense_inverse(prob):
    """C = the contact block of K_r^{-1}, computed by MUMPS as selected entries of the inverse
    (ICNTL(30), PETSc's MatMumpsGetInverseTranspose, which petsc4py does not wrap: called through
    ctypes on the wheel's libpetsc).  The requested pattern (n_c x n_c entries) lives on rank 0,
    which receives the entries; no dense n x n_c block is formed."""
    comm, nc = prob.comm, prob.n_c
    F = prob.ksp.getPC().getFactorMatrix()
    N = prob.Kr.getSize()[0]
    if comm.rank == 0:
        idx = (2 * prob.C_edges).astype(PETSc.IntType)          # sorted
        counts = np.zeros(N, PETSc.IntType)
        counts[idx] = nc
        indptr = np.concatenate([[0], np.cumsum(counts)]).astype(PETSc.IntType)
        cols = np.tile(idx, nc).astype(PETSc.IntType)
        vals = np.ones(nc * nc)
        sizes = ((N, N), (N, N))
    else:
        indptr, cols, vals = np.zeros(1, PETSc.IntType), np.zeros(0, PETSc.IntType), np.zeros(0)
        sizes = ((0, N), (0, N))
    S = PETSc.Mat().createAIJ(sizes, csr=(indptr, cols, vals), comm=comm)
    S.assemble()
    keep = {k: F.getMumpsIcntl(k) for k in (20, 21, 30)}
    ierr = petsc_lib().MatMumpsGetInverseTranspose(ctypes.c_void_p(F.handle), ctypes.c_void_p(S.handle))
    info = (F.getMumpsInfog(1), F.getMumpsInfog(2), F.getMumpsInfo(1), F.getMumpsInfo(2))
    for k, v in keep.items():                 # back to ordinary solves
        F.setMumpsIcntl(k, v)
    if comm.allreduce(ierr, op=MPI.MAX):
        raise RuntimeError(f"MatMumpsGetInverseTranspose failed (PETSc error {ierr}; MUMPS INFOG(1:2), "
                           f"INFO(1:2) on rank {comm.rank}: {info}; local rows {prob.Kr.getLocalSize()[0]}, "
                           f"contact {len(prob.con_lb)})")
    prob.n_solves += nc
    Cm = None
    if comm.rank == 0:
        ip, jj, vv = S.getValuesCSR()
        Cm = np.empty((nc, nc))
        for k, i in enumerate(idx):
            if not np.array_equal(jj[ip[i]:ip[i + 1]], idx):
                raise RuntimeError("MatMumpsGetInverseTranspose changed the requested pattern")
            Cm[k] = vv[ip[i]:ip[i + 1]]
        Cm = 0.5 * (Cm + Cm.T)
    S.destroy()
    return Cm
