"""Check a tresca-cr results file through three independent readers.

    .venv/bin/python scripts/check_results.py run.h5 [--xdmf run.xdmf]

* h5py (the ``tresca`` group, ``tresca_py.results.read``): the README layout, ``completed``, status, finite
  values, the per-step checksums (the energy audit's too, in files since they cover it), σ_τ = −μ/|e| on Γ_C,
  and the energy audit: its balance (``tresca_py.audit``), its terms recomputed from the stored fields where the
  file allows (``tresca_py.audit_evidence``), and its presence in a file of the Rust solver.
* VTK's ``vtkHDFReader`` (the VTKHDF view: a collection of the block ``body`` and, when Γ_C exists, ``contact``):
  numbers of points, cells and frames, each block's array names, and every frame's displacement / von Mises /
  contact arrays against values recomputed from ``tresca/u`` (``tresca_py.fields``).
* meshio's XDMF ``TimeSeriesReader`` (the sidecar; it reads the last temporal collection, the body): same numbers
  and values; VTK's ``vtkXdmfReader``: every block (a single grid when there is no contact block), the contact
  fields at the first and last frame. The sidecar must reference this results file (not the original of a copy).

Also for the file of a killed run (status ``running``): every reader must see exactly the committed steps.
The serial Python solvers write the ``/tresca`` group alone (``tresca_py.results.write``; docs/results.md): such a
file, without ``/VTKHDF`` and ``/xdmf``, has no views and no sidecar, and is checked through h5py only (said in the
output). A file that holds the views must come with its sidecar.
Exits 1 with one line per mismatch; a file that cannot be checked at all gives one ``error:`` line and exit 2.
"""
import argparse
import os
import sys

import numpy as np

from . import audit, audit_evidence, fields, paths, results, vtkhdf_layout

BODY_CELLS = ["strain", "stress", "von_mises"]
CONTACT_CELLS = ["sigma_t", "slip", "slip_increment", "stick_slip"]
NORMAL_CELLS = ["pressure", "gap", "status"]  # with normal unknowns (a unilateral or Coulomb part) only


class Checker:
    """The mismatches found so far."""

    def __init__(self):
        self.failures = []

    def check(self, ok, msg):
        if not ok:
            self.failures.append(msg)
        return ok

    def close(self, a, b, what, rtol=2e-6, size=0.0):
        """max|a − b| ≤ rtol · max(max|b|, size) (the views are f32: 2e-6 is a few f32 roundings; ``size``: that of
        the tensor a component of which is compared, whose rounding the component carries)."""
        a, b = np.asarray(a, float), np.asarray(b, float)
        if not self.check(a.shape == b.shape, f"{what}: shape {a.shape} != {b.shape}"):
            return
        scale = max(float(np.max(np.abs(b))) if b.size else 0.0, size, 1e-300)
        err = float(np.max(np.abs(a - b))) if a.size else 0.0
        self.check(np.isfinite(err) and err <= rtol * scale, f"{what}: max difference {err:.3e} (scale {scale:.3e})")


def reference(r, S=None):
    """Expected VTK arrays of the first S committed steps: (displacement (S, 3T, 2), von Mises (S, T),
    σxx (S, T)). ``r``: Results, or an open h5py ``tresca`` group (read again, validated)."""
    if not isinstance(r, results.Results):
        r = results.read(r.file.filename)
    S = r.completed if S is None else S
    disp, vm, sxx = fields.of_steps(r, slice(0, S))
    return disp.reshape(S, -1, 2), vm, sxx


def array_names(data):
    return sorted(data.GetArrayName(i) for i in range(data.GetNumberOfArrays()))


def blocks_of(o, vtk):
    """{block name: dataset} of a reader's output: a collection, a multiblock, or one grid (the body)."""
    if o.IsA("vtkPartitionedDataSetCollection"):
        return {o.GetMetaData(i).Get(vtk.vtkCompositeDataSet.NAME()): o.GetPartition(i, 0)
                for i in range(o.GetNumberOfPartitionedDataSets())}
    if o.IsA("vtkMultiBlockDataSet"):
        return {o.GetMetaData(i).Get(vtk.vtkCompositeDataSet.NAME()): o.GetBlock(i)
                for i in range(o.GetNumberOfBlocks())}
    return {"body": o}


class Run:
    """The committed steps of a results file, their frames and the values every view must hold."""

    def __init__(self, r):
        self.r = r
        S, m = r.completed, r.mesh
        self.T, self.E = len(m.triangles), len(m.edges)
        self.C = 0 if r.contact is None else len(r.contact.edges)
        every = int(r.attrs.get("frame_every", 1))
        self.every = every
        self.frames = [n for n in range(S) if n % every == 0 or n == r.n_steps]
        self.disp, self.vm, self.sxx = reference(r)
        self.contact_pts = fields.contact_points(r) if self.C else None
        self.blocks = {"body": (3 * self.T, self.T, ["displacement"], BODY_CELLS)}
        self.normal = self.C and r.contact.pressure is not None
        self.contact_cells = CONTACT_CELLS + (NORMAL_CELLS if self.normal else [])
        if self.C:
            self.blocks["contact"] = (2 * self.C, self.C, ["displacement"], self.contact_cells)


def check_tresca(c, run):
    r = run.r
    if run.C:
        m, ct = r.mesh, r.contact
        length = np.linalg.norm(np.diff(m.points[m.edges[ct.edges]], axis=1)[:, 0], axis=1)
        if ct.mu is not None:
            c.close(ct.sigma_t, -ct.mu / length, "sigma_t = -mu/|e|", 1e-14)


def check_audit(c, r, views, budget):
    """The energy audit: its balance (``tresca_py.audit``) and its terms against the stored fields
    (``tresca_py.audit_evidence``); a file of the Rust solver (it has the views) without its audit fails, and an
    audit the step checksums do not cover is said to be so. ``budget``: ``audit.read``'s series, read in
    ``main`` where a damaged audit is an error of the file."""
    if budget is None:
        c.check(not views, "energy audit: the file has none (tresca/steps/stored_energy, ...): deleted, or written "
                           "by a version before the audit")
        if not views:
            print("no energy audit (the Python solvers write none)")
        return
    print(audit.summary(budget))
    if not r.audit_checksummed:
        print("note: energy audit not covered by the step checksums (a file of a version before they covered it)")
    problems, notes = audit_evidence.recompute(r, budget)
    for m in notes:
        print(f"note: {m}")
    for m in audit.problems(budget, audit.rounding(r.path, audit.largest_work(budget))) + problems:
        c.check(False, m)


def check_vtkhdf(c, run, h5):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy as v2n
    vtkhdf_layout.validate(h5)
    r = vtk.vtkHDFReader()
    r.SetFileName(h5)
    r.UpdateInformation()
    frames, res = run.frames, run.r
    c.check(r.GetNumberOfSteps() == len(frames), f"VTKHDF: {r.GetNumberOfSteps()} steps, expected {len(frames)} frames")
    for k, n in enumerate(frames[: r.GetNumberOfSteps()]):
        r.SetStep(k)
        r.Update()
        blocks = blocks_of(r.GetOutputDataObject(0), vtk)
        c.check(sorted(blocks) == sorted(run.blocks), f"VTKHDF blocks {sorted(blocks)}, expected {sorted(run.blocks)}")
        for name, (npt, ncl, pnames, cnames) in run.blocks.items():
            b = blocks.get(name)
            if not c.check(b is not None, f"VTKHDF block {name} missing"):
                continue
            c.check(b.GetNumberOfPoints() == npt and b.GetNumberOfCells() == ncl,
                    f"VTKHDF {name} frame {k}: {b.GetNumberOfPoints()} points, {b.GetNumberOfCells()} cells; "
                    f"expected {npt}, {ncl}")
            cells, pts = array_names(b.GetCellData()), array_names(b.GetPointData())
            c.check(cells == sorted(cnames), f"VTKHDF {name} cell arrays {cells}")
            c.check(pts == pnames, f"VTKHDF {name} point arrays {pts}")
        body, cont = blocks.get("body"), blocks.get("contact")
        if body is not None and body.GetPointData().GetArray("displacement") is not None:
            d = v2n(body.GetPointData().GetArray("displacement"))
            c.close(d[:, :2], run.disp[n], f"VTKHDF displacement frame {k} (step {n})")
            c.check(np.all(d[:, 2] == 0), "VTKHDF displacement z != 0")
            if body.GetCellData().GetArray("von_mises") is not None:
                c.close(v2n(body.GetCellData().GetArray("von_mises")), run.vm[n], f"VTKHDF von_mises frame {k}", 2e-5)
                # σxx, zero in exact arithmetic in a uniaxial state, is rounding of the stress's size (von Mises)
                c.close(v2n(body.GetCellData().GetArray("stress"))[:, 0], run.sxx[n], f"VTKHDF stress xx frame {k}",
                        2e-5, float(np.max(np.abs(run.vm[n]), initial=0.0)))
        if run.C and cont is not None and array_names(cont.GetCellData()) == sorted(run.contact_cells):
            cd = cont.GetCellData()
            c.close(v2n(cd.GetArray("sigma_t")), res.contact.sigma_t[n], f"VTKHDF sigma_t frame {k}")
            c.close(v2n(cd.GetArray("slip")), res.contact.slip[n], f"VTKHDF slip frame {k}")
            c.check(np.array_equal(v2n(cd.GetArray("stick_slip")), res.contact.state[n]),
                    f"VTKHDF stick_slip frame {k}")
            c.close(v2n(cont.GetPointData().GetArray("displacement"))[:, :2], run.disp[n][run.contact_pts],
                    f"VTKHDF contact displacement frame {k}")
            check_normal(c, run, cd, n, f"VTKHDF frame {k}")
        tval = r.GetOutputInformation(0).Get(vtk.vtkStreamingDemandDrivenPipeline.TIME_STEPS())
        if k == 0 and tval is not None:
            c.close(np.array(tval), res.times[frames], "VTKHDF time values", 1e-15)


def check_meshio(c, run, xdmf):
    import meshio
    frames, times = run.frames, run.r.times
    with meshio.xdmf.TimeSeriesReader(xdmf) as rd:
        points, cells = rd.read_points_cells()
        c.check(len(points) == 3 * run.T, f"XDMF: {len(points)} points, expected {3 * run.T}")
        c.check([b.type for b in cells] == ["triangle"] and len(cells[0].data) == run.T,
                f"XDMF (meshio): cells {cells}")
        c.check(rd.num_steps == len(frames), f"XDMF: {rd.num_steps} steps, expected {len(frames)}")
        for k in range(min(rd.num_steps, len(frames))):
            t, pd, cd = rd.read_data(k)
            n = frames[k]
            c.check(abs(t - times[n]) <= 1e-12 * max(1.0, abs(times[n])), f"XDMF time {t} != {times[n]}")
            c.close(pd["displacement"][:, :2], run.disp[n], f"XDMF displacement frame {k}")
            c.close(np.concatenate(cd["von_mises"]), run.vm[n], f"XDMF von_mises frame {k}", 2e-5)
            c.check(sorted(cd) == sorted(BODY_CELLS), f"XDMF (meshio) cell arrays {sorted(cd)}")


def check_vtkxdmf(c, run, xdmf):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy as v2n
    x = vtk.vtkXdmfReader()
    x.SetFileName(xdmf)
    x.UpdateInformation()
    tsteps = x.GetOutputInformation(0).Get(vtk.vtkStreamingDemandDrivenPipeline.TIME_STEPS()) or []
    frames, res = run.frames, run.r
    c.check(len(tsteps) == len(frames), f"XDMF (vtkXdmfReader): {len(tsteps)} time steps, expected {len(frames)}")
    for k in sorted({0, min(len(tsteps), len(frames)) - 1}) if len(tsteps) and len(frames) else []:
        x.UpdateTimeStep(tsteps[k])
        blocks = blocks_of(x.GetOutputDataObject(0), vtk)
        c.check(sorted(blocks) == sorted(run.blocks), f"XDMF (vtkXdmfReader) blocks {sorted(blocks)}")
        n = frames[k]
        body = blocks.get("body")
        if body is not None and body.GetCellData().GetArray("von_mises") is not None:
            c.close(v2n(body.GetCellData().GetArray("von_mises")), run.vm[n], f"XDMF (VTK) von_mises frame {k}", 2e-5)
            c.check(array_names(body.GetCellData()) == sorted(BODY_CELLS), "XDMF (VTK) body cell arrays")
        if run.C and "contact" in blocks:
            cd = blocks["contact"].GetCellData()
            if c.check(array_names(cd) == sorted(run.contact_cells),
                       f"XDMF (VTK) contact cell arrays {array_names(cd)}"):
                check_normal(c, run, cd, n, f"XDMF (VTK) frame {k}")
                c.close(v2n(cd.GetArray("slip")), res.contact.slip[n], f"XDMF (VTK) slip frame {k}")
                c.check(np.array_equal(v2n(cd.GetArray("stick_slip")), res.contact.state[n]),
                        f"XDMF (VTK) stick_slip frame {k}")


def check_normal(c, run, cd, n, where):
    """The contact block's pressure, gap (f32 of /tresca's) and status (exact) at step n, with normal unknowns."""
    if not run.normal:
        return
    from vtk.util.numpy_support import vtk_to_numpy as v2n
    ct = run.r.contact
    c.close(v2n(cd.GetArray("pressure")), ct.pressure[n], f"{where} pressure")
    c.close(v2n(cd.GetArray("gap")), ct.gap[n], f"{where} gap")
    c.check(np.array_equal(v2n(cd.GetArray("status")), ct.status[n]), f"{where} status")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("h5")
    ap.add_argument("--xdmf", help="sidecar (default: same stem, .xdmf)")
    args = ap.parse_args(argv)
    xdmf = args.xdmf or os.path.splitext(args.h5)[0] + ".xdmf"
    try:
        r = results.read(args.h5)
        views = has_views(r.path)
        if views or args.xdmf:
            paths.check_sidecar(r.path, xdmf)
        budget = audit.read(r.path, r.completed)
    except (results.ResultsError, paths.PathError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    run = Run(r)
    c = Checker()
    print(f"{args.h5}: {r.completed} steps, {len(run.frames)} frames (every {run.every}), {run.T} triangles, "
          f"{run.E} edges, {run.C} contact edges, status {r.status!r}")
    check_tresca(c, run)
    check_audit(c, r, views, budget)
    readers = (("VTKHDF (vtkHDFReader)", check_vtkhdf, r.path), ("XDMF (meshio)", check_meshio, os.path.abspath(xdmf)),
               ("XDMF (vtkXdmfReader)", check_vtkxdmf, os.path.abspath(xdmf)))
    if not views:
        print(f"no /VTKHDF or /xdmf views (solver {r.attrs.get('solver', '?')!r}): the tresca group alone is checked")
        readers = ()
    for name, step, path in readers:
        try:
            step(c, run, path)
        except (Exception, SystemExit) as err:  # a reader that fails on a damaged view is a finding, not a crash
            c.check(False, f"{name} failed: {type(err).__name__}: {str(err).strip()[:200]}")
    if c.failures:
        print(f"FAILED ({len(c.failures)}):")
        for m in c.failures[:50]:
            print("  " + m)
        return 1
    print("OK: VTKHDF (vtkHDFReader), XDMF (meshio, vtkXdmfReader) and the tresca group agree" if views
          else "OK: the tresca group is valid")
    return 0


def has_views(path):
    """True if the results file holds the visualisation views (``/VTKHDF`` or ``/xdmf``), as the Rust solver
    writes them; the Python solvers' files hold ``/tresca`` alone."""
    import h5py
    with h5py.File(path, "r") as f:
        return "VTKHDF" in f or "xdmf" in f
