"""The bench's measurements: a command line run repeatedly (Rec), what its --json summary says, the
formatting of times, and the scenes every section uses."""
import os
import statistics

import h5py

from tresca_py.bench.timing import timed
from tresca_py.common import ROOT, load1
from tresca_py.compare import CompareError, compare_files
from tresca_py.verify import summary as cli_summary

ELASTIC = os.path.join(ROOT, "verification", "bench", "bench_elastic.toml")

EX51 = os.path.join(ROOT, "verification", "cases", "paper_example_5_1.toml")


def run_info(s):
    """What a run's --json summary says: sizes, the set-up split (results-file order), iterations, CLI wall."""
    r = s["run"]
    return dict(unknowns=r["unknowns"], paper_dofs=r["paper_dofs"], contact=r["contact_edges"], steps=r["steps"],
                setup=cli_summary.setup_times(s), iters=r["iterations"], residual=r["max_residual"],
                cli_wall=s["wall"])


def max_du(a, b):
    """The largest relative L2 difference of u over the time nodes of two results files
    (tresca_py.compare, what scripts/compare.py reports); NaN when they cannot be compared."""
    try:
        return compare_files(a, b)["du"]
    except (CompareError, OSError, KeyError) as e:
        print(f"warning: {a} vs {b}: {e}")
        return float("nan")


def med(xs):
    return statistics.median(xs)


class Rec:
    """Repeated measurement of one command line."""

    def __init__(self, cmd, repeats, env=None, mem=False, h5=None):
        self.cmd = cmd
        self.walls, self.cli, self.setups, self.loads, self.rss, self.step_walls = [], [], [], [], [], []
        self.cpus = []
        self.info = None
        for _ in range(repeats):
            la = load1()
            t = timed(cmd, env=env, mem=mem, summary=True)
            r = run_info(t.summary)
            self.info = r
            self.walls.append(t.wall)
            self.cpus.append(t.cpu)
            self.cli.append(r["cli_wall"])
            self.setups.append(r["setup"])
            self.loads.append(la)
            if t.rss is not None:
                self.rss.append(t.rss)
            if h5:
                with h5py.File(h5, "r") as f:
                    self.step_walls.extend(f["tresca/steps/wall_time"][1:].tolist())

    @property
    def wall(self):
        return med(self.walls)

    @property
    def cpu(self):
        return med(self.cpus)

    @property
    def setup(self):
        return [med([s[i] for s in self.setups]) for i in range(5)]

    @property
    def per_step(self):
        """(CLI wall - set-up) / N per run, median: step time including the result handling."""
        n = self.info["steps"]
        return med([(c - sum(s)) / n for c, s in zip(self.cli, self.setups, strict=False)])

    @property
    def load(self):
        return f"{min(self.loads):.2f}-{max(self.loads):.2f}"

    def shell(self):
        return " ".join(os.path.relpath(c, ROOT) if c.startswith(ROOT) else c for c in self.cmd)


def fmt_t(s):
    if s < 1e-3:
        return f"{s * 1e6:.1f} µs"
    if s < 1:
        return f"{s * 1e3:.1f} ms"
    return f"{s:.2f} s"
