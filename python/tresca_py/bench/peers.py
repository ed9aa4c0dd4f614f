"""One sparse Cholesky/LDLᵀ set-up of a matrix exported by probes/export_matrix.rs, in this process.

    python -m tresca_py.bench.peers SOLVER DIR      # SOLVER: cholmod, cholmod-metis, pardiso, mumps, dense

Prints one JSON line: the phases (analysis, factorisation, seconds of wall time), nnz(L), the flop count
where the solver reports it, the CPU time of the process and its peak RSS. Each solver runs in a process of
its own: their BLAS libraries (OpenBLAS of Debian's CHOLMOD, MKL of pypardiso, PETSc's) cannot share one.
`dense` measures the machine's dense-kernel rate instead: a Cholesky factorisation of an SPD matrix of
order DIR (numpy, the threads OpenBLAS is given), flops n³/3, rate by CPU time.
"""
import json
import resource
import sys
import time

import numpy as np


class Phase:
    """Wall and process CPU time (all threads) of a phase."""

    def __enter__(self):
        self.w, self.c = time.perf_counter(), time.process_time()
        return self

    def __exit__(self, *exc):
        self.wall, self.cpu = time.perf_counter() - self.w, time.process_time() - self.c


def phases(a, f, **more):
    return dict(analysis=a.wall, factorisation=f.wall, analysis_cpu=a.cpu, factorisation_cpu=f.cpu, **more)


def load(directory):
    """The symmetric matrix (lower triangle stored, CSC) as scipy CSC of both triangles, and its lower part."""
    import scipy.sparse as sp
    ptr, idx, data = (np.load(f"{directory}/{f}.npy") for f in ("indptr", "indices", "data"))
    n = len(ptr) - 1
    lower = sp.csc_matrix((data, idx, ptr), shape=(n, n))
    full = (lower + sp.tril(lower, -1).T).tocsc()
    return full, lower


def cholmod(directory, ordering):
    from sksparse.cholmod import analyze
    full, _ = load(directory)
    with Phase() as a:
        sym = analyze(full, mode="supernodal", ordering_method=ordering)
    with Phase() as f:
        factor = sym.cholesky(full)
    # nnz(L) and Σ c_j² from L's column counts
    counts = np.diff(factor.L().indptr).astype(np.float64)
    return phases(a, f, nnz_l=float(counts.sum()), flops=float((counts ** 2).sum()))


def pardiso(directory):
    import pypardiso
    import scipy.sparse as sp
    full, _ = load(directory)
    upper = sp.triu(full).tocsr()  # PARDISO reads the upper triangle of a symmetric matrix, CSR
    s = pypardiso.PyPardisoSolver(mtype=2)  # real SPD
    s.set_iparm(19, -1)  # report the factorisation's Mflops in iparm(19)
    b = np.ones(upper.shape[0])
    with Phase() as a:
        s.set_phase(11)
        s._call_pardiso(upper, b)
    with Phase() as f:
        s.set_phase(22)
        s._call_pardiso(upper, b)
    iparm = s.get_iparms()
    return phases(a, f, nnz_l=float(iparm[18]), flops=float(iparm[19]) * 1e6)


def mumps(directory):
    import dolfinx_solver  # noqa: F401  (loads the MPI library PETSc needs)
    from petsc4py import PETSc
    full, _ = load(directory)
    full = full.tocsr()
    a = PETSc.Mat().createAIJ(size=full.shape, csr=(full.indptr.astype(PETSc.IntType),
                                                    full.indices.astype(PETSc.IntType), full.data))
    a.setOption(PETSc.Mat.Option.SPD, True)
    a.assemble()
    pc = PETSc.PC().create()
    pc.setOperators(a)
    pc.setType("cholesky")
    pc.setFactorSolverType("mumps")
    with Phase() as t:
        pc.setUp()
    fm = pc.getFactorMatrix()
    return dict(analysis=float("nan"), factorisation=float("nan"), total=t.wall, analysis_cpu=float("nan"),
                factorisation_cpu=float("nan"), total_cpu=t.cpu,
                nnz_l=float(fm.getMumpsInfog(29)), flops=float(fm.getMumpsRinfog(3)))


def dense(n):
    rng = np.random.default_rng(0)
    m = rng.standard_normal((n, n))
    a = m @ m.T + n * np.eye(n)
    np.linalg.cholesky(a)  # warm-up
    with Phase() as f:
        np.linalg.cholesky(a)
    # by CPU time (all threads), as the sparse rates: the shared machine's wall times carry its load
    return dict(factorisation=f.wall, factorisation_cpu=f.cpu, flops=n ** 3 / 3.0, rate=n ** 3 / 3.0 / f.cpu)


def main(argv):
    solver, arg = argv[1], argv[2]
    c0 = time.process_time()
    run = {"cholmod": lambda: cholmod(arg, "amd"), "cholmod-metis": lambda: cholmod(arg, "metis"),
           "pardiso": lambda: pardiso(arg), "mumps": lambda: mumps(arg), "dense": lambda: dense(int(arg))}[solver]
    out = run()
    out.update(solver=solver, cpu=time.process_time() - c0,
               peak_rss=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024)
    print(json.dumps(out))


if __name__ == "__main__":
    main(sys.argv)
