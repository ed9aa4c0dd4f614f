"""The common command line of the Python solvers: SCENE.toml -o OUT.h5 [--refine k] [--steps N] [-q], and
how they fail: bad input (scene, mesh, loads, output path) ends the run with one ``error: …`` line and a
non-zero exit, never a traceback, and leaves no results file."""
import contextlib
import sys

from tresca_py import paths, results
from tresca_py.errors import InputError
from tresca_py.scene import SceneError, load_scene

#: what a solver reports as bad input instead of a traceback
FAILURES = (InputError, paths.PathError, results.ResultsError, OSError)


def cli(description, argv=None):
    """Common command line: SCENE.toml -o OUT.h5 [--refine k] [--steps N]."""
    import argparse
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("scene", help="scene TOML file")
    ap.add_argument("-o", "--output", help="results file (default: [output] path of the scene)")
    ap.add_argument("--refine", type=int, default=None, help="override [mesh] refine")
    ap.add_argument("--steps", type=int, default=None, help="override the number of uniform time steps")
    ap.add_argument("-q", "--quiet", action="store_true", help="no per-step log")
    ap.add_argument("--force", action="store_true", help="replace an existing results file")
    args = ap.parse_args(argv)
    return args


def message(err):
    """One line naming the problem (an OSError names its file)."""
    if isinstance(err, OSError) and not isinstance(err, paths.PathError) and err.strerror:
        return f"{err.filename}: {err.strerror}" if err.filename else err.strerror
    return " ".join(str(err).split()) or type(err).__name__


@contextlib.contextmanager
def exit_on_failure(report=True):
    """Turn a ``FAILURES`` exception into ``error: <message>`` on stderr (if ``report``: rank 0 of an MPI run
    reports, the others exit silently) and exit status 2."""
    try:
        yield
    except FAILURES as err:
        if report:
            print(f"error: {message(err)}", file=sys.stderr, flush=True)
        sys.exit(2)


def input_files(args, scene):
    """The (path, what) of a solver's inputs: the scene and its mesh file, if any."""
    return [(args.scene, "scene")] + ([(scene.mesh["file"], "mesh")] if "file" in scene.mesh else [])


def output_path(args, scene):
    """The results path (``-o`` or the scene's ``[output] path``), made absolute, checked before any work under
    the rule of every output (``paths.new_output``: an existing file replaced only with ``--force``; never the
    scene or its mesh), in a directory where files can be created."""
    out = args.output or scene.output
    if not out:
        raise SceneError("no output path: give -o OUT.h5 or [output] path in the scene")
    paths.distinct([(out, "results file")], input_files(args, scene))
    paths.new_output(out, "results file", args.force)
    return paths.output_file(out, "results file")


def open_scene(args, discretise, report=True, unilateral=False):
    """Scene, the solver's own discretisation ``discretise(scene)`` and the checked output path; bad input exits
    with one error line. Unless ``unilateral``, a scene with a unilateral, Coulomb or loaded contact part is
    refused (``Scene.refuse_contact_extensions``)."""
    with exit_on_failure(report):
        scene = load_scene(args.scene, refine=args.refine, steps=args.steps)
        if not unilateral:
            scene.refuse_contact_extensions(discretise.__module__.split(".")[1])
        out = output_path(args, scene)
        disc = discretise(scene)
    return scene, disc, out
