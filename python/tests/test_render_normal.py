"""render.py's pictures of the normal condition along Γ_C (issue 40, "Results"): the contact pressure and σ_τ over
the friction threshold, for unilateral and Coulomb results."""
import os

import numpy as np
import pytest

from conftest import PY, SCRIPTS, run
from tresca_py import render
from tresca_py.common import CASES


@pytest.fixture(scope="module", params=["mms_signorini_moving", "mms_signorini_coulomb"])
def normal_run(request, tmp_path_factory, rust_bin):
    out = str(tmp_path_factory.mktemp(request.param) / "run.h5")
    p = run([rust_bin, "run", os.path.join(CASES, f"{request.param}.toml"), "--refine", "1", "-o", out, "-q"])
    assert p.returncode == 0, p.stderr
    return out


def test_render_draws_the_normal_condition(normal_run, tmp_path):
    """The system shall draw, for a unilateral or Coulomb run, one picture of the pressure and of σ_τ over the
    threshold along Γ_C per chosen time, beside the deformed body and the contact picture."""
    p = run([PY, os.path.join(SCRIPTS, "render.py"), normal_run, "-o", str(tmp_path), "--times", "1.0"])
    assert p.returncode == 0, p.stderr
    names = sorted(os.listdir(tmp_path))
    assert [n for n in names if n.startswith("normal_")] == ["normal_000008.png"], names
    assert os.path.getsize(tmp_path / "normal_000008.png") > 10_000


def test_threshold_ratio_is_one_on_slip_below_on_stick(normal_run):
    """The system shall show |σ_τ| over the threshold as 1 on a slipping edge and at most 1 on a sticking one, and no
    value where the edge is separated."""
    d = render.load(normal_run)
    # a slipping edge's force is the threshold itself (the solver projects onto it) and a sticking one's lies inside
    # to the solver's tolerance (1e-12 in these cases); the division rounds by a few ε
    tol = 1e-12
    seen = set()
    for n in range(1, len(d["times"])):
        r, status = render.threshold_ratio(d, n), d["c_status"][n]
        assert np.all(np.isnan(r[status == 2]))
        assert np.all(np.abs(r[status == 1] - 1) <= tol), r[status == 1]
        assert np.all(r[status == 0] <= 1 + tol), r[status == 0]
        seen.update(int(s) for s in status)
    assert seen == {0, 1, 2}, "the case has stick, slip and separated edges"
