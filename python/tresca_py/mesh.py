"""Meshes of a scene: the structured quadrilateral of [mesh] corners/cells/diagonal, Gmsh 4.1 files
(meshio), uniform red refinement, and matching of point sets between numberings."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tresca_py.scene import Scene, SceneError


@dataclass
class Mesh:
    points: np.ndarray               # (P, 2)
    triangles: np.ndarray            # (T, 3) counter-clockwise
    boundary_segments: dict = field(default_factory=dict)   # name -> (k, 2) vertex pairs


def structured_mesh(corners, n, m, diagonal="first"):
    """Structured triangulation of the quadrilateral c0 c1 c2 c3 (README).

    p(i,j) = bilinear map of (i/n, j/m); index j*(n+1)+i.  Cell (i,j) is split along
    p(i,j)-p(i+1,j+1) ("first") or p(i+1,j)-p(i,j+1) ("second").  Sides: bottom (j=0), right (i=n),
    top (j=m), left (i=0).
    """
    c = np.asarray(corners, dtype=float)
    xi = np.arange(n + 1) / n
    eta = np.arange(m + 1) / m
    X, Y = np.meshgrid(xi, eta)            # (m+1, n+1): index [j, i]
    X, Y = X.ravel()[:, None], Y.ravel()[:, None]
    pts = ((1 - X) * (1 - Y) * c[0] + X * (1 - Y) * c[1] + X * Y * c[2] + (1 - X) * Y * c[3])

    def idx(i, j):
        return j * (n + 1) + i

    Ii, Jj = np.meshgrid(np.arange(n), np.arange(m))
    Ii, Jj = Ii.ravel(), Jj.ravel()
    p00, p10, p11, p01 = idx(Ii, Jj), idx(Ii + 1, Jj), idx(Ii + 1, Jj + 1), idx(Ii, Jj + 1)
    if diagonal == "first":
        tri = np.stack([np.stack([p00, p10, p11], 1), np.stack([p00, p11, p01], 1)], 1)
    else:
        tri = np.stack([np.stack([p00, p10, p01], 1), np.stack([p10, p11, p01], 1)], 1)
    tri = tri.reshape(-1, 3)
    i_n, j_m = np.arange(n), np.arange(m)
    segs = {
        "bottom": np.stack([idx(i_n, 0), idx(i_n + 1, 0)], 1),
        "right": np.stack([idx(n, j_m), idx(n, j_m + 1)], 1),
        "top": np.stack([idx(i_n + 1, m), idx(i_n, m)], 1),
        "left": np.stack([idx(0, j_m + 1), idx(0, j_m)], 1),
    }
    return Mesh(pts, tri.astype(np.int64), segs)


def red_refine(mesh: Mesh) -> Mesh:
    """Split every triangle into four through its edge midpoints; boundary segments are halved."""
    tri = mesh.triangles
    P = len(mesh.points)
    pairs = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    uniq, inv = np.unique(pairs, axis=0, return_inverse=True)
    inv = inv.ravel()
    mids = 0.5 * (mesh.points[uniq[:, 0]] + mesh.points[uniq[:, 1]])
    nt = len(tri)
    m01, m12, m20 = P + inv[:nt], P + inv[nt:2 * nt], P + inv[2 * nt:]
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    new = np.concatenate([np.stack([a, m01, m20], 1), np.stack([m01, b, m12], 1),
                          np.stack([m20, m12, c], 1), np.stack([m01, m12, m20], 1)])
    lookup = {tuple(p): P + k for k, p in enumerate(uniq)}
    segs = {}
    for name, s in mesh.boundary_segments.items():
        mid = np.array([lookup[tuple(sorted(e))] for e in s.tolist()], dtype=np.int64).reshape(-1)
        segs[name] = np.concatenate([np.stack([s[:, 0], mid], 1), np.stack([mid, s[:, 1]], 1)]) \
            if len(s) else s
    return Mesh(np.vstack([mesh.points, mids]), new.astype(np.int64), segs)


def gmsh_mesh(path) -> Mesh:
    """Read a Gmsh 4.1 mesh with meshio: triangles, and 1D physical groups naming boundary parts."""
    import meshio
    try:
        msh = meshio.read(path, file_format="gmsh")
    except FileNotFoundError:
        raise SceneError(f"mesh file {path!r} does not exist") from None
    except Exception as err:
        raise SceneError(f"cannot read Gmsh mesh {path!r}: {err}") from None
    tris, lines, line_tags = [], [], []
    phys = msh.cell_data.get("gmsh:physical")
    for k, block in enumerate(msh.cells):
        if block.type == "triangle":
            tris.append(block.data)
        elif block.type == "line":
            lines.append(block.data)
            if phys is None:
                raise SceneError(f"{path}: line elements carry no physical tags")
            line_tags.append(np.asarray(phys[k]))
        elif block.type in ("vertex",):
            continue
        else:
            raise SceneError(f"{path}: unsupported element type '{block.type}' (only linear triangles and lines)")
    if not tris:
        raise SceneError(f"{path}: no triangles")
    tri = np.concatenate(tris).astype(np.int64)
    pts = np.asarray(msh.points[:, :2], dtype=float)
    if msh.points.shape[1] > 2 and np.any(np.abs(msh.points[:, 2]) > 1e-14):
        raise SceneError(f"{path}: mesh is not planar (z != 0)")
    used = np.unique(tri)
    renum = -np.ones(len(pts), dtype=np.int64)
    renum[used] = np.arange(len(used))
    pts, tri = pts[used], renum[tri]
    d = pts[tri[:, 1]] - pts[tri[:, 0]], pts[tri[:, 2]] - pts[tri[:, 0]]
    area2 = d[0][:, 0] * d[1][:, 1] - d[0][:, 1] * d[1][:, 0]
    tri[area2 < 0] = tri[area2 < 0][:, [0, 2, 1]]
    names = {}
    for name, (tag, dim) in msh.field_data.items():
        if int(dim) == 1:
            names[int(tag)] = name
    segs = {}
    if lines:
        L = np.concatenate(lines).astype(np.int64)
        T = np.concatenate(line_tags)
        if np.any(renum[L] < 0):
            raise SceneError(f"{path}: a boundary line uses a node that belongs to no triangle")
        L = renum[L]
        for tag in np.unique(T):
            if int(tag) == 0:          # lines outside any physical group name no boundary part
                continue
            if int(tag) not in names:
                raise SceneError(f"{path}: physical line tag {tag} has no name")
            segs[names[int(tag)]] = L[T == tag]
    check_segments(path, pts, tri, segs)
    return Mesh(pts, tri, segs)


def check_segments(path, pts, tri, segs):
    """Every tagged line is a boundary edge of the triangles, in at most one part (as src/mesh does it:
    an edge in two parts would be given two boundary conditions)."""
    loc = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    keys, counts = np.unique(loc, axis=0, return_counts=True)
    count = {(int(a), int(b)): int(c) for (a, b), c in zip(keys, counts, strict=True)}
    owner = {}
    for name, seg in segs.items():
        for a, b in np.sort(seg, axis=1).tolist():
            x, y = pts[a]
            where = f"({x:.6f}, {y:.6f})"
            if (a, b) not in count:
                raise SceneError(f"{path}: boundary element at {where} of part '{name}' is not an edge of any "
                                 "triangle")
            if count[(a, b)] > 1:
                raise SceneError(f"{path}: interior edge at {where} is tagged as boundary part '{name}'")
            other = owner.setdefault((a, b), name)
            if other != name:
                raise SceneError(f"{path}: boundary edge at {where} is in two parts: '{other}' and '{name}'")


def build_mesh(scene: Scene) -> Mesh:
    ms = scene.mesh
    if "file" in ms:
        mesh = gmsh_mesh(ms["file"])
        for _ in range(ms["refine"]):
            mesh = red_refine(mesh)
        return mesh
    k = 2 ** ms["refine"]
    return structured_mesh(ms["corners"], ms["cells"][0] * k, ms["cells"][1] * k, ms["diagonal"])



def match_points(ref, other, tol=1e-9, what="points"):
    """Index array ``idx`` with ``other[i] == ref[idx[i]]`` (nearest neighbour, checked to ``tol``)."""
    from scipy.spatial import cKDTree
    scale = max(1.0, float(np.max(np.abs(ref))) if len(ref) else 1.0)
    dist, idx = cKDTree(ref).query(other)
    if len(dist) and np.max(dist) > tol * scale:
        i = int(np.argmax(dist))
        raise ValueError(f"cannot match {what}: {other[i]} has no partner (distance {dist[i]:.3e})")
    return idx


