"""The common command line of the Python solvers: SCENE.toml -o OUT.h5 [--refine k] [--steps N] [-q]."""
import sys

from tresca_py.errors import InputError
from tresca_py.scene import SceneError, load_scene
from tresca_py.skfem_cr.cr import Discretisation


def cli(description, argv=None):
    """Common command line: SCENE.toml -o OUT.h5 [--refine k] [--steps N]."""
    import argparse
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("scene", help="scene TOML file")
    ap.add_argument("-o", "--output", help="results file (default: [output] path of the scene)")
    ap.add_argument("--refine", type=int, default=None, help="override [mesh] refine")
    ap.add_argument("--steps", type=int, default=None, help="override the number of uniform time steps")
    ap.add_argument("-q", "--quiet", action="store_true", help="no per-step log")
    args = ap.parse_args(argv)
    return args


def open_scene(args):
    """Load scene + discretisation, turning bad input (InputError) into a clean exit message."""
    try:
        scene = load_scene(args.scene, refine=args.refine, steps=args.steps)
        out = args.output or scene.output
        if not out:
            raise SceneError("no output path: give -o OUT.h5 or [output] path in the scene")
        disc = Discretisation(scene)
    except InputError as err:
        sys.exit(f"error: {err}")
    return scene, disc, out
