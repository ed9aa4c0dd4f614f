"""The brute-force grid of verification/planner.py (:mod:`tresca_py.verify.planner`): configurations
(refine r, steps N) of one manufactured case, each run once and cached, and run only when a question needs them.

A configuration is run as a plan runs it: semismooth Newton at the plan's tolerance (GRID_TOL, the tolerance
`tresca-cr plan` chooses for every target of the sweep: 10^⌊log₁₀(0.01 T/‖u‖)⌋ clamped to ≤ 1e-6, src/plan/mod.rs).
So a plan's configuration is a grid point, and its true error is the grid's (one run for both; the same command,
bit for bit, as the planned level of `plan --run`).

The questions, and the runs they need:
* the sweep's finest target: the finest configuration (refine R, the most steps N_max);
* PL5, the cheapest configuration meeting a bound: the configurations in increasing work W(n, N)
  (:func:`tresca_py.verify.planner_md.work`; n from `tresca-cr check`, which costs no solve, up to the level
  it assembles, ~1e5 unknowns; a finer level's from a run, :meth:`Grid.unknowns`) up to the
  first one that meets it. Every configuration of less work is run and found not to meet it, so the answer is
  exactly the full grid's;
* with --costs (`make bench`: the cheapest configuration by CPU time, which no order predicts), every one.
"""
import json
import os

from tresca_py.common import BIN, case, cmdline, strip_exact
from tresca_py.verify import summary as cli_summary
from tresca_py.verify.planner_md import work

# the plans' solver tolerance at the sweep's targets (module doc)
GRID_TOL = 1e-6


class Cache:
    """Measured configurations, kept in a JSON file as they are measured, so an interrupted check resumes
    where it stopped. Valid only for the binary that measured them: a file written by another version
    (``tresca-cr --version``, which names the commit) is ignored and replaced."""

    def __init__(self, path, version):
        self.path, self.rows, self.version = path, {}, version
        if path and os.path.exists(path):
            data = json.load(open(path))
            if data.get("version") == version:
                self.rows = data["rows"]

    def get(self, key):
        return self.rows.get(key)

    def put(self, key, row):
        self.rows[key] = row
        if self.path:
            with open(self.path + ".tmp", "w") as f:
                json.dump(dict(version=self.version, rows=self.rows), f)
            os.replace(self.path + ".tmp", self.path)


class Runner:
    """Runs configurations of one case (cached): true error with [exact]; with ``measure`` (a function of a
    command returning CPU s, wall s, load) also the cost, on the scene without [exact]."""

    def __init__(self, name, tmp, cache, measure=None):
        self.name = name
        self.full = case(name)
        self.bare = os.path.join(tmp, f"{name}_noexact.toml")
        open(self.bare, "w").write(strip_exact(open(self.full).read()))
        # a mesh file the scene names resolves beside the copy too (mms_lshape's lshape_sides.msh)
        here = os.path.dirname(self.full)
        for f in os.listdir(here):
            if f.endswith(".msh") and not os.path.exists(os.path.join(tmp, f)):
                os.symlink(os.path.join(here, f), os.path.join(tmp, f))
        self.cache, self.measure = cache, measure

    def config(self, r, n, tol):
        key = f"{self.name}:{r}:{n}:{tol}"
        row = self.cache.get(key)
        extra = ["--solver", "ssn", "--tol", f"{tol:g}"]
        cmd = [BIN, "run", self.full, "--refine", r, "--steps", n, "-q"] + extra
        if row is None:
            s, _ = cli_summary.run(cmd)
            row = dict(refine=r, steps=n, tol=tol, error=s["run"]["max_errors"]["energy"], cmd=cmdline(cmd),
                       unknowns=s["run"]["unknowns"])
        if self.measure and "cpu" not in row:
            cpu, wall, load = self.measure([BIN, "run", self.bare, "--refine", r, "--steps", n, "-q"] + extra)
            row.update(cpu=cpu, wall=wall, load=load)
        self.cache.put(key, row)
        return row

    def mesh(self, r):
        """(unknowns, triangles) of the mesh `tresca-cr check --refine r` assembles (no solve; cached). Above
        ASSEMBLED_UNKNOWNS (src/cli/check.rs) it assembles a coarser level: see :meth:`Grid.unknowns`."""
        key = f"{self.name}:{r}:mesh"
        if self.cache.get(key) is None:
            s, _ = cli_summary.run([BIN, "check", self.full, "--refine", r])
            self.cache.put(key, [s["check"]["unknowns"], s["check"]["triangles"]])
        return tuple(self.cache.get(key))


class Grid:
    """Refinements 0..R × ``steps`` of one case at GRID_TOL, run on demand (module doc)."""

    def __init__(self, runner, rmax, steps):
        self.runner, self.refines, self.steps = runner, range(rmax + 1), steps
        self.run = {}

    def at(self, r, n):
        if (r, n) not in self.run:
            self.run[(r, n)] = self.runner.config(r, n, GRID_TOL)
            g = self.run[(r, n)]
            print(f"  grid {self.runner.name} r={r} N={n}: error {g['error']:.4e}" +
                  (f", CPU {g['cpu']:.3f} s" if "cpu" in g else ""), flush=True)
        return self.run[(r, n)]

    def finest(self):
        return self.at(self.refines[-1], self.steps[-1])

    def everything(self):
        return [self.at(r, n) for r in self.refines for n in self.steps]

    def unknowns(self, r):
        """The unknowns at refinement ``r``: a run's; else `check`'s where it assembled level r (its triangles
        4^r times the coarsest level's; a finer level it only counts from a coarser one), else a run's of
        (r, the fewest steps)."""
        known = [g["unknowns"] for (q, _), g in self.run.items() if q == r]
        if known:
            return known[0]
        n, triangles = self.runner.mesh(r)
        if triangles == self.runner.mesh(0)[1] * 4 ** r:
            return n
        return self.at(r, self.steps[0])["unknowns"]

    def by_work(self):
        """The configurations (work, r, N), least work first."""
        return sorted((work(self.unknowns(r), n), r, n) for r in self.refines for n in self.steps)

    def cheapest(self, bound):
        """The configuration of least work whose true error is at most ``bound`` (with its work), or None."""
        for w, r, n in self.by_work():
            g = self.at(r, n)
            if g["error"] <= bound:
                return dict(g, work=w)
        return None

    def rows(self):
        """The configurations run so far."""
        return list(self.run.values())
