"""The ParaView pipeline of ``tresca_py.paraview_view`` (runs under pvpython; imports ``paraview``): the
deformed body coloured by von Mises over the grey reference mesh and, when the run has a contact block, the
contact line coloured stick / slip.

The warped body shows gaps between triangles: a Crouzeix–Raviart field is continuous only at edge
midpoints, so each triangle carries its own linear field and neighbours separate at their vertices.
"""
import os
import time

from paraview.simple import (ColorBy, ExtractBlock, GetActiveViewOrCreate, GetColorTransferFunction,
                             GetScalarBar, Render, SaveScreenshot, Show, Text, WarpByVector, XDMFReader)

from . import paths


class RenderError(RuntimeError):
    """ParaView could not show the file."""


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


def open_run(p):
    """The reader of a checked plan: the XDMF sidecar, or /VTKHDF (ParaView >= 5.13)."""
    if p["xdmf"] is None:
        if version() < (5, 13):
            raise RenderError(f"ParaView {'.'.join(map(str, version()))} cannot read temporal VTKHDF collections "
                              "(5.13 or newer can); drop --vtkhdf to read the XDMF sidecar")
        from paraview.simple import VTKHDFReader
        return VTKHDFReader(FileName=[p["h5"]]), "VTKHDF"
    return XDMFReader(FileNames=[p["xdmf"]]), "XDMF"


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


def show_contact(line, view, scale, size):
    """The contact line, warped, coloured stick / slip, in front of the body."""
    dc = Show(WarpByVector(Input=line, Vectors=["POINTS", "displacement"], ScaleFactor=scale), view)
    ColorBy(dc, ("CELLS", "stick_slip"))
    dc.LineWidth = 5.0
    dc.Position = [0.0, 0.0, 0.05 * size]
    ss = GetColorTransferFunction("stick_slip")
    ss.InterpretValuesAsCategories = 1
    ss.Annotations = ["0", "stick", "1", "slip"]
    ss.IndexedColors = [0.12, 0.35, 0.95, 0.9, 0.1, 0.1]
    scalar_bar(ss, view, "contact line", "Horizontal", [0.35, 0.03], 0.3)
    dc.SetScalarBarVisibility(view, True)


def show_body(body, view, scale, size, sample):
    """The grey reference mesh behind the warped body coloured by von Mises."""
    ref = Show(body, view)
    ref.SetRepresentationType("Wireframe")
    ref.Position = [0.0, 0.0, -0.05 * size]
    ColorBy(ref, None)
    ref.AmbientColor = ref.DiffuseColor = [0.8, 0.8, 0.8]
    db = Show(WarpByVector(Input=body, Vectors=["POINTS", "displacement"], ScaleFactor=scale), view)
    ColorBy(db, ("CELLS", "von_mises"))
    vm_lo, vm_hi = fetch_range(body, "von_mises", sample, 0)
    lut = GetColorTransferFunction("von_mises")
    lut.ApplyPreset("Viridis (matplotlib)", True)
    lut.RescaleTransferFunction(max(vm_lo, 0.0), vm_hi if vm_hi > vm_lo else vm_lo + 1.0)
    lut.AutomaticRescaleRangeMode = "Never"
    scalar_bar(lut, view, "von Mises stress (plane strain)", "Vertical", [0.89, 0.12], 0.7)
    db.SetScalarBarVisibility(view, True)


def render(p, args):
    """Draw the plan ``p`` (``paraview_view.plan``); returns [(screenshot, time started)]."""
    reader, kind = open_run(p)
    reader.UpdatePipelineInformation()
    times = list(reader.TimestepValues) if reader.TimestepValues else [0.0]
    # a run without Γ_C has one block: the reader's output is then the body itself, and no block is
    # extracted (ExtractBlock of a missing block crashes pvpython 5.11 in vtkExtractBlockUsingDataAssembly)
    has_contact = "contact" in p["blocks"]
    if p["xdmf"] is None:  # /VTKHDF (ParaView >= 5.13, not available here to test): count the blocks read
        reader.UpdatePipeline(times[-1])
        has_contact = reader.GetDataInformation().DataInformation.GetNumberOfDataSets() >= 2
    body = ExtractBlock(Input=reader, Selectors=["/Root/body"]) if has_contact else reader
    body.UpdatePipeline(times[-1])
    bounds = body.GetDataInformation().GetBounds()
    size = max(bounds[1] - bounds[0], bounds[3] - bounds[2])
    if not (size > 0):
        raise RenderError(f"{p['xdmf'] or p['h5']}: ParaView read no body (bounds {bounds})")
    pick = times[-1] if args.time is None else args.time
    shown = times if p["frames"] else [min(times, key=lambda t: abs(t - pick))]
    sample = times[:: max(1, len(times) // 50)] + [times[-1]] if p["frames"] else shown
    umax = fetch_range(body, "displacement", sample)[1]
    scale = args.scale or (0.1 * size / umax if umax > 0 else 1.0)
    view = GetActiveViewOrCreate("RenderView")
    view.ViewSize = args.size
    view.OrientationAxesVisibility = 0
    try:
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    view.Background = [1.0, 1.0, 1.0]
    show_body(body, view, scale, size, sample)
    if has_contact:
        show_contact(ExtractBlock(Input=reader, Selectors=["/Root/contact"]), view, scale, size)
    label = Text()
    lt = Show(label, view)
    lt.Color = [0, 0, 0]
    lt.FontSize = 14
    lt.WindowLocation = "Upper Center"
    view.InteractionMode = "2D"
    view.ViewTime = shown[-1]
    Render(view)
    view.ResetCamera()
    view.GetActiveCamera().Zoom(0.85)
    line = "body: von Mises; contact line: stick / slip" if has_contact else "body: von Mises (no contact line)"
    outs = [os.path.join(p["frames"], f"frame_{k:04d}.png") for k in range(len(shown))] if p["frames"] else [p["out"]]
    # the rule of every output (tresca_py.paths), for every picture before the first is drawn
    paths.distinct([(o, "screenshot") for o in outs], p["inputs"])
    for o in outs:
        paths.new_output(o, "screenshot", p["force"])
    written = []
    for t, out in zip(shown, outs, strict=True):
        label.Text = (f"{p['name']} ({kind}): t = {t:.4g} (frame {times.index(t) + 1} of {len(times)})\n"
                      f"displacement magnified x{scale:.3g} (grey: reference); {line}")
        view.ViewTime = t
        Render(view)
        start = time.time()
        paths.write_named(out, lambda tmp: SaveScreenshot(tmp, view, ImageResolution=args.size), "screenshot",
                          p["force"])
        written.append((out, start))
        print(out)
    return written
