"""Command line of the dolfinx re-implementation: scripts/dolfinx_solve.py SCENE.toml -o OUT.h5
[--refine k] [--steps N] [-q], also under mpirun (same answer)."""
import time

import dolfinx_solver  # noqa: F401  (loads libmpi for the wheel; must precede dolfinx)
from mpi4py import MPI

from tresca_py.cli import cli, exit_on_failure, open_scene
from tresca_py.dolfinx_cr.assemble import DolfinxProblem
from tresca_py.dolfinx_cr.edges import CrEdges
from tresca_py.dolfinx_cr.friction import TaoStepSolver
from tresca_py.dolfinx_cr.stepping import backward_euler, save
from tresca_py.dolfinx_cr.unilateral import TaoFloatingStepSolver, TaoUnilateralStepSolver


def main(argv=None):
    comm = MPI.COMM_WORLD
    args = cli("Quasi-static Tresca friction with stabilised Crouzeix-Raviart elements -- DOLFINx 0.11 solver.", argv)
    root = comm.rank == 0
    scene, edges, out = open_scene(args, CrEdges, report=root, unilateral=True)   # every rank reads the scene
    stepper = TaoUnilateralStepSolver if edges.normal_unknowns else TaoStepSolver
    if len(edges.dirichlet) == 0:
        stepper = TaoFloatingStepSolver
    with exit_on_failure(report=root):   # the errors below are raised on every rank (collective checks)
        t0 = time.perf_counter()
        prob = DolfinxProblem(edges, comm)
        t_asm = time.perf_counter() - t0
        series = backward_euler(edges, prob, stepper, comm, log=not args.quiet and root)
        wall = time.perf_counter() - t0
        if root:
            save(out, edges, series, {"assembly_time": t_asm, "total_time": wall, "method": stepper.method,
                                      "mpi_size": comm.size})
    if root:
        print(f"dolfinx ({comm.size} rank{'s' if comm.size > 1 else ''}): {len(edges.edges)} edges, "
              f"{len(edges.contact)} contact edges, {len(scene.times) - 1} steps; "
              f"assembly+JIT {t_asm:.2f} s, total {wall:.2f} s -> {out}")
