"""The manufactured L-shape mms_lshape (tresca_py/mms/lshape.py, williams.py): the Williams mode solves the
equations and frees the corner's faces, the data it prints satisfy the problem's equations and boundary
conditions, and the committed scene is what the derivation writes."""
import pathlib

import numpy as np
import pytest
import sympy as sp

from tresca_py.expr import parse, symbols
from tresca_py.mms import lshape, williams
from tresca_py.mms.blocks import lam
from tresca_py.mms.derive import CheckFailed

x, y, t = symbols()
ROOT = pathlib.Path(__file__).resolve().parents[2]


# the derivation and its symbolic checks are study-sized: the tests that use it are marked `study` (make
# verify, T1); the Williams mode's own check stays in make test
@pytest.fixture(scope="module")
def derived():
    return lshape.run_checks(lshape.case_lshape(), log=lambda msg: None)


def test_the_williams_mode_is_an_equilibrium_with_traction_free_faces_only_at_the_root():
    """The system shall use a mode with div σ = 0 identically (symbolic) whose faces θ = ±3π/4 are free of
    traction at the 30-digit root λ (to 1e-25, the root's precision with O(1) terms) and not at λ = 0.55."""
    div, faces = williams.polar_checks(sp.Rational(3, 10))
    assert div == [0, 0]
    root = williams.exponent()
    assert float(root) == pytest.approx(0.5444837367824639, abs=1e-15)
    r = sp.Symbol("r", positive=True)
    for lam_v, free in ((root, True), (sp.Float("0.55", 30), False)):
        q = williams.q_of(lam_v).evalf(30)
        worst = max(abs(sp.N(f.subs({williams.LAM: lam_v, williams.Q: q, r: sp.Rational(1, 3)}), 30)) for f in faces)
        assert (worst < 1e-25) == free, (lam_v, worst)


@pytest.mark.study
def test_the_printed_data_satisfy_the_equations_at_sample_points(derived):
    """The system shall print f with f + div σ(u) = 0 (σ of the printed grad, central differences, h = 1e-5:
    error O(h²|∇³σ|) ≤ 1e-6 relative at r ≥ 0.05) and grad equal to the derivative of the printed u."""
    P = {k: parse(v, k) for k, v in derived["str"].items()}
    rng = np.random.default_rng(7)
    X, Y = lshape.region(rng, 300, r_min=0.05)
    T = rng.random(300)
    G = [[lam(P[f"grad{i}{j}"]) for j in (1, 2)] for i in (1, 2)]
    lam_, mu = float(derived["lam"]), float(derived["mu"])

    def sig(Xp, Yp):
        g = [[G[i][j](Xp, Yp, T) for j in range(2)] for i in range(2)]
        tr = g[0][0] + g[1][1]
        return lam_ * tr + 2 * mu * g[0][0], mu * (g[0][1] + g[1][0]), lam_ * tr + 2 * mu * g[1][1]

    h = 1e-5
    xp, xm, yp, ym = sig(X + h, Y), sig(X - h, Y), sig(X, Y + h), sig(X, Y - h)
    div = [(xp[0] - xm[0] + yp[1] - ym[1]) / (2 * h), (xp[1] - xm[1] + yp[2] - ym[2]) / (2 * h)]
    f = [lam(P["f1"])(X, Y, T), lam(P["f2"])(X, Y, T)]
    scale = max(np.max(np.abs(f[0])), np.max(np.abs(f[1])))
    assert max(np.max(np.abs(f[0] + div[0])), np.max(np.abs(f[1] + div[1]))) < 1e-6 * scale
    u1 = lam(P["u1"])
    fd = (u1(X + 1e-6, Y, T) - u1(X - 1e-6, Y, T)) / 2e-6
    assert np.max(np.abs(fd - G[0][0](X, Y, T))) < 1e-6 * np.max(np.abs(G[0][0](X, Y, T)))


@pytest.mark.study
def test_the_singular_part_vanishes_on_the_far_sides_and_the_floor(derived):
    """The system shall keep χw off Γ_C, the clamp and the far sides: u = u_T there exactly (χ = 0 for r > 3/4)."""
    P = {k: parse(v, k) for k, v in derived["str"].items()}
    u_T = [lam(c.xreplace(derived["vals"])) for c in derived["u_T"]]
    for side in ("floor", "right", "top", "clamp"):
        X, Y, T = lshape.side_points(side)
        for i in (1, 2):
            assert np.max(np.abs(lam(P[f"u{i}"])(X, Y, T) - u_T[i - 1](X, Y, T))) == 0.0, side


@pytest.mark.study
def test_a_wrong_traction_on_the_notch_is_caught(derived):
    """The system shall reject printed data whose traction on a corner face is not σ(u)n."""
    bad = dict(derived, parsed=dict(derived["parsed"]))
    bad["parsed"]["g_notch_1"] = bad["parsed"]["g_notch_1"] * sp.Rational(101, 100)
    with pytest.raises(CheckFailed, match="notch"):
        lshape.check_sides(bad, log=lambda msg: None)


@pytest.mark.study
def test_the_committed_scene_is_the_derivation(derived):
    """The system shall ship verification/cases/mms_lshape.toml exactly as the derivation writes it."""
    assert (ROOT / "verification/cases/mms_lshape.toml").read_text() == lshape.scene_text(derived)
