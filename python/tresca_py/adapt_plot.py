"""Figures of ``tresca-cr adapt``: the mesh of every level (where the refinement goes) from its results
file ``DIR/level_<k>.h5``, and error against DOF from the ``--csv`` tables of an adaptive and a uniform
run (``--theta 1``), with DOF^(-1/2) for reference.

``python scripts/adapt_plot.py meshes DIR -o OUT [--levels 0 4 8]`` writes ``OUT/mesh_<k>.png``;
``python scripts/adapt_plot.py rates ADAPTIVE.csv UNIFORM.csv -o FIG.png [--title T]``."""
import argparse
import csv
import glob
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from tresca_py import paths, results  # noqa: E402


def mesh_picture(path, out, title):
    """Draw the mesh of results file ``path`` into ``out``."""
    m = results.read(path, verify=False).mesh
    fig, ax = plt.subplots(figsize=(5, 5))
    ax.triplot(m.points[:, 0], m.points[:, 1], m.triangles, lw=0.25, color="k")
    ax.set_aspect("equal")
    ax.set_title(f"{title}: {len(m.triangles)} triangles")
    ax.set_axis_off()
    paths.save_figure(fig, out, dpi=130, bbox_inches="tight")
    plt.close(fig)


def read_rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def number(path, rows, i, col):
    """The value of column ``col`` in data row ``i`` of the CSV ``path``: a finite positive number, since a
    log-log picture cannot draw anything else (NaN, inf, 0 or a negative value is refused naming its place)."""
    text = rows[i].get(col)
    try:
        v = float(text)
    except (TypeError, ValueError):
        v = math.nan
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{path}: line {i + 2}, column {col} = {text!r}: not a finite positive number, which "
                         "a log-log picture cannot draw")
    return v


def error_column(rows):
    """The error compared: the reference distance, else the true error, else the distance to the next level."""
    for col in ("vs_reference", "error", "vs_next"):
        if rows and rows[0].get(col):
            return col
    raise ValueError("no error column with values")


def rates_picture(adaptive, uniform, out, title):
    """Error and estimator against unknowns for both routes (log-log) into ``out``."""
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for path, name, mark in ((adaptive, "adaptive", "o"), (uniform, "uniform", "s")):
        rows = read_rows(path)
        col = error_column(rows)
        d = np.array([number(path, rows, i, "unknowns") for i in range(len(rows))])
        keep = [i for i, r in enumerate(rows) if r[col]]
        e = np.array([number(path, rows, i, col) for i in keep])
        eta = np.array([number(path, rows, i, "estimator") for i in range(len(rows))])
        ax.loglog(d[keep], e, mark + "-", label=f"{name}: error ({col})")
        ax.loglog(d, eta, mark + "--", mfc="none", label=f"{name}: estimator")
    first = read_rows(adaptive)
    d0 = np.array([number(adaptive, first, i, "unknowns") for i in range(len(first))])
    e0 = number(adaptive, first, 0, error_column(first))
    ax.loglog(d0, e0 * (d0 / d0[0]) ** -0.5, "k:", label="DOF^(-1/2)")
    ax.set_xlabel("unknowns")
    ax.set_ylabel("energy norm (max over time nodes)")
    ax.set_title(title)
    ax.legend(fontsize=7)
    paths.save_figure(fig, out, dpi=130, bbox_inches="tight")
    plt.close(fig)


def check_outputs(pictures, inputs, force):
    """The rule of every output (``tresca_py.paths``) for all ``pictures`` before the first is drawn."""
    paths.distinct([(p, "picture") for p in pictures], [(p, "input") for p in inputs])
    for p in pictures:
        paths.new_output(p, "picture", force)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    m = sub.add_parser("meshes")
    m.add_argument("dir")
    m.add_argument("-o", "--out", required=True)
    m.add_argument("--levels", type=int, nargs="*")
    m.add_argument("--title", default="level")
    r = sub.add_parser("rates")
    r.add_argument("adaptive")
    r.add_argument("uniform")
    r.add_argument("-o", "--out", required=True)
    r.add_argument("--title", default="")
    for p in (m, r):
        p.add_argument("--force", action="store_true", help="replace existing pictures")
    a = ap.parse_args(argv)
    try:
        if a.cmd == "meshes":
            files = {int(re.search(r"level_(\d+)\.h5$", p).group(1)): p
                     for p in glob.glob(os.path.join(a.dir, "level_*.h5"))}
            if not files:
                raise ValueError(f"{a.dir}: no level_<k>.h5 files")
            levels = a.levels if a.levels else sorted(files)
            missing = [k for k in levels if k not in files]
            if missing:
                raise ValueError(f"{a.dir}: no level_{missing[0]}.h5")
            out = paths.output_dir(a.out, "pictures directory")
            pictures = [(k, os.path.join(out, f"mesh_{k}.png")) for k in levels]
            check_outputs([p for _, p in pictures], [files[k] for k in levels], a.force)
            for k, p in pictures:
                mesh_picture(files[k], p, f"{a.title} {k}")
        else:
            check_outputs([a.out], [a.adaptive, a.uniform], a.force)
            paths.output_file(a.out, "picture")
            rates_picture(a.adaptive, a.uniform, a.out, a.title)
    except (OSError, ValueError, results.ResultsError, paths.PathError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    return 0
