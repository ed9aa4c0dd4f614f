"""Newest-vertex bisection's minimum-angle guarantee, computed independently of the Rust refinement.

NVB labels each initial triangle once (its refinement edge: the longest side, as ``tresca-cr adapt``
does) and then bisects (v0; v1, v2) at the midpoint m of v1v2 into (m; v0, v1) and (m; v2, v0). Every
triangle it ever produces from an initial triangle T, with or without the completion steps, is a node of
T's binary bisection tree, and those nodes fall into at most four similarity classes (Sewell 1972;
Mitchell 1991), all present within the first few generations. So the smallest angle over the first
:data:`GENERATIONS` generations of T's tree bounds every adapted mesh's angles from below.
"""
import numpy as np

# four similarity classes appear within two generations; six leave a margin
GENERATIONS = 6


def min_angles(tris):
    """Smallest interior angle (degrees) of each triangle, ``tris`` of shape (n, 3, 2)."""
    t = np.asarray(tris, dtype=float)
    out = np.full(len(t), 180.0)
    for i in range(3):
        a, b, c = t[:, i], t[:, (i + 1) % 3], t[:, (i + 2) % 3]
        u, v = b - a, c - a
        cos = np.sum(u * v, axis=1) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
        out = np.minimum(out, np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
    return out


def label_longest_edge(tris):
    """Each triangle reordered so that vertex 0 is opposite its longest side (cyclic order kept; ties: the
    first longest of v1v2, v2v0, v0v1)."""
    t = np.asarray(tris, dtype=float)
    lengths = np.stack([np.linalg.norm(t[:, (i + 1) % 3] - t[:, (i + 2) % 3], axis=1) for i in range(3)], axis=1)
    first = np.argmax(lengths, axis=1)
    return np.stack([t[np.arange(len(t)), (first + k) % 3] for k in range(3)], axis=1)


def descendant_bound(points, triangles, generations=GENERATIONS):
    """The smallest angle (degrees) over ``generations`` uniform bisections of every triangle of the
    initial mesh (``points`` (n, 2), ``triangles`` (m, 3)): NVB's lower bound for its adapted meshes."""
    level = label_longest_edge(np.asarray(points, dtype=float)[np.asarray(triangles)])
    low = float(min_angles(level).min())
    for _ in range(generations):
        m = 0.5 * (level[:, 1] + level[:, 2])
        level = np.concatenate([np.stack([m, level[:, 0], level[:, 1]], axis=1),
                                np.stack([m, level[:, 2], level[:, 0]], axis=1)])
        low = min(low, float(min_angles(level).min()))
    return low
