"""tresca-cr's column of the external suite: the CR field read back from a results file."""
from pathlib import Path

import h5py
import numpy as np
import pytest

from tresca_py.external import problem, tresca

ROOT = Path(__file__).resolve().parents[2]
BINARY = ROOT / "target" / "release" / "tresca-cr"
SCENE = ROOT / "verification" / "cases" / "mms_front.toml"


@pytest.mark.skipif(not BINARY.exists(), reason="no release binary (cargo build --release)")
def test_cr_trace_and_norms(tmp_path):
    """The system shall evaluate the CR trace on Γ_C to the slip dofs at the edge midpoints, and report the run's
    own true H1 error and ½ its energy."""
    prob = problem.build(SCENE, 0, 2)
    pen_scale = prob["gamma_n"] * (prob["lam"] + 2 * prob["mu"])
    raw = tresca.run_level(BINARY, SCENE, 0, 2, tmp_path, prob["probes"], pen_scale)
    with h5py.File(tmp_path / "tresca_r0.h5") as f:
        slip = f["tresca/contact/slip"][-1]
        state = f["tresca/contact/state"][-1]
        mids = f["tresca/mesh/midpoints"][:][f["tresca/contact/edges"][:]]
        assert raw["err_h1_semi"] == f["tresca/errors/h1"][-1]
        assert raw["energy"] == pytest.approx(0.5 * f["tresca/energy"][-1], rel=1e-15)
    s_mid = (mids - np.asarray(prob["probes"]["start"])) @ np.asarray(prob["probes"]["tangent"])
    s_samples = np.linspace(0.0, prob["probes"]["length"], len(prob["probes"]["samples"]))
    for s, value in zip(s_mid, slip, strict=True):
        k = int(np.argmin(np.abs(s_samples - s)))
        assert abs(s_samples[k] - s) < 1e-12  # the 513 samples contain the midpoints of 4·2^r edges
        # the samples sit 1e-10·|Γ_C| inside Ω (problem.contact_probes): |∇u| ≲ 1 moves the value by ≲ 1e-10
        assert raw["u_tau_samples"][k] == pytest.approx(value, rel=1e-9, abs=1e-10)
    assert raw["h1_norm"] > 0 and np.isfinite(raw["sigma_t_integral"])
    # the stick margin's sign is the edge state: φ ≥ 0 where the edge sticks, φ < 0 where it slips
    margin = np.asarray(raw["quad_margin"])
    assert np.array_equal(margin >= 0, state == 0) and (state == 1).any()
