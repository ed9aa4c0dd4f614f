"""Output of the distributed solver without gathering the field: each rank writes its owned edges to
``OUT.h5.parts/rank<r>.h5``; rank 0 writes ``OUT.h5`` with the README /tresca layout, the big arrays as HDF5
virtual datasets over the parts."""
import os

import numpy as np

from tresca_py.skfem_cr.stepping import git_commit


class PartWriter:
    """This rank's part: owned points, triangles, edges, midpoints and u at every step."""

    def __init__(self, out, prob, n_times):
        import h5py
        comm = prob.comm
        self.dir = out + ".parts"
        if comm.rank == 0:
            os.makedirs(self.dir, exist_ok=True)
            for f in os.listdir(self.dir):
                if f.startswith("rank") and f.endswith(".h5"):
                    os.remove(os.path.join(self.dir, f))
        comm.barrier()
        self.path = os.path.join(self.dir, f"rank{comm.rank}.h5")
        self.h5 = h5py.File(self.path, "w")
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


def write_main(out, prob, res, writer_dirname, sizes, attrs):
    """Rank 0: the README /tresca layout, the big arrays as virtual datasets over the parts."""
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

        vds("points", "points", (2,), "f8")
        vds("triangles", "triangles", (3,), "i8")
        vds("edges", "edges", (2,), "i8")
        vds("midpoints", "edges", (2,), "f8")
        vds("u", "edges", (2,), "f8", lead=(N1,))
        g.create_dataset("times", data=scene.times)
        g.create_dataset("energy", data=res["energy"])
        g.create_dataset("contact/edges", data=prob.C_edges)
        g.create_dataset("contact/normal", data=prob.C_normal.reshape(-1, 2))
        g.create_dataset("contact/tangent", data=prob.C_tangent.reshape(-1, 2))
        g.create_dataset("contact/g", data=prob.C_g)
        for k in ("slip", "sigma_t", "mu", "state"):
            g.create_dataset(f"contact/{k}", data=res[k])
        g.create_dataset("contact/dof", data=res["slip"])
        for k in ("iterations", "residual", "n_stick", "n_slip", "wall_time"):
            g.create_dataset(f"steps/{k}", data=res[k])
        if "errors" in res:
            for k, v in res["errors"].items():
                g.create_dataset(f"errors/{k}", data=v)
        a = {"scene": scene.text, "scene_path": os.path.abspath(scene.path), "version": "python-distributed-1",
             "git_commit": git_commit(), "solver": "dolfinx-distributed",
             "method": "TAO TRON on the condensed dual (PETSc), rank 0",
             "tol": float(scene.solver.get("tol", 1e-12)), "rho": scene.rho, "E": scene.E, "nu": scene.nu,
             "refine": int(scene.mesh["refine"]), "steps": N1 - 1, "n_edges": prob.nb_glob,
             "n_contact": prob.n_c, "n_dofs": 2 * prob.nb_glob, "parts": rel}
        a.update(attrs)
        for k, v in a.items():
            g.attrs[k] = v
