"""ParaView as users meet it: Debian's ParaView (pvpython, on a virtual X server) opens the files of a finished, a
killed and a resumed run with each XDMF reader, with the solver's values, and renders a picture that
shows the body and the contact line; and a finished run with unilateral contact, whose contact line also
holds the normal condition.

    .venv/bin/python verification/paraview_check.py [--skip-missing] [--json OUT]

The check is tresca_py/verify/paraview.py; this file is its entry point and, with --dump, the part that runs
inside pvpython (Debian's Python, without the tresca_py package: it imports nothing of it).

Requirement (make verify V1-paraview, make test): for each file, `XDMFReader`, `Xdmf3ReaderS` and
`Xdmf3ReaderT` (opened by a bare relative name with XDMFReader, by absolute path with the Xdmf3 readers,
whose 5.11 versions abort on bare names) see exactly the committed frames as a two-block dataset —
the body (triangles: displacement, strain, stress, von_mises) and the contact line (Γ_C edges:
displacement, sigma_t, slip, slip_increment, stick_slip, and on a scene with normal unknowns
(mms_signorini_moving) also pressure, gap and status) — with von Mises, displacement, slip and
stick/slip (and pressure, gap, status) equal to the values of `/tresca` at two times; and `scripts/paraview_view.py`
renders a PNG of the last frame (relative path) whose pixels show a coloured body and the red/blue contact
line. Pictures are kept in out/paraview/. With --skip-missing a machine without `pvpython` passes with a
message (make test); `make paraview` installs it (Debian: paraview python3-paraview xvfb xauth).
"""
import json
import os
import sys


# ---------------------------------------------------------------- run inside pvpython (--dump)
def dump(xdmf, reader_name, which):
    """Print JSON: time steps and, at the frames `which`, each block's arrays (read by pvpython)."""
    import paraview.simple as pv
    from paraview import servermanager as sm
    R = getattr(pv, reader_name)
    r = R(FileNames=[xdmf]) if reader_name == "XDMFReader" else R(FileName=[xdmf])
    r.UpdatePipelineInformation()
    times = list(r.TimestepValues) if r.TimestepValues else []
    out = {"times": times, "frames": {}}
    for k in which:
        k = len(times) // 2 if k == "mid" else int(k)
        k = k if k >= 0 else len(times) + k  # -1: the last frame
        if not 0 <= k < len(times):
            continue
        r.UpdatePipeline(times[k])
        d = sm.Fetch(r)
        blocks = {}
        it = d.NewIterator()
        it.InitTraversal()
        while not it.IsDoneWithTraversal():
            b = it.GetCurrentDataObject()
            arrays = {}
            for data in (b.GetPointData(), b.GetCellData()):
                for i in range(data.GetNumberOfArrays()):
                    a = data.GetArray(i)
                    arrays[a.GetName()] = [[a.GetComponent(j, c) for c in range(a.GetNumberOfComponents())]
                                           for j in range(a.GetNumberOfTuples())]
            kind = "contact" if "slip" in arrays else "body"
            blocks[kind] = {
                "points": b.GetNumberOfPoints(),
                "cells": b.GetNumberOfCells(),
                "cell_arrays": sorted(
                    b.GetCellData().GetArrayName(i) for i in range(b.GetCellData().GetNumberOfArrays())
                ),
                "arrays": arrays,
            }
            it.GoToNextItem()
        out["frames"][str(k)] = blocks
    print("JSON" + json.dumps(out))
    sys.stdout.flush()
    os._exit(0)


if __name__ == "__main__":
    if len(sys.argv) == 5 and sys.argv[1] == "--dump":
        dump(sys.argv[2], sys.argv[3], sys.argv[4].split(","))
    from tresca_py.verify.paraview import main
    sys.exit(main())
