#!/usr/bin/env python3
"""Check a tresca-cr results file through three independent readers.

    .venv/bin/python scripts/check_results.py run.h5 [--xdmf run.xdmf]

* VTK's ``vtkHDFReader`` (the VTKHDF view, a collection of the blocks ``body`` and ``contact``): numbers of
  points, cells and frames, each block's array names, and every frame's displacement / von Mises / contact arrays against values recomputed here from ``tresca/u``
  (the CR field evaluated at triangle vertices: U(v_j) = sum_{i != j} U_{e_i} - U_{e_j}).
* meshio's XDMF ``TimeSeriesReader`` (the sidecar; it reads the last temporal collection, the body): same
  numbers and values; VTK's ``vtkXdmfReader``: both blocks, contact fields at the first and last frame.
* h5py (the ``tresca`` group): shapes of the README table, ``completed`` attribute, finiteness, and the
  per-step checksums ``tresca/steps/checksum`` (XXH64 of each step's rows, recomputed here with numpy; the
  first step that does not match is named: storage corruption after the file was written).

Also for the file of a killed run (status ``running``): its series have room for every step of the run
and only the first ``completed`` rows are data; every reader must still open it and see exactly the
committed steps and frames. tresca-cr moves a file under its name only at its first commit, so a file
without a committed step is reported as an error.

Exits non-zero with one line per mismatch.
"""
import argparse
import os
import sys

import h5py
import numpy as np

FAIL = []


def check(ok, msg):
    if not ok:
        FAIL.append(msg)
    return ok


def close(a, b, what, rtol=2e-6):
    a, b = np.asarray(a, float), np.asarray(b, float)
    if not check(a.shape == b.shape, f"{what}: shape {a.shape} != {b.shape}"):
        return
    scale = max(float(np.max(np.abs(b))) if b.size else 0.0, 1e-300)
    err = float(np.max(np.abs(a - b))) if a.size else 0.0
    check(err <= rtol * scale, f"{what}: max difference {err:.3e} (scale {scale:.3e})")


# XXH64 (seed 0), vectorised over the rows of a (steps, bytes) uint8 array: the checksum of tresca/steps/checksum
_P = [np.uint64(v) for v in (0x9E3779B185EBCA87, 0xC2B2AE3D27D4EB4F, 0x165667B19E3779F9, 0x85EBCA77C2B2AE63,
                             0x27D4EB2F165667C5)]


def _rotl(x, r):
    return (x << np.uint64(r)) | (x >> np.uint64(64 - r))


def _round(acc, lane):
    return _rotl(acc + lane * _P[1], 31) * _P[0]


def xxh64_rows(rows):
    rows = np.ascontiguousarray(rows, dtype=np.uint8)
    S, L = rows.shape
    with np.errstate(over="ignore"):
        words = rows[:, : L // 8 * 8].copy().view("<u8")
        i = 0
        if L >= 32:
            v = [np.full(S, x, dtype=np.uint64) for x in (_P[0] + _P[1], _P[1], np.uint64(0), np.uint64(0) - _P[0])]
            for s in range(L // 32):
                for j in range(4):
                    v[j] = _round(v[j], words[:, 4 * s + j])
            h = _rotl(v[0], 1) + _rotl(v[1], 7) + _rotl(v[2], 12) + _rotl(v[3], 18)
            for j in range(4):
                h = (h ^ _round(np.zeros(S, np.uint64), v[j])) * _P[0] + _P[3]
            i = L // 32 * 32
        else:
            h = np.full(S, _P[4], dtype=np.uint64)
        h = h + np.uint64(L)
        while i + 8 <= L:
            h = _rotl(h ^ _round(np.zeros(S, np.uint64), words[:, i // 8]), 27) * _P[0] + _P[3]
            i += 8
        if i + 4 <= L:
            h = _rotl(h ^ (rows[:, i:i + 4].copy().view("<u4")[:, 0].astype(np.uint64) * _P[0]), 23) * _P[1] + _P[2]
            i += 4
        while i < L:
            h = _rotl(h ^ (rows[:, i].astype(np.uint64) * _P[4]), 11) * _P[0]
            i += 1
        h = (h ^ (h >> np.uint64(33))) * _P[1]
        h = (h ^ (h >> np.uint64(29))) * _P[2]
        return h ^ (h >> np.uint64(32))


CHECKSUMMED = ["times", "u", "energy", "steps/iterations", "steps/residual", "steps/n_stick", "steps/n_slip",
               "steps/wall_time", "contact/slip", "contact/sigma_t", "contact/state", "contact/mu", "contact/dof",
               "errors/energy", "errors/h1", "errors/l2"]


def first_bad_step(g, S):
    """The first of the S committed steps whose rows do not match tresca/steps/checksum (None: all match)."""
    names = [k for k in CHECKSUMMED if k in g]
    per_step = sum(g[k].dtype.itemsize * int(np.prod(g[k].shape[1:])) for k in names)
    block = max(1, (64 << 20) // max(per_step, 1))  # steps per read: about 64 MB
    stored = g["steps/checksum"][:S]
    for a in range(0, S, block):
        b = min(S, a + block)
        parts = [np.ascontiguousarray(g[k][a:b]).reshape(b - a, -1).view(np.uint8) for k in names]
        bad = np.nonzero(xxh64_rows(np.concatenate(parts, axis=1)) != stored[a:b])[0]
        if len(bad):
            return a + int(bad[0])
    return None


def reference(g, S):
    """Expected VTK arrays per step from the tresca group (f64)."""
    tri = g["mesh/triangles"][()]
    pts = g["mesh/points"][()]
    edges = g["mesh/edges"][()]
    # edge opposite local vertex i of each triangle
    index = {tuple(sorted(e)): k for k, e in enumerate(edges)}
    te = np.array([[index[tuple(sorted((t[(i + 1) % 3], t[(i + 2) % 3])))] for i in range(3)] for t in tri])
    u = g["u"][:S]  # (S, E, 2)
    U = u[:, te, :]  # (S, T, 3, 2)
    disp = U.sum(axis=2, keepdims=True) - 2.0 * U  # value at vertex j
    # gradient of the P1 field on each triangle from vertex values
    x = pts[tri]  # (T, 3, 2)
    a2 = (x[:, 1, 0] - x[:, 0, 0]) * (x[:, 2, 1] - x[:, 0, 1]) - (x[:, 1, 1] - x[:, 0, 1]) * (x[:, 2, 0] - x[:, 0, 0])
    gl = np.zeros((len(tri), 3, 2))
    for i in range(3):
        b, c = x[:, (i + 1) % 3], x[:, (i + 2) % 3]
        gl[:, i, 0] = (b[:, 1] - c[:, 1]) / a2
        gl[:, i, 1] = (c[:, 0] - b[:, 0]) / a2
    G = np.einsum("stja,tjb->stab", disp, gl)
    E, nu = float(g.attrs["E"]), float(g.attrs["nu"])
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    exx, eyy, exy = G[..., 0, 0], G[..., 1, 1], 0.5 * (G[..., 0, 1] + G[..., 1, 0])
    tr = exx + eyy
    sxx, syy, szz, sxy = lam * tr + 2 * mu * exx, lam * tr + 2 * mu * eyy, lam * tr, 2 * mu * exy
    vm = np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2) + 3 * sxy ** 2)
    return disp.reshape(len(u), 3 * len(tri), 2), vm, sxx


BODY_CELLS = ["strain", "stress", "von_mises"]
CONTACT_CELLS = ["sigma_t", "slip", "slip_increment", "stick_slip"]


def array_names(data):
    return sorted(data.GetArrayName(i) for i in range(data.GetNumberOfArrays()))


def contact_points(g):
    """Broken-mesh point (3t + j) of each of the 2C contact line points: the ends of Γ_C edge k as
    vertices of its one triangle, in the order (j+1, j+2) after the local vertex j opposite the edge."""
    tri, edges = g["mesh/triangles"][()], g["mesh/edges"][()]
    out = []
    for e in g["contact/edges"][()]:
        a, b = sorted(edges[e])
        for t, tv in enumerate(tri):
            for i in range(3):
                if sorted((tv[(i + 1) % 3], tv[(i + 2) % 3])) == [a, b]:
                    out += [3 * t + (i + 1) % 3, 3 * t + (i + 2) % 3]
                    break
            else:
                continue
            break
    return np.array(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    ap.add_argument("h5")
    ap.add_argument("--xdmf", help="sidecar (default: same stem, .xdmf)")
    args = ap.parse_args(argv)
    xdmf = args.xdmf or os.path.splitext(args.h5)[0] + ".xdmf"

    f = h5py.File(args.h5, "r")
    g = f["tresca"]
    S = int(g["steps"].attrs["completed"])
    T, E = len(g["mesh/triangles"]), len(g["mesh/edges"])
    C = len(g["contact/edges"]) if "contact" in g else 0
    if not check(S >= 1, "no committed step: tresca-cr never leaves such a file under its name"):
        print(f"FAILED: {args.h5}: {FAIL[0]}")
        return 1
    # a finished or stopped run holds exactly its completed steps; a killed one ("running") has room for all
    killed = g.attrs["status"] == "running"
    R = int(g.attrs["steps"]) + 1 if killed else S
    check(S <= R, f"completed {S} > steps + 1")
    check(g["times"].shape == (R,), f"tresca/times shape {g['times'].shape}, completed {S}, rows {R}")
    check(g["u"].shape == (R, E, 2), f"tresca/u shape {g['u'].shape}")
    for k in ("iterations", "residual", "n_stick", "n_slip", "wall_time"):
        check(g[f"steps/{k}"].shape == (R,), f"tresca/steps/{k} shape")
    if C:
        for k in ("slip", "sigma_t", "state", "mu"):
            check(g[f"contact/{k}"].shape == (R, C), f"tresca/contact/{k} shape")
        close(g["contact/sigma_t"][:S], -g["contact/mu"][:S] /
              np.linalg.norm(np.diff(g["mesh/points"][()][g["mesh/edges"][()][g["contact/edges"][()]]], axis=1)[:, 0], axis=1),
              "sigma_t = -mu/|e|", 1e-14)
    if "steps/checksum" in g:
        bad = first_bad_step(g, S)
        check(bad is None, f"step {bad} does not match its checksum (tresca/steps/checksum): the file was damaged "
                           f"after it was written; steps before it are intact")
    else:
        print(f"{args.h5}: no tresca/steps/checksum (written before checksums were added): not verified")
    for name in ("u", "energy", "times"):
        check(np.all(np.isfinite(g[name][:S])), f"tresca/{name} has non-finite values")
    every = int(g.attrs["frame_every"])
    steps = np.arange(S)
    frames = [n for n in steps if n % every == 0 or n == int(g.attrs["steps"])]
    times = g["times"][:S]
    disp_ref, vm_ref, sxx_ref = reference(g, S)
    P = 3 * T
    contact_pts = contact_points(g) if C else None
    print(f"{args.h5}: {S} steps, {len(frames)} frames (every {every}), {T} triangles, {E} edges, {C} contact edges, "
          f"status {g.attrs['status']!r}")

    # --- VTK vtkHDFReader: a PartitionedDataSetCollection of `body` and `contact`
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy as v2n
    r = vtk.vtkHDFReader()
    r.SetFileName(args.h5)
    r.UpdateInformation()
    check(r.GetNumberOfSteps() == len(frames), f"VTKHDF: {r.GetNumberOfSteps()} steps, expected {len(frames)} frames")
    want_blocks = {"body": (P, T, ["displacement"], BODY_CELLS)}
    if C:
        want_blocks["contact"] = (2 * C, C, ["displacement"], CONTACT_CELLS)
    for k, n in enumerate(frames[: r.GetNumberOfSteps()]):
        r.SetStep(k)
        r.Update()
        o = r.GetOutputDataObject(0)
        if not check(o.IsA("vtkPartitionedDataSetCollection"), f"VTKHDF: {o.GetClassName()}, not a collection"):
            break
        blocks = {o.GetMetaData(i).Get(vtk.vtkCompositeDataSet.NAME()): o.GetPartition(i, 0)
                  for i in range(o.GetNumberOfPartitionedDataSets())}
        check(sorted(blocks) == sorted(want_blocks), f"VTKHDF blocks {sorted(blocks)}")
        for name, (npt, ncl, pnames, cnames) in want_blocks.items():
            b = blocks.get(name)
            if not check(b is not None, f"VTKHDF block {name} missing"):
                continue
            check(b.GetNumberOfPoints() == npt and b.GetNumberOfCells() == ncl,
                  f"VTKHDF {name} frame {k}: {b.GetNumberOfPoints()} points, {b.GetNumberOfCells()} cells; expected {npt}, {ncl}")
            check(array_names(b.GetCellData()) == sorted(cnames), f"VTKHDF {name} cell arrays {array_names(b.GetCellData())}")
            check(array_names(b.GetPointData()) == pnames, f"VTKHDF {name} point arrays {array_names(b.GetPointData())}")
        body, cont = blocks.get("body"), blocks.get("contact")
        if body is not None:
            d = v2n(body.GetPointData().GetArray("displacement"))
            close(d[:, :2], disp_ref[n], f"VTKHDF displacement frame {k} (step {n})")
            check(np.all(d[:, 2] == 0), "VTKHDF displacement z != 0")
            close(v2n(body.GetCellData().GetArray("von_mises")), vm_ref[n], f"VTKHDF von_mises frame {k}", 2e-5)
            close(v2n(body.GetCellData().GetArray("stress"))[:, 0], sxx_ref[n], f"VTKHDF stress xx frame {k}", 2e-5)
        if C and cont is not None:
            close(v2n(cont.GetCellData().GetArray("sigma_t")), g["contact/sigma_t"][n], f"VTKHDF sigma_t frame {k}")
            close(v2n(cont.GetCellData().GetArray("slip")), g["contact/slip"][n], f"VTKHDF slip frame {k}")
            check(np.array_equal(v2n(cont.GetCellData().GetArray("stick_slip")), g["contact/state"][n]),
                  f"VTKHDF stick_slip frame {k}")
            close(v2n(cont.GetPointData().GetArray("displacement"))[:, :2], disp_ref[n][contact_pts],
                  f"VTKHDF contact displacement frame {k}")
        tval = r.GetOutputInformation(0).Get(vtk.vtkStreamingDemandDrivenPipeline.TIME_STEPS())
        if k == 0 and tval is not None:
            close(np.array(tval), times[frames], "VTKHDF time values", 1e-15)

    # --- meshio XDMF time series: reads the last temporal collection, the body
    import meshio
    with meshio.xdmf.TimeSeriesReader(xdmf) as rd:
        points, cells = rd.read_points_cells()
        check(len(points) == P, f"XDMF: {len(points)} points, expected {P}")
        check([c.type for c in cells] == ["triangle"] and len(cells[0].data) == T, f"XDMF (meshio): cells {cells}")
        check(rd.num_steps == len(frames), f"XDMF: {rd.num_steps} steps, expected {len(frames)}")
        for k in range(rd.num_steps):
            t, pd, cd = rd.read_data(k)
            n = frames[k]
            check(abs(t - times[n]) <= 1e-12 * max(1.0, abs(times[n])), f"XDMF time {t} != {times[n]}")
            close(pd["displacement"][:, :2], disp_ref[n], f"XDMF displacement frame {k}")
            close(np.concatenate(cd["von_mises"]), vm_ref[n], f"XDMF von_mises frame {k}", 2e-5)
            check(sorted(cd) == sorted(BODY_CELLS), f"XDMF (meshio) cell arrays {sorted(cd)}")

    # --- VTK's XDMF reader: both blocks, the contact fields at the first and the last frame
    x = vtk.vtkXdmfReader()
    x.SetFileName(xdmf)
    x.UpdateInformation()
    tsteps = x.GetOutputInformation(0).Get(vtk.vtkStreamingDemandDrivenPipeline.TIME_STEPS()) or []
    check(len(tsteps) == len(frames), f"XDMF (vtkXdmfReader): {len(tsteps)} time steps, expected {len(frames)}")
    for k in sorted({0, len(tsteps) - 1}) if len(tsteps) else []:
        x.UpdateTimeStep(tsteps[k])
        o = x.GetOutputDataObject(0)
        blocks = {o.GetMetaData(i).Get(vtk.vtkCompositeDataSet.NAME()): o.GetBlock(i) for i in range(o.GetNumberOfBlocks())}
        check(sorted(blocks) == sorted(want_blocks), f"XDMF (vtkXdmfReader) blocks {sorted(blocks)}")
        n = frames[k]
        if "body" in blocks:
            close(v2n(blocks["body"].GetCellData().GetArray("von_mises")), vm_ref[n], f"XDMF (VTK) von_mises frame {k}", 2e-5)
            check(array_names(blocks["body"].GetCellData()) == sorted(BODY_CELLS), "XDMF (VTK) body cell arrays")
        if C and "contact" in blocks:
            cd = blocks["contact"].GetCellData()
            check(array_names(cd) == sorted(CONTACT_CELLS), f"XDMF (VTK) contact cell arrays {array_names(cd)}")
            close(v2n(cd.GetArray("slip")), g["contact/slip"][n], f"XDMF (VTK) slip frame {k}")
            check(np.array_equal(v2n(cd.GetArray("stick_slip")), g["contact/state"][n]), f"XDMF (VTK) stick_slip frame {k}")
    if FAIL:
        print(f"FAILED ({len(FAIL)}):")
        for m in FAIL[:50]:
            print("  " + m)
        return 1
    print("OK: VTKHDF (vtkHDFReader), XDMF (meshio, vtkXdmfReader) and the tresca group agree")
    return 0


if __name__ == "__main__":
    sys.exit(main())
