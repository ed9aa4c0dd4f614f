"""One command to look at a tresca-cr run in ParaView (pvpython 5.11 from Debian 12 and newer).

    xvfb-run -a pvpython scripts/paraview_view.py run.h5 [-o view.png] [--time T] [--frames DIR] [--scale S]

(`run.h5` or `run.xdmf`, any path form: bare, ./relative, absolute.) Shows the deformed body (the CR
displacement, warped with a stated scale: by default 10 % of the body's size over the largest |u| of the
shown frames) coloured by von Mises stress, and the contact line Γ_C coloured by stick (blue) / slip
(red), with the time, step and scale written on the picture. Saves one screenshot (`-o`, default
`<run>_view.png`, at the last stored frame or `--time`) or, with `--frames DIR`, one PNG per stored frame.
Without a display use `xvfb-run -a pvpython ...`; in the GUI, `Tools > Python Shell > Run Script` works too.

Reader: the XDMF sidecar through `XDMFReader`, which ParaView 5.11 and newer read with every frame; a killed
run shows exactly its committed frames. `--vtkhdf` reads the `/VTKHDF` collection instead (ParaView ≥ 5.13).
Paths are made absolute before opening: 5.11's Xdmf3 readers abort on a bare relative name.

Everything is checked before ParaView opens anything (``tresca_py.paths``; one ``error:`` line, exit 2): the
results file (a readable regular HDF5 file of its recorded length), its sidecar `<run>.xdmf` (present, and
referencing this `<run>.h5`: a pair copied or renamed keeps pointing at the original's data), the outputs
(not a directory, in a directory where files can be created), `--size` (1 .. 16384 pixels), `--scale` and
`--time` (finite). A run without a contact part (no Γ_C) has only the body block, shown without the contact
line. A screenshot that ParaView did not write is an error (exit 1).

This module runs under ParaView's own Python: it imports only the standard library, ``tresca_py.paths`` (the
same) and, inside the functions that render, ``paraview``.
"""
import argparse
import math
import os
import sys

from . import paths

MAX_PIXELS = 16384


def pixels(text):
    v = int(text)
    if not 1 <= v <= MAX_PIXELS:
        raise argparse.ArgumentTypeError(f"must be 1 .. {MAX_PIXELS} pixels, not {text}")
    return v


def finite(text, lo=-math.inf):
    v = float(text)
    if not (math.isfinite(v) and v >= lo):
        raise argparse.ArgumentTypeError(f"must be a finite number{' >= 0' if lo == 0 else ''}, not {text}")
    return v


def arguments(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", help="run.h5 or run.xdmf")
    ap.add_argument("-o", "--out", help="screenshot (default: <run>_view.png)")
    ap.add_argument("--time", type=finite, help="time to show (nearest stored frame; default: the last)")
    ap.add_argument("--frames", help="write one PNG per stored frame into this directory")
    ap.add_argument("--scale", type=lambda t: finite(t, 0.0), default=0.0,
                    help="displacement magnification (default 0: automatic)")
    ap.add_argument("--size", type=pixels, nargs=2, default=[1200, 800], help="picture size in pixels")
    ap.add_argument("--vtkhdf", action="store_true", help="read /VTKHDF (ParaView >= 5.13) instead of the XDMF")
    ap.add_argument("--force", action="store_true", help="replace an existing screenshot (or frame)")
    return ap.parse_args(argv)


def plan(args):
    """{h5, xdmf, blocks, out, frames, name, inputs, force} of valid arguments, or PathError naming the problem."""
    given = os.path.abspath(args.results)
    stem, ext = os.path.splitext(given)
    h5 = paths.hdf5_file(stem + ".h5" if ext == ".xdmf" else given)
    xdmf, blocks = None, ["body", "contact"]
    if not args.vtkhdf:
        xdmf = stem + ".xdmf"
        if not os.path.lexists(xdmf):
            raise paths.PathError(f"{xdmf}: no such file: the XDMF sidecar tresca-cr writes next to {h5} is missing "
                                  "(is this a tresca-cr results file?)")
        blocks = paths.check_sidecar(h5, xdmf)
    out = frames = None
    inputs = [(h5, "results file")] + ([(xdmf, "XDMF sidecar")] if xdmf else [])
    if args.frames:
        frames = paths.output_subdir(args.frames, "frames directory")
    else:
        out = args.out or stem + "_view.png"
        paths.distinct([(out, "screenshot")], inputs)
        out = paths.output_file(paths.new_output(out, "screenshot", args.force), "screenshot")
    return {"h5": h5, "xdmf": xdmf, "blocks": blocks, "out": out, "frames": frames, "name": os.path.basename(stem),
            "inputs": inputs, "force": args.force}


def main(argv=None):
    args = arguments(argv)
    try:
        p = plan(args)
    except paths.PathError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    try:
        import paraview.simple  # noqa: F401
    except ImportError:
        print("error: ParaView's Python is needed: run `xvfb-run -a pvpython scripts/paraview_view.py ...`",
              file=sys.stderr)
        return 2
    from . import paraview_render
    try:
        written = paraview_render.render(p, args)
    except (paraview_render.RenderError, paths.PathError) as err:
        print(f"error: {err}", file=sys.stderr)
        sys.stderr.flush()
        os._exit(1)
    for out, start in written:
        if not (os.path.isfile(out) and os.path.getsize(out) > 0 and os.path.getmtime(out) >= start - 1):
            print(f"error: {out}: ParaView did not write the screenshot", file=sys.stderr)
            sys.stderr.flush()
            os._exit(1)
    sys.stdout.flush()
    os._exit(0)  # skip the render window teardown, which can raise X errors under xvfb
