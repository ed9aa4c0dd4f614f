"""One command to look at a tresca-cr run in ParaView (pvpython 5.11 from Debian 12 and newer).

    xvfb-run -a pvpython scripts/paraview_view.py run.h5 [-o view.png] [--time T] [--frames DIR] [--scale S]

(`run.h5` or `run.xdmf`, any path form: bare, ./relative, absolute.) Shows the deformed body (the CR
displacement, warped with a stated scale: by default 10 % of the body's size over the largest |u| of the
shown frames) coloured by von Mises stress, and the contact line Γ_C coloured by stick (blue) / slip
(red), with the time, step and scale written on the picture. Saves one screenshot (`-o`, default
`<run>_view.png`, at the last stored frame or `--time`) or, with `--frames DIR`, one PNG per stored frame.
Without a display use `xvfb-run -a pvpython ...`; in the GUI, `Tools > Python Shell > Run Script` works too.

Reader: the XDMF sidecar through `XDMFReader`, which ParaView 5.11 and newer read with every frame; a killed
run shows exactly its committed frames. `--vtkhdf` reads the `/VTKHDF` collection instead (ParaView ≥ 5.13:
5.11's reader knows VTKHDF 1.0 only and would show frame 0). Paths are made absolute before opening:
5.11's Xdmf3 readers abort on a bare relative name (`run.xdmf` makes HDF5 look for `run.xdmfrun.h5`).

The warped body shows gaps between triangles: a Crouzeix–Raviart field is continuous only at edge
midpoints, so each triangle carries its own linear field and neighbours separate at their vertices.
"""
import argparse
import os
import sys

from paraview import servermanager as sm
from paraview.simple import (AnnotateTimeFilter, ColorBy, ExtractBlock, GetActiveViewOrCreate,  # noqa: F401
                             GetColorTransferFunction, GetScalarBar, Render, SaveScreenshot, Show, Text,
                             WarpByVector, XDMFReader)


def scalar_bar(lut, view, title, orientation, position, length):
    """A black-on-white colour legend of `lut` at a fixed place of the view (off the body)."""
    bar = GetScalarBar(lut, view)
    bar.Title = title
    bar.ComponentTitle = ""
    bar.TitleColor = bar.LabelColor = [0, 0, 0]
    bar.WindowLocation = "Any Location"
    bar.Orientation = orientation
    bar.Position = position
    bar.ScalarBarLength = length
    return bar


def version():
    from paraview.simple import GetParaViewVersion
    v = GetParaViewVersion()
    return (v.major, v.minor)


def open_run(path, vtkhdf):
    """The reader of a results file, by absolute path; .h5 opens its .xdmf sidecar unless --vtkhdf."""
    path = os.path.abspath(path)
    stem, ext = os.path.splitext(path)
    if vtkhdf:
        if version() < (5, 13):
            sys.exit(f"error: ParaView {'.'.join(map(str, version()))} cannot read temporal VTKHDF collections "
                     "(5.13 or newer can); drop --vtkhdf to read the XDMF sidecar")
        from paraview.simple import VTKHDFReader
        return VTKHDFReader(FileName=[stem + ".h5"]), "VTKHDF"
    xdmf = stem + ".xdmf" if ext != ".xdmf" else path
    if not os.path.exists(xdmf):
        sys.exit(f"error: {xdmf} not found (tresca-cr writes it next to the .h5 file)")
    return XDMFReader(FileNames=[xdmf]), "XDMF"


def block(src, name):
    return ExtractBlock(Input=src, Selectors=[f"/Root/{name}"])


def fetch_range(src, array, times, comp=-1):
    """Range of an array (component comp; -1 magnitude) over the given times."""
    lo, hi = float("inf"), float("-inf")
    for t in times:
        src.UpdatePipeline(t)
        info = src.GetDataInformation().DataInformation
        a = info.GetPointDataInformation().GetArrayInformation(array) or \
            info.GetCellDataInformation().GetArrayInformation(array)
        if a is None:
            continue
        r = a.GetComponentRange(comp)
        lo, hi = min(lo, r[0]), max(hi, r[1])
    return lo, hi


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", help="run.h5 or run.xdmf")
    ap.add_argument("-o", "--out", help="screenshot (default: <run>_view.png)")
    ap.add_argument("--time", type=float, help="time to show (nearest stored frame; default: the last)")
    ap.add_argument("--frames", help="write one PNG per stored frame into this directory")
    ap.add_argument("--scale", type=float, default=0.0, help="displacement magnification (default: automatic)")
    ap.add_argument("--size", type=int, nargs=2, default=[1200, 800], help="picture size in pixels")
    ap.add_argument("--vtkhdf", action="store_true", help="read /VTKHDF (ParaView >= 5.13) instead of the XDMF")
    args = ap.parse_args(argv)

    reader, kind = open_run(args.results, args.vtkhdf)
    reader.UpdatePipelineInformation()
    times = list(reader.TimestepValues) if reader.TimestepValues else [0.0]
    if not times:
        sys.exit("error: the file holds no frame")
    body, line = block(reader, "body"), block(reader, "contact")
    # scale: 10 % of the body's size over the largest |u| of the frames shown
    reader.UpdatePipeline(times[-1])
    b = body
    b.UpdatePipeline(times[-1])
    bounds = b.GetDataInformation().GetBounds()
    size = max(bounds[1] - bounds[0], bounds[3] - bounds[2])
    shown = times if args.frames else [min(times, key=lambda t: abs(t - (times[-1] if args.time is None else args.time)))]
    sample = times[:: max(1, len(times) // 50)] + [times[-1]] if args.frames else shown
    umax = fetch_range(body, "displacement", sample)[1]
    scale = args.scale or (0.1 * size / umax if umax > 0 else 1.0)
    warp_b = WarpByVector(Input=body, Vectors=["POINTS", "displacement"], ScaleFactor=scale)
    warp_c = WarpByVector(Input=line, Vectors=["POINTS", "displacement"], ScaleFactor=scale)

    view = GetActiveViewOrCreate("RenderView")
    view.ViewSize = args.size
    view.OrientationAxesVisibility = 0
    try:
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    view.Background = [1.0, 1.0, 1.0]
    ref = Show(body, view)  # the reference configuration, light grey, behind the deformed body
    ref.SetRepresentationType("Wireframe")
    ref.Position = [0.0, 0.0, -0.05 * size]
    ColorBy(ref, None)
    ref.AmbientColor = ref.DiffuseColor = [0.8, 0.8, 0.8]
    db = Show(warp_b, view)
    ColorBy(db, ("CELLS", "von_mises"))
    vm_lo, vm_hi = fetch_range(body, "von_mises", sample, 0)
    lut = GetColorTransferFunction("von_mises")
    lut.ApplyPreset("Viridis (matplotlib)", True)
    lut.RescaleTransferFunction(max(vm_lo, 0.0), vm_hi if vm_hi > vm_lo else vm_lo + 1.0)
    lut.AutomaticRescaleRangeMode = "Never"
    scalar_bar(lut, view, "von Mises stress (plane strain)", "Vertical", [0.89, 0.12], 0.7)
    db.SetScalarBarVisibility(view, True)
    dc = Show(warp_c, view)
    ColorBy(dc, ("CELLS", "stick_slip"))
    dc.LineWidth = 5.0
    dc.Position = [0.0, 0.0, 0.05 * size]  # in front of the body
    ss = GetColorTransferFunction("stick_slip")
    ss.InterpretValuesAsCategories = 1
    ss.Annotations = ["0", "stick", "1", "slip"]
    ss.IndexedColors = [0.12, 0.35, 0.95, 0.9, 0.1, 0.1]
    scalar_bar(ss, view, "contact line", "Horizontal", [0.35, 0.03], 0.3)
    dc.SetScalarBarVisibility(view, True)
    label = Text()
    lt = Show(label, view)
    lt.Color = [0, 0, 0]
    lt.FontSize = 14
    lt.WindowLocation = "Upper Center"
    view.InteractionMode = "2D"

    name = os.path.basename(os.path.splitext(args.results)[0])

    def draw(t, out):
        k = times.index(t)
        label.Text = (f"{name} ({kind}): t = {t:.4g} (frame {k + 1} of {len(times)})\n"
                      f"displacement magnified x{scale:.3g} (grey: reference); body: von Mises; contact line: stick / slip")
        view.ViewTime = t
        for s in (warp_b, warp_c):
            s.UpdatePipeline(t)
        Render(view)
        SaveScreenshot(out, view, ImageResolution=args.size)
        print(out)

    view.ViewTime = shown[-1]
    Render(view)
    view.ResetCamera()
    cam = view.GetActiveCamera()
    cam.Zoom(0.85)
    if args.frames:
        os.makedirs(args.frames, exist_ok=True)
        for k, t in enumerate(times):
            draw(t, os.path.join(args.frames, f"frame_{k:04d}.png"))
    else:
        draw(shown[-1], args.out or os.path.splitext(os.path.abspath(args.results))[0] + "_view.png")
    sys.stdout.flush()
    os._exit(0)  # skip the render window teardown, which can raise X errors under xvfb


if __name__ == "__main__":
    sys.exit(main())
