"""The per-step checksums of ``tresca/steps/checksum``: XXH64 (seed 0) of each step's rows of every series,
concatenated in the order of ``SERIES`` (those present), then ``AUDIT`` where the checksum covers it
(``covers_audit``), as little-endian bytes. The Rust writer computes the
same (``src/output/checksum.rs``, ``step_checksums``); ``--resume`` and the readers verify it.

XXH64 is evaluated here with numpy, vectorised over the steps (one row of bytes per step).
"""
import numpy as np

# The order of the series in a step's checksum (src/output/tresca.rs module doc).
SERIES = ("times", "u", "energy", "steps/iterations", "steps/residual", "steps/n_stick", "steps/n_slip",
          "steps/wall_time", "contact/slip", "contact/sigma_t", "contact/state", "contact/mu", "contact/dof",
          "errors/energy", "errors/h1", "errors/l2")

#: The energy audit's series: last in a step's checksum in files whose checksum names them in its attribute
#: ``COVERS`` (files written before then have no such attribute, and their checksums end with ``SERIES``).
AUDIT = tuple(f"steps/{k}" for k in ("external_work", "boundary_work", "stored_energy", "friction_dissipation",
                                     "euler_dissipation", "balance_residual"))
COVERS = "series"


def covers_audit(dataset):
    """True if the checksum ``dataset`` (h5py) names the audit series in its ``COVERS`` attribute."""
    v = dataset.attrs.get(COVERS)
    v = v.decode() if isinstance(v, bytes) else v
    return isinstance(v, str) and set(AUDIT) <= set(v.split(", "))


_P = [np.uint64(v) for v in (0x9E3779B185EBCA87, 0xC2B2AE3D27D4EB4F, 0x165667B19E3779F9, 0x85EBCA77C2B2AE63,
                             0x27D4EB2F165667C5)]


def _rotl(x, r):
    return (x << np.uint64(r)) | (x >> np.uint64(64 - r))


def _round(acc, lane):
    return _rotl(acc + lane * _P[1], 31) * _P[0]


def xxh64_rows(rows):
    """XXH64 (seed 0) of every row of a (steps, bytes) uint8 array."""
    rows = np.ascontiguousarray(rows, dtype=np.uint8)
    S, L = rows.shape
    with np.errstate(over="ignore"):
        words = rows[:, : L // 8 * 8].copy().view("<u8")
        i = 0
        if L >= 32:
            v = [np.full(S, x, dtype=np.uint64) for x in (_P[0] + _P[1], _P[1], np.uint64(0), np.uint64(0) - _P[0])]
            for s in range(L // 32):
                for j in range(4):
                    v[j] = _round(v[j], words[:, 4 * s + j])
            h = _rotl(v[0], 1) + _rotl(v[1], 7) + _rotl(v[2], 12) + _rotl(v[3], 18)
            for j in range(4):
                h = (h ^ _round(np.zeros(S, np.uint64), v[j])) * _P[0] + _P[3]
            i = L // 32 * 32
        else:
            h = np.full(S, _P[4], dtype=np.uint64)
        h = h + np.uint64(L)
        while i + 8 <= L:
            h = _rotl(h ^ _round(np.zeros(S, np.uint64), words[:, i // 8]), 27) * _P[0] + _P[3]
            i += 8
        if i + 4 <= L:
            h = _rotl(h ^ (rows[:, i:i + 4].copy().view("<u4")[:, 0].astype(np.uint64) * _P[0]), 23) * _P[1] + _P[2]
            i += 4
        while i < L:
            h = _rotl(h ^ (rows[:, i].astype(np.uint64) * _P[4]), 11) * _P[0]
            i += 1
        h = (h ^ (h >> np.uint64(33))) * _P[1]
        h = (h ^ (h >> np.uint64(29))) * _P[2]
        return h ^ (h >> np.uint64(32))


def step_checksums(series):
    """The checksum of every step of ``series``: arrays whose first axis is the step, in ``SERIES`` order,
    each already in its stored (little-endian) dtype."""
    steps = len(series[0])
    parts = [np.ascontiguousarray(a).reshape(steps, -1).view(np.uint8) for a in series]
    return xxh64_rows(np.concatenate(parts, axis=1))
