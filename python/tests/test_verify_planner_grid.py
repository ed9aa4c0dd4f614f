"""tresca_py.verify.planner_grid: the brute-force grid run on demand gives PL5's cheapest configuration exactly as
the full grid does, and runs no configuration of more work than that answer (but to learn the unknowns of a level
finer than `tresca-cr check` assembles)."""
import itertools

from tresca_py.verify.planner_grid import Grid
from tresca_py.verify.planner_md import work


class FakeRunner:
    """A case whose error falls with refinement and, at refinement r, also with the steps up to a time floor
    (a time error that more steps remove), and which records the configurations it is asked to run."""

    name = "fake"

    def __init__(self, cap=None):
        self.ran, self.cap = [], cap

    def unknowns(self, r):
        return 100 * 4 ** r

    def mesh(self, r):
        """`check`'s (unknowns, triangles): above ``cap`` the level it assembles is the finest at most cap."""
        q = r if self.cap is None else min(r, self.cap)
        return self.unknowns(q), 10 * 4 ** q

    def config(self, r, n, tol):
        self.ran.append((r, n))
        error = 0.5 ** r + 0.8 / n
        return dict(refine=r, steps=n, tol=tol, error=error, unknowns=self.unknowns(r), cmd="")


def full_cheapest(runner, refines, steps, bound):
    rows = [runner.config(r, n, None) for r, n in itertools.product(refines, steps)]
    meets = [dict(g, work=work(g["unknowns"], g["steps"])) for g in rows if g["error"] <= bound]
    return min(meets, key=lambda g: g["work"], default=None)


def test_the_cheapest_configuration_is_the_full_grids_and_nothing_dearer_is_run():
    """The system shall find, for every bound, the configuration of least work meeting it that the full grid
    finds (or none where none meets it), running only configurations of at most that work."""
    steps = [4, 8, 16, 32]
    for bound, cap in itertools.product([2.0, 0.5, 0.2, 0.1, 0.06, 0.04, 0.03, 1e-3], [None, 3]):
        lazy = FakeRunner(cap)
        got = Grid(lazy, 5, steps).cheapest(bound)
        want = full_cheapest(FakeRunner(), range(6), steps, bound)
        assert (got is None) == (want is None), bound
        if got is None:
            continue
        assert (got["refine"], got["steps"], got["work"]) == (want["refine"], want["steps"], want["work"]), bound
        # beyond check's cap a level's unknowns come from its run of the fewest steps
        learnt = {(r, steps[0]) for r in range(6) if cap is not None and r > cap}
        assert all(work(lazy.unknowns(r), n) <= got["work"] for r, n in set(lazy.ran) - learnt), bound


def test_a_configuration_is_run_once():
    """The system shall run each configuration of the grid at most once, whichever questions ask for it."""
    runner = FakeRunner()
    grid = Grid(runner, 3, [4, 8])
    grid.finest()
    for bound in [0.6, 0.3, 0.2]:
        grid.cheapest(bound)
    grid.everything()
    assert sorted(runner.ran) == sorted(set(runner.ran)) and len(runner.ran) == 8
