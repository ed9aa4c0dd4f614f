"""The scikit-fem solver's unilateral contact (issue 40): scenes with `law`, `coulomb`, a contact `traction` and
`kind = "symmetry"` read and refused as the Rust reader does; the bound-constrained dual QP solved to its KKT
conditions; per-edge pressure, gap and status satisfying the discrete Signorini and friction conditions; and
convergence to the manufactured solutions (study-sized)."""
import pathlib

import numpy as np
import pytest

from tresca_py import results
from tresca_py.common import PY, case, run
from tresca_py.scene import SceneError, load_scene
from tresca_py.skfem_cr.friction import bound_qp, natural_residual
from tresca_py.skfem_cr.unilateral import SEPARATED
from tresca_py.verify.unilateral import convergence, discrete_signorini

BLOCK = """
[mesh]
corners = [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]]
cells = [4, 2]
[material]
E = 100.0
nu = 0.3
[[boundary]]
name = "top"
kind = "dirichlet"
u = ["0", "-0.02*t*x"]
[[boundary]]
name = "left"
kind = "neumann"
traction = ["0.5*t", "0"]
[[boundary]]
name = "right"
kind = "{right}"
[[boundary]]
name = "bottom"
kind = "contact"
{bottom}
[time]
T = 1.0
steps = 3
"""


def write(tmp_path, right="neumann", bottom='g_a = "0.1"', name="s.toml"):
    path = tmp_path / name
    path.write_text(BLOCK.format(right=right, bottom=bottom))
    return path


def solve(tmp_path, scene, refine=1):
    out = tmp_path / (scene.stem + f"_{refine}.h5")
    run([PY, "scripts/skfem_solve.py", scene, "--refine", refine, "-o", out, "-q"])
    return results.read(str(out))


def test_the_system_shall_solve_the_bound_constrained_qp_to_its_kkt_conditions():
    """The system shall solve min ½xᵀCx − dᵀx over lo ≤ x ≤ hi (finite, half-infinite, free and pinned bounds)
    to a natural residual ≤ 1e-12 of the problem's scale."""
    rng = np.random.default_rng(40)
    for trial in range(200):
        n = int(rng.integers(2, 30))
        A = rng.standard_normal((n, n))
        C = A @ A.T + 1e-2 * np.eye(n)
        d = rng.standard_normal(n) * rng.uniform(0.1, 10)
        kind = rng.integers(0, 4, n)                   # box, [0, inf), (-inf, inf), pinned at 0
        w = rng.uniform(0, 2, n)
        lo = np.select([kind == 0, kind == 1, kind == 2], [-w, 0.0, -np.inf], 0.0)
        hi = np.select([kind == 0, kind == 1, kind == 2], [w, np.inf, np.inf], 0.0)
        x, _ = bound_qp(C, d, lo, hi, rng.uniform(-2, 2, n) if trial % 2 else None)
        assert np.all(x >= lo) and np.all(x <= hi)
        scale = np.abs(d).max() + np.abs(C).max() * max(np.abs(x).max(), 1.0)
        assert natural_residual(C, d, lo, hi, x) <= 1e-12 * scale


def test_the_system_shall_read_the_contact_law_coulomb_traction_and_symmetry(tmp_path):
    """The system shall read law, coulomb, a contact traction and a symmetry part."""
    bottom = 'law = "unilateral"\ncoulomb = "0.3"\ngap = "0.001*x"\ntraction = ["0", "-0.1*t"]'
    s = load_scene(write(tmp_path, right="symmetry", bottom=bottom))
    b = {p.name: p for p in s.boundaries}
    assert b["bottom"].law == "unilateral" and b["bottom"].g_a is None and b["bottom"].coulomb is not None
    assert b["bottom"].traction is not None and b["right"].symmetry and b["right"].kind == "contact"
    assert s.normal_unknowns and s.has_boundary_data       # the top's data are lifted, the gap is not


@pytest.mark.parametrize("bottom,right,message", [
    ('g_a = "0.1"\ncoulomb = "0.3"', "neumann", "not both"),
    ('law = "sticky"\ng_a = "0.1"', "neumann", "unknown contact law"),
    ('law = "unilateral"', "neumann", "needs 'g_a'"),
    ('g_a = "0.1"', "symmetry\"\ng_a = \"0.2", "'g_a' is only allowed"),
    ('g_a = "0.1"', "neumann\"\ncoulomb = \"0.2", "'coulomb' is only allowed"),
    ('g_a = "0.1"', "neumann\"\nlaw = \"unilateral", "'law' is only allowed"),
])
def test_the_system_shall_refuse_contact_keys_that_do_not_fit(tmp_path, bottom, right, message):
    """The system shall refuse g_a with coulomb, an unknown law, a friction-less contact part and the contact keys
    on other parts, naming the part."""
    with pytest.raises(SceneError, match=message):
        load_scene(write(tmp_path, right=right, bottom=bottom))


def test_the_system_shall_refuse_unilateral_scenes_in_the_bilateral_solvers(tmp_path):
    """The system shall refuse a unilateral scene in a solver that models bilateral contact only (the distributed
    dolfinx solver)."""
    s = load_scene(write(tmp_path, bottom='law = "unilateral"\ng_a = "0.1"'))
    with pytest.raises(SceneError, match="'bottom'.*bilateral Tresca contact only"):
        s.refuse_contact_extensions("distributed dolfinx")


@pytest.mark.parametrize("coulomb,message", [("x-1", "coulomb = -0.9"), ("sqrt(x-5)", "has the value nan")])
def test_the_system_shall_refuse_a_negative_or_infinite_coulomb_coefficient(tmp_path, coulomb, message):
    """The system shall refuse F < 0 or F not finite, naming the part and a point, with exit status 2."""
    scene = write(tmp_path, bottom=f'law = "unilateral"\ncoulomb = "{coulomb}"')
    p, _ = run([PY, "scripts/skfem_solve.py", scene, "--refine", 1, "-o", tmp_path / "out.h5", "-q"], check=False)
    assert p.returncode == 2 and "boundary 'bottom'" in p.stderr and message in p.stderr
    assert not (tmp_path / "out.h5").exists()


def test_the_system_shall_refuse_an_initial_state_that_penetrates(tmp_path):
    """The system shall refuse u0 with u0.n > g on a unilateral part, naming the part and the point, exit 2."""
    scene = write(tmp_path, bottom='law = "unilateral"\ng_a = "0.1"\ngap = "0.001"')
    scene.write_text(scene.read_text() + '[initial]\nu0 = ["0", "(0.002-0.002*x)*(1-y)"]\n')
    p, _ = run([PY, "scripts/skfem_solve.py", scene, "-o", tmp_path / "out.h5", "-q"], check=False)
    assert p.returncode == 2 and "penetrates the unilateral part 'bottom' at (1.750000, 0.000000)" in p.stderr
    assert not (tmp_path / "out.h5").exists()


def test_the_system_shall_solve_a_symmetry_part_as_frictionless_bilateral_contact(tmp_path):
    """The system shall give a symmetry part exactly the solution of a frictionless bilateral contact part."""
    a = solve(tmp_path, write(tmp_path, bottom='g_a = "0"', right="symmetry", name="sym.toml"))
    b = solve(tmp_path, write(tmp_path, bottom='g_a = "0"', right='contact"\ng_a = "0', name="contact.toml"))
    assert np.array_equal(a.u, b.u)


@pytest.mark.parametrize("name", ["mms_signorini_moving", "mms_signorini_coulomb"])
def test_the_system_shall_satisfy_signorini_and_friction_edge_by_edge(tmp_path, name):
    """The system shall solve every step to a natural residual <= 1e-12 and write per-edge pressure, gap and
    status with P >= 0, u_n <= g, P (u_n - g) = 0, |mu| <= threshold, status 2 where separated (P = 0, open gap),
    else the stick/slip state."""
    r = solve(tmp_path, pathlib.Path(case(name)), refine=1)
    c = r.contact
    assert np.max(r.steps["residual"]) <= 1e-12
    assert discrete_signorini(r) <= 1e-12
    lengths = np.linalg.norm(np.diff(r.mesh.points[r.mesh.edges[c.edges]], axis=1)[:, 0], axis=1)
    P = c.pressure * lengths
    xm = r.mesh.midpoints[c.edges, 0]
    bound = (2 + xm) / 5 * P if name.endswith("coulomb") else np.tile(c.g * lengths, (len(r.times), 1))
    assert np.all(np.abs(c.mu[1:]) <= bound[1:] * (1 + 1e-12) + 1e-15)
    sep = c.status[1:] == SEPARATED
    assert sep.any() and np.all(c.pressure[1:][sep] == 0) and np.all(c.gap[1:][sep] < 0)
    assert np.all(c.pressure[1:][~sep] >= 0) and (c.status[1:] == 1).any() and (c.status[1:] == 0).any()
    assert np.array_equal(np.where(sep, c.state[1:], c.status[1:]), c.state[1:])   # status refines state


@pytest.mark.study
def test_the_system_shall_converge_to_the_manufactured_signorini_solution():
    """The system shall converge with energy order 1 ± 0.1 and L² order 2 ± 0.15 (fit and last two successive
    orders) on mms_signorini_moving, refine 0..3 (the scikit-fem solver)."""
    _, (ok_e, m_e), (ok_l, m_l), _ = convergence("mms_signorini_moving", range(4))
    assert ok_e, m_e
    assert ok_l, m_l


@pytest.mark.parametrize("bottom,separated", [('law = "unilateral"\ng_a = "0.1"\ngap = "-0.001 + 1e-13*x"', False),
                                              ('law = "unilateral"\ng_a = "0.1"\ngap = "-0.001 + 1e-6*x"', True),
                                              ('coulomb = "0.3"\ngap = "-0.001 + 1e-6*x"', False)])
def test_the_system_shall_mark_step_zero_separated_by_the_later_steps_rule(tmp_path, bottom, separated):
    """The system shall mark a unilateral edge separated at step 0 where its gap is open by more than 1e-9 of
    max(|u0.n|, |gbar|) over Gamma_C (1e-3 here; the Rust solver's rule): an opening of <= 2e-13 is rounding
    (closed), one of >= 2.5e-7 is separated; a bilateral edge is never separated."""
    from tresca_py.skfem_cr.cr import Discretisation
    from tresca_py.skfem_cr.unilateral import initial_state
    scene = write(tmp_path, bottom=bottom)
    scene.write_text(scene.read_text() + '[initial]\nu0 = ["0", "0.001*(1 - y)"]\n')
    s = load_scene(scene)
    disc = Discretisation(s)
    _, status = initial_state(disc, disc.interpolate(s.u0, s.times[0]), s.times[0])
    assert len(status) and np.all((status == SEPARATED) == separated), status
