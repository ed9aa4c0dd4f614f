"""Command line of the dolfinx re-implementation: scripts/dolfinx_solve.py SCENE.toml -o OUT.h5
[--refine k] [--steps N] [-q], also under mpirun (same answer)."""
import time

import dolfinx_solver  # noqa: F401  (loads libmpi for the wheel; must precede dolfinx)
from mpi4py import MPI

from tresca_py.cli import cli, exit_on_failure, open_scene
from tresca_py.dolfinx_cr.assemble import DolfinxProblem
from tresca_py.dolfinx_cr.friction import TaoStepSolver
from tresca_py.skfem_cr.stepping import run, write_results


def main(argv=None):
    comm = MPI.COMM_WORLD
    args = cli("Quasi-static Tresca friction with stabilised Crouzeix-Raviart elements -- DOLFINx 0.11 solver.", argv)
    root = comm.rank == 0
    scene, disc, out = open_scene(args, report=root)      # every rank reads the scene (deterministic)
    with exit_on_failure(report=root):   # the errors below are raised on every rank (collective checks)
        t0 = time.perf_counter()
        prob = DolfinxProblem(disc, comm)
        t_asm = time.perf_counter() - t0
        errors = prob.errors if scene.exact_u is not None else None
        res = run(disc, prob.K, prob.J, prob.load, errors, comm=comm, log=not args.quiet and root,
                  step_solver=TaoStepSolver)
        wall = time.perf_counter() - t0
        if root:
            write_results(out, disc, res, "dolfinx", {"assembly_time": t_asm, "total_time": wall,
                                                         "method": TaoStepSolver.method, "mpi_size": comm.size})
    if root:
        print(f"dolfinx ({comm.size} rank{'s' if comm.size > 1 else ''}): {len(disc.edges)} edges, "
              f"{len(disc.contact)} contact edges, {len(scene.times) - 1} steps; "
              f"assembly+JIT {t_asm:.2f} s, total {wall:.2f} s -> {out}")
