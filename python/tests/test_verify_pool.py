"""The worker pool of make verify (tresca_py.verify.pool): the requirement table, the staged reference files
and the printed output do not depend on which study finishes first."""
import os
import time

from tresca_py.verify import pool
from tresca_py.verify.harness import Harness


def fake(name, delay, rid):
    """A study that waits ``delay`` s, prints (itself and from a child process), records one result and
    stages one file."""
    def fn(hs):
        time.sleep(delay)
        print(f"{name}: first line", flush=True)
        os.system(f"echo '{name}: from a child process'")
        hs.require(rid, True, f"{name} measured")
        hs.write(f"{name}.md", f"{name}\n")
    return pool.Study(name, fn)


def run(tmp_path, studies, jobs):
    hs = Harness(out=str(tmp_path / f"{'-'.join(s.name for s in studies)}-{jobs}"))
    pool.run(hs, studies, jobs=jobs)
    staged = {n: open(hs.path(n)).read() for n in sorted(os.listdir(hs.staged))}
    return hs.table(), staged


def test_the_table_and_staged_files_are_the_same_whatever_the_finishing_order(tmp_path, capfd):
    # with two workers the slow first study finishes after the fast second one
    slow, fast = fake("slow", 0.5, "T1-study-tests-a"), fake("fast", 0.0, "T1-study-tests-b")
    serial = run(tmp_path, [slow, fast], 1)
    assert run(tmp_path, [slow, fast], 2) == serial
    out = capfd.readouterr().out
    # each study's output printed whole and in the table's order, both times
    block = "slow: first line\nslow: from a child process\n"
    assert out.count(block) == 2, out
    assert out.index(block) < out.index("fast: first line")
    assert out.rindex(block) < out.rindex("fast: first line")
    # the other table order gives the other order of rows, again whatever the finishing order
    assert run(tmp_path, [fast, slow], 2) == run(tmp_path, [fast, slow], 1)
    assert serial[0].index("T1-study-tests-a") < serial[0].index("T1-study-tests-b")


def test_a_study_that_raises_is_a_failed_requirement():
    def broken(hs):
        raise RuntimeError("no binary")
    hs = Harness(out=None, echo=False)
    pool.run(hs, [pool.Study("broken", broken)], jobs=2)
    assert [(r.id, r.passed, r.measured) for r in hs.results] == [("broken-run", False, "no binary")]


def test_alone_studies_run_by_themselves_and_files_go_to_their_declared_owner():
    a, b = pool.Study("a", None, writes=("a/*",)), pool.Study("b", None, alone=True)
    c = pool.Study("c", None, writes=("c.h5",))
    assert pool.segments([a, b, c]) == [[a], [b], [c]]
    assert pool.segments([a, c]) == [[a, c]]
    assert pool.owns(a, "a/x/level_1.h5") and not pool.owns(a, "c.h5") and pool.owns(c, "c.h5")
