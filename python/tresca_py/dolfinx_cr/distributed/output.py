"""Output of the distributed solver without gathering the field: each rank writes its owned edges to
``OUT.h5.parts/rank<r>.h5``; rank 0 writes ``OUT.h5`` with the one ``/tresca`` layout of
``tresca_py.results`` (docs/results.md), the big arrays as HDF5 virtual datasets over the parts.

Why not ``tresca_py.results.write``: it takes the whole run in one process (mesh and u of every step as
arrays) and writes them serially, and this route never gathers the mesh or u onto one rank (that is what
lets it run beyond one machine's memory). So rank 0 writes the layout itself, with the dataset names and
dtypes of ``tresca_py.results.SPEC`` and the attributes ``read`` requires (``status``, ``steps``,
``tresca/steps`` ``completed``, ``n_edges``, ``n_contact``), and the tests read its files with
``tresca_py.results.read``. Left out: ``tresca/steps/checksum`` (optional in the layout), which hashes
whole steps of u that no rank holds, the energy audit and the visualisation views (``/VTKHDF``,
``OUT.xdmf``) of the Rust solver; the displacement for ParaView is ``OUT_vtk/displacement.pvd``
(dolfinx's parallel VTKFile).

Every file written follows the rule of every output (``tresca_py.paths``): ``check_outputs`` refuses, before any
work, a parts or frames directory that is a link (or not a directory) and, without ``--force``, the files of an
earlier run in them; the parts are created exclusively (``w-``: never through a link planted since), and
``OUT.h5`` is built beside it and renamed into place (``paths.write_named``).
"""
import os

import numpy as np

from tresca_py import paths
from tresca_py.results import SPEC
from tresca_py.common import git_commit

#: the files of a run in its parts and frames directories: (directory of ``OUT.h5``, test of a file name)
RUN_FILES = ((lambda out: out + ".parts", lambda f: f.startswith("rank") and f.endswith(".h5")),
             (lambda out: os.path.splitext(out)[0] + "_vtk", lambda f: f.startswith("displacement")))


def check_outputs(out, force, inputs):
    """PathError unless the parts and frames directories of ``OUT.h5`` may be written: each a directory (not a
    link) or absent, the files of an earlier run in them (``RUN_FILES``) replaced only with ``force``, each then
    a regular file of one link and not one of ``inputs`` ((path, what) pairs). Returns the files to remove."""
    stale = []
    for where, ours in RUN_FILES:
        d = where(out)
        if not os.path.lexists(d):
            continue
        paths.output_subdir(d, "directory of the run's parts and frames")
        for f in sorted(os.listdir(d)):
            if ours(f):
                stale.append(paths.new_output(os.path.join(d, f), "file of an earlier run", force))
    paths.distinct([(f, "file of an earlier run") for f in stale], inputs)
    return stale


class PartWriter:
    """This rank's part: owned points, triangles, edges, midpoints and u at every step."""

    def __init__(self, out, prob, n_times, stale):
        import h5py
        comm = prob.comm
        self.dir = out + ".parts"
        if comm.rank == 0:
            for f in stale:                        # checked by check_outputs (regular, --force given)
                os.unlink(f)
            os.makedirs(self.dir, exist_ok=True)
        comm.barrier()
        self.path = os.path.join(self.dir, f"rank{comm.rank}.h5")
        self.h5 = h5py.File(self.path, "w-")
        g = self.h5
        g["points"] = prob.points
        g["triangles"] = prob.triangles
        g["edges"] = prob.edges_vertices
        g["midpoints"] = prob.midpoints
        chunk = (1, max(1, prob.nb_own), 2)
        self.u = g.create_dataset("u", shape=(n_times, prob.nb_own, 2), dtype="f8",
                                  chunks=chunk if prob.nb_own else None)

    def write(self, n, u_owned):
        self.u[n] = u_owned.reshape(-1, 2)

    def close(self):
        self.h5.close()


def setup_time_attrs(times):
    """The set-up wall times {stage: s} as the results layout has them (as the Rust solver writes them): the
    float array ``setup_times`` and ``setup_times_meaning`` naming its entries."""
    return {"setup_times": np.array(list(times.values()), dtype=float),
            "setup_times_meaning": ", ".join(times) + " (s)"}


def setup_times(attrs):
    """{stage: s} back from a distributed run's /tresca attributes (``setup_time_attrs``)."""
    names = str(attrs["setup_times_meaning"]).removesuffix(" (s)").split(", ")
    return dict(zip(names, (float(v) for v in attrs["setup_times"]), strict=True))


def write_main(out, prob, res, writer_dirname, sizes, attrs, force):
    """Rank 0: ``OUT.h5`` (``write_layout``) under the rule of every output, replacing a file there only with
    ``force``."""
    paths.write_named(out, lambda tmp: write_layout(tmp, prob, res, writer_dirname, sizes, attrs), "results file",
                      force)


def write_layout(out, prob, res, writer_dirname, sizes, attrs):
    """Rank 0: the README /tresca layout into the new file ``out``, the big arrays as virtual datasets over the
    parts."""
    import h5py
    scene = prob.scene
    N1 = len(scene.times)
    P = len(sizes)
    rel = os.path.basename(writer_dirname)
    with h5py.File(out, "w") as h5:
        g = h5.create_group("tresca")

        def vds(name, key, tail, dtype, lead=()):
            total = sum(s[key] for s in sizes)
            lay = h5py.VirtualLayout(shape=lead + (total,) + tail, dtype=dtype)
            o = 0
            for r in range(P):
                nr = sizes[r][key]
                if nr:
                    src = h5py.VirtualSource(f"{rel}/rank{r}.h5", name, shape=lead + (nr,) + tail)
                    if lead:
                        lay[:, o:o + nr] = src
                    else:
                        lay[o:o + nr] = src
                o += nr
            g.create_virtual_dataset(f"mesh/{name}" if name != "u" else "u", lay,
                                     fillvalue=np.nan if dtype == "f8" else -1)

        vds("points", "points", (2,), SPEC["mesh/points"][0])
        vds("triangles", "triangles", (3,), SPEC["mesh/triangles"][0])
        vds("edges", "edges", (2,), SPEC["mesh/edges"][0])
        vds("midpoints", "edges", (2,), SPEC["mesh/midpoints"][0])
        vds("u", "edges", (2,), SPEC["u"][0], lead=(N1,))

        def put(name, a):
            g.create_dataset(name, data=np.asarray(a, SPEC[name][0]))

        put("times", scene.times)
        put("energy", res["energy"])
        for k in ("iterations", "residual", "n_stick", "n_slip", "wall_time"):
            put(f"steps/{k}", res[k])
        g["steps"].attrs["completed"] = np.int64(N1)
        if prob.n_c:                     # the layout has a contact group only when Γ_C has edges
            for k, v in (("edges", prob.C_edges), ("normal", prob.C_normal.reshape(-1, 2)),
                         ("tangent", prob.C_tangent.reshape(-1, 2)), ("g", prob.C_g), ("dof", res["slip"])):
                put(f"contact/{k}", v)
            for k in ("slip", "sigma_t", "mu", "state"):
                put(f"contact/{k}", res[k])
        if "errors" in res:
            for k, v in res["errors"].items():
                put(f"errors/{k}", v)
        a = {"scene": scene.text, "scene_path": os.path.abspath(scene.path), "title": scene.title,
             "version": "python-distributed-1", "git_commit": git_commit(), "solver": "dolfinx-distributed",
             "method": "TAO TRON on the condensed dual (PETSc), rank 0", "status": "completed",
             "tol": float(scene.solver.get("tol", 1e-12)), "rho": scene.rho, "E": scene.E, "nu": scene.nu,
             "refine": int(scene.mesh["refine"]), "steps": N1 - 1, "n_edges": prob.nb_glob,
             "n_contact": prob.n_c, "n_dofs": 2 * prob.nb_glob, "parts": rel}
        a.update(attrs)
        for k, v in a.items():
            g.attrs[k] = v
