"""Command line and time loop of the distributed solver (scripts/dolfinx_distributed.py)."""
import argparse
import json
import math
import os
import sys
import time

import dolfinx_solver  # noqa: F401  (loads libmpi for the wheel; must precede dolfinx)
import dolfinx
import numpy as np
from dolfinx import fem
from mpi4py import MPI

from tresca_py.dolfinx_cr.distributed.mesh import Fail
from tresca_py.dolfinx_cr.distributed.output import PartWriter, check_outputs, setup_time_attrs, write_main
from tresca_py.dolfinx_cr.distributed.problem import Problem, peak_mb
from tresca_py.cli import FAILURES, input_files, message, output_path
from tresca_py.errors import InputError
from tresca_py.dolfinx_cr.friction import TaoBoxQP, natural_residual
from tresca_py.dolfinx_cr.stepping import slipping
from tresca_py.scene import load_scene

DESCRIPTION = ("Quasi-static Tresca friction with stabilised CR elements -- distributed DOLFINx 0.11 + PETSc/MUMPS "
               "solver.")


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=DESCRIPTION)
    ap.add_argument("scene", help="scene TOML file")
    ap.add_argument("-o", "--output", help="results file (default: [output] path of the scene)")
    ap.add_argument("--refine", type=int, default=None, help="override [mesh] refine")
    ap.add_argument("--steps", type=int, default=None, help="override the number of uniform time steps")
    ap.add_argument("-q", "--quiet", action="store_true", help="no per-step log")
    ap.add_argument("--force", action="store_true", help="replace an existing results file")
    ap.add_argument("--ksp", choices=("mumps", "cg-gamg"), default="mumps",
                    help="linear solver for K_r: MUMPS Cholesky (default) or CG + GAMG (rtol 1e-13)")
    ap.add_argument("--mumps-analysis", choices=("sequential", "parallel"), default="sequential",
                    help="MUMPS analysis: METIS on the host (default) or PT-Scotch in parallel")
    ap.add_argument("--condense", choices=("inverse", "matsolve"), default="inverse",
                    help="MUMPS: C from selected entries of K_r^-1 (ICNTL(30), default) or from blocked MatMatSolve")
    ap.add_argument("--rhs-block", type=int, default=32,
                    help="right-hand sides per MatMatSolve when building C (memory: 2 x n x block doubles)")
    ap.add_argument("--frame-every", type=int, default=None,
                    help="visualisation frame every k steps (default: about 50 frames; 0 = none)")
    ap.add_argument("--mem-log", action="store_true", help="print every rank's RSS after each set-up stage")
    return ap.parse_args(argv)


def abort_on_error(exc_type, exc, tb):
    """An uncaught exception on one rank would leave the others waiting in a collective call forever
    (and MPI_Finalize waiting for them): print it and abort the whole job."""
    sys.__excepthook__(exc_type, exc, tb)
    sys.stderr.flush()
    MPI.COMM_WORLD.Abort(1)


def set_up(comm, args, log):
    """Scene, output path and Problem; bad input on any rank stops every rank with one message (exit 2)."""
    try:
        try:
            scene = load_scene(args.scene, refine=args.refine, steps=args.steps)
            scene.refuse_contact_extensions("distributed dolfinx")
            if not any(b.kind == "dirichlet" for b in scene.boundaries):
                raise Fail("no dirichlet part: the distributed dolfinx solver takes a body held by a Dirichlet part "
                           "only (a floating body's rigid motions are not modelled)")
        except InputError as e:
            raise Fail(str(e)) from None
        try:
            out = output_path(args, scene)
            stale = check_outputs(out, args.force, input_files(args, scene))
        except FAILURES as e:
            raise Fail(message(e)) from None
        if args.rhs_block < 1:
            raise Fail("--rhs-block must be >= 1")
        if args.frame_every is not None and args.frame_every < 0:
            raise Fail("--frame-every must be >= 0")
        try:
            prob = Problem(scene, comm, args, log, mem_log=args.mem_log)
        except InputError as e:
            raise Fail(str(e)) from None
    except Fail as e:
        stop(comm, e)
    return scene, out, prob, stale


def stop(comm, err):
    """Every rank: the error on rank 0's stderr as one line, exit status 2."""
    if comm.rank == 0:
        print(f"error: {err}", file=sys.stderr, flush=True)
    comm.Barrier()
    sys.exit(2)


def remove_partial(comm, out, writer_dir):
    """Rank 0, after a failed time loop: the files this run wrote (the parts, the visualisation frames), so
    no half-written result is left."""
    comm.barrier()
    if comm.rank:
        return
    vtk = os.path.splitext(out)[0] + "_vtk"
    for d, keep in ((writer_dir, lambda f: not (f.startswith("rank") and f.endswith(".h5"))),
                    (vtk, lambda f: not f.startswith("displacement"))):
        if os.path.isdir(d):
            for f in os.listdir(d):
                if not keep(f):
                    os.remove(os.path.join(d, f))
            if not os.listdir(d):
                os.rmdir(d)


def new_results(scene, nc):
    N1 = len(scene.times)
    res = dict(slip=np.zeros((N1, nc)), sigma_t=np.zeros((N1, nc)), mu=np.zeros((N1, nc)),
               state=np.zeros((N1, nc), np.int8), iterations=np.zeros(N1, np.int64),
               residual=np.zeros(N1), n_stick=np.zeros(N1, np.int64), n_slip=np.zeros(N1, np.int64),
               wall_time=np.zeros(N1), energy=np.zeros(N1))
    if scene.exact_u is not None:
        res["errors"] = {k: np.zeros(N1) for k in ("energy", "h1", "l2")}
    return res


class Friction:
    """The friction problem of each step on rank 0: the dual box QP on the condensed contact unknowns by
    PETSc TAO TRON (``tresca_py.dolfinx_cr.friction``)."""

    def __init__(self, prob):
        self.prob = prob
        self.s_prev = prob.gather_contact(prob.ur)
        root = prob.comm.rank == 0
        self.mu_prev = np.zeros(prob.n_c) if root else None
        self.qp = TaoBoxQP(prob.C, prob.C_w) if root and prob.n_c else None

    def step(self, n, sf, res):
        """Rank 0: mu of step n from the frictionless contact unknowns sf; the statistics into res."""
        prob = self.prob
        d = sf - self.s_prev
        mu, its = self.qp.solve(d, self.mu_prev)
        ds = d - prob.C @ mu
        res["iterations"][n] = its
        res["residual"][n] = natural_residual(prob.C, d, prob.C_w, mu)
        res["state"][n] = slipping(mu, ds, d, prob.C_w)
        res["sigma_t"][n] = -mu / prob.C_len
        res["mu"][n] = mu
        self.mu_prev = mu.copy()
        self.s_prev = sf - prob.C @ mu
        return mu


def solve_step(prob, friction, n, t, res):
    """u^n = u_f - K_r^{-1} E mu with u_f = K_r^{-1} l^n (into prob.ur)."""
    ur, uf, w = prob.ur, prob.uf, prob.w
    prob.solve(prob.load(t), uf)
    sf = prob.gather_contact(uf)
    if not prob.n_c:
        uf.copy(ur)
        return
    mu = friction.step(n, sf, res) if prob.comm.rank == 0 else None
    mu = prob.comm.bcast(mu, root=0)
    prob.rhs.set(0.0)
    prob.rhs.array[2 * prob.con_lb] = mu[prob.c_offset:prob.c_offset + len(prob.con_lb)]
    prob.solve(prob.rhs, w)
    uf.copy(ur)
    ur.axpy(-1.0, w)


def time_loop(prob, args, out, log, stale):
    """Backward Euler over the scene's times; returns (results on rank 0, step wall times, part writer)."""
    comm, scene = prob.comm, prob.scene
    times = scene.times
    N = len(times) - 1
    root = comm.rank == 0
    nc = prob.n_c
    res = new_results(scene, nc) if root else None
    writer = PartWriter(out, prob, N + 1, stale)
    fe = args.frame_every if args.frame_every is not None else max(1, N // 50)
    vis = None
    if fe > 0:
        udg = fem.Function(fem.functionspace(prob.msh, ("DG", 1, (2,))), name="displacement")
        vis = dolfinx.io.VTKFile(comm, os.path.splitext(out)[0] + "_vtk/displacement.pvd", "w")
    prob.ur.array[:] = prob.r0
    friction = Friction(prob)
    step_times = []
    for n, t in enumerate(times):
        tic = time.perf_counter()
        if n > 0:
            try:
                solve_step(prob, friction, n, t, res)
            except Fail as e:
                vis = None                   # destroyed (and its .pvd written) before its files are removed
                writer.close()
                remove_partial(comm, out, writer.dir)
                raise Fail(f"step {n} (t = {t:.6g}): {e}") from None
        if root:
            res["slip"][n] = friction.s_prev
            res["n_slip"][n] = int(res["state"][n].sum())
            res["n_stick"][n] = nc - res["n_slip"][n]
        prob.to_function(prob.ur, t)
        en = prob.energy(prob.ur)
        writer.write(n, prob.uh.x.array[:2 * prob.nb_own])
        if prob.err_forms is not None:
            e = prob.errors(t)
            if root:
                for key, val in zip(("energy", "h1", "l2"), e, strict=True):
                    res["errors"][key][n] = math.sqrt(max(float(val), 0.0))
        if vis is not None and (n % fe == 0 or n == N):
            udg.interpolate(prob.uh)
            vis.write_function(udg, float(t))
        el = time.perf_counter() - tic
        step_times.append(el)
        if root:
            res["energy"][n] = en
            res["wall_time"][n] = el
            if n == N or (N >= 10 and n % max(1, N // 10) == 0):
                extra = f" err_E={res['errors']['energy'][n]:.4e}" if "errors" in res else ""
                log(f"step {n:5d}/{N} t={t:.6g} iters={res['iterations'][n]} slip={res['n_slip'][n]}/{nc} "
                    f"a_h(u,u)={en:.6e}{extra} ({el:.3f} s)")
    if vis is not None:
        vis.close()
    writer.close()
    return res, step_times, writer


def main(argv=None):
    comm = MPI.COMM_WORLD
    args = parse_args(argv)
    if comm.size > 1:
        sys.excepthook = abort_on_error
    t_start = time.perf_counter()
    log = (lambda *a: print(*a, flush=True)) if comm.rank == 0 and not args.quiet else (lambda *a: None)
    scene, out, prob, stale = set_up(comm, args, log)
    setup_time = time.perf_counter() - t_start
    log(f"set-up {setup_time:.2f} s: " + ", ".join(f"{k} {v:.2f} s" for k, v in prob.times_setup.items())
        + f"; {2 * prob.nb_glob} unknowns, {prob.n_c} contact edges, {comm.size} rank(s)")
    try:
        res, step_times, writer = time_loop(prob, args, out, log, stale)
    except Fail as e:
        stop(comm, e)
    N = len(scene.times) - 1
    sizes = comm.gather(dict(points=len(prob.points), triangles=len(prob.triangles), edges=prob.nb_own), root=0)
    total = time.perf_counter() - t_start
    peaks = comm.gather(peak_mb(), root=0)
    mem_setup = comm.gather(prob.mem_setup, root=0)
    comm.barrier()                     # every part is closed before the virtual datasets point at them
    if comm.rank == 0:
        attrs = {"total_time": total, "setup_time": setup_time, "mpi_size": comm.size,
                 **setup_time_attrs(prob.times_setup),
                 "step_time_median": float(np.median(step_times[1:])) if N else 0.0,
                 "peak_rss_mb": np.array(peaks), "setup_peak_rss_mb": json.dumps(mem_setup),
                 "mumps": json.dumps(prob.mumps), "linear_solver": args.ksp, "condensation": prob.condense_path,
                 "linear_solves": prob.n_solves, "ksp_iterations_max": int(max(prob.ksp_its)) if prob.ksp_its else 0}
        write_main(out, prob, res, writer.dir, sizes, attrs, args.force)
        log(f"dolfinx distributed ({comm.size} rank{'s' if comm.size > 1 else ''}): {2 * prob.nb_glob} unknowns, "
            f"{prob.n_c} contact edges, {N} steps; set-up {setup_time:.2f} s, total {total:.2f} s, "
            f"peak RSS per rank {', '.join(f'{p:.0f}' for p in peaks)} MB -> {out}")
    comm.barrier()
