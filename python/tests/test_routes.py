"""What each re-implementation route models (``tresca_py.verify.routes``), the refusals of the scenes outside a
route (issue 40)."""
import os

import pytest

from tresca_py.common import CASES, PY, ROOT, case, run
from tresca_py.verify import routes

SCRIPTS = {"dolfinx": "dolfinx_solve.py", "distributed": "dolfinx_distributed.py", "skfem": "skfem_solve.py"}


def test_the_system_shall_state_what_each_route_models_for_every_case():
    """The system shall place every scene of verification/cases in or out of each route by what it declares:
    Coulomb friction outside dolfinx and the distributed route (TAO takes fixed thresholds), unilateral contact and
    floating bodies outside the distributed route, everything inside scikit-fem (whose floating bodies all have a
    unilateral or Coulomb part here); the reason names the part."""
    seen = set()
    for f in sorted(os.listdir(CASES)):
        if not f.endswith(".toml"):
            continue
        path = os.path.join(CASES, f)
        text = open(path).read()
        coulomb, unilateral = "coulomb =" in text, 'law = "unilateral"' in text
        floating = 'kind = "dirichlet"' not in text
        assert routes.unsupported("skfem", path) is None, f
        dx = routes.unsupported("dolfinx", path)
        assert (dx is not None) == coulomb, f
        dist = routes.unsupported("distributed", path)
        assert (dist is not None) == (coulomb or unilateral or floating), f
        for why in (dx, dist):
            if why is not None and why[0] is not None:
                assert f"'{why[0]}'" in why[1], f
        seen.add((coulomb, unilateral, floating))
    assert {(True, True, False), (False, True, False), (False, False, False), (False, True, True)} <= seen


@pytest.mark.parametrize("route, name", [("dolfinx", "coulomb_block"), ("distributed", "mms_signorini_stop"),
                                         ("distributed", "floating_block")])
def test_the_system_shall_refuse_a_scene_outside_a_route_naming_the_part(tmp_path, route, name):
    """The system shall refuse a scene a route does not model with exit status 2, an ``error:`` line naming the part
    (or, for a floating body, the missing Dirichlet part) and no results file, as ``routes.refused`` requires."""
    out = tmp_path / "out.h5"
    p, _ = run([PY, os.path.join(ROOT, "scripts", SCRIPTS[route]), case(name), "-o", str(out), "-q"], check=False)
    part, _why = routes.unsupported(route, case(name))
    assert routes.refused(p.returncode, p.stderr, part), (p.returncode, p.stderr)
    assert not out.exists()


FLOATING_BILATERAL = """title = "a floating block on a bilateral Tresca foundation and a symmetry plane"
[mesh]
corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
cells = [2, 2]
[material]
E = 10.0
nu = 0.3
[[boundary]]
name = "bottom"
kind = "contact"
g_a = "0.5"
[[boundary]]
name = "left"
kind = "symmetry"
[[boundary]]
name = "right"
kind = "neumann"
traction = ["0", "0"]
[[boundary]]
name = "top"
kind = "neumann"
traction = ["0.1*t", "-t"]
[time]
T = 1.0
steps = 2
"""


@pytest.mark.parametrize("route", routes.ROUTES)
def test_the_system_shall_refuse_a_floating_body_without_normal_unknowns_in_every_route(tmp_path, route):
    """The system shall refuse, in every re-implementation route, a floating body (no Dirichlet part) held by
    bilateral contact and a symmetry plane only (no normal unknowns, which the routes' floating solvers need;
    the distributed route has no rigid motions at all): exit status 2 naming the missing Dirichlet part, no file."""
    scene, out = tmp_path / "floating.toml", tmp_path / "out.h5"
    scene.write_text(FLOATING_BILATERAL)
    assert routes.unsupported(route, str(scene)) is not None
    p, _ = run([PY, os.path.join(ROOT, "scripts", SCRIPTS[route]), str(scene), "-o", str(out), "-q"], check=False)
    assert routes.refused(p.returncode, p.stderr, None), (p.returncode, p.stderr)
    assert not out.exists()
