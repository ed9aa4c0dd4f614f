"""Command line of the scikit-fem re-implementation: scripts/skfem_solve.py SCENE.toml -o OUT.h5
[--refine k] [--steps N] [-q]."""
import time

from tresca_py.cli import cli, exit_on_failure, open_scene
from tresca_py.skfem_cr.assemble import SkfemProblem
from tresca_py.skfem_cr.cr import Discretisation
from tresca_py.skfem_cr.lifting import SkfemLifting
from tresca_py.skfem_cr.stepping import run, write_results


def main(argv=None):
    args = cli("Quasi-static Tresca friction with stabilised Crouzeix-Raviart elements -- scikit-fem solver.", argv)
    scene, disc, out = open_scene(args, Discretisation, unilateral=True)
    with exit_on_failure():
        t0 = time.perf_counter()
        prob = SkfemProblem(disc)
        t_asm = time.perf_counter() - t0
        errors = prob.errors if scene.exact_u is not None else None
        lifting = SkfemLifting(prob) if scene.has_boundary_data else None
        res = run(disc, prob.K, prob.load, errors, log=not args.quiet, lifting=lifting)
        wall = time.perf_counter() - t0
        write_results(out, disc, res, "skfem", {"assembly_time": t_asm, "total_time": wall})
    print(f"skfem: {len(disc.edges)} edges, {len(disc.contact)} contact edges, {len(scene.times) - 1} steps; "
          f"assembly {t_asm:.2f} s, total {wall:.2f} s -> {out}")
