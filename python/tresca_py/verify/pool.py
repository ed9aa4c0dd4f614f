"""The worker pool of ``make verify``: independent studies run side by side in a bounded number of worker
processes, and what they report does not depend on the order in which they finish.

Each study runs in a forked worker with its own :class:`~tresca_py.verify.harness.Harness` (same output
directory) and its standard output and error (the file descriptors, so its child processes' too) sent to a
private file; the parent prints each study's output whole and adopts its results in the table's order, once
that study and every one before it are done. A study marked ``alone`` (it measures memory or time, or wants
every core) runs with no other study beside it.

The energy audit (EB1, :mod:`tresca_py.verify.audits`) is the parent's: a worker only reports the ``.h5`` files
that changed under the output directory while its study ran, which includes those of a study running beside
it; the parent keeps, for each study, those that match the study's declared ``writes`` patterns (paths
relative to the output directory). A changed file that no study declares is audited as ``EB1-other``, so
the table is the same whatever ran beside what.
"""
import fnmatch
import multiprocessing
import os
import pickle
import sys
import tempfile
import time
from dataclasses import dataclass, field
from multiprocessing.connection import wait as mp_wait

from tresca_py.verify import audits
from tresca_py.verify.harness import Harness, Result

#: worker processes by default (this machine's two cores; ``run_all.py --jobs N`` overrides)
DEFAULT_JOBS = 2


@dataclass(frozen=True)
class Study:
    """One study of the table: ``fn(hs)`` records its requirements in the harness ``hs``."""
    name: str
    fn: object
    alone: bool = False
    writes: tuple = field(default=())


def owns(study, rel):
    """True when ``rel`` (a path relative to the output directory) matches one of ``study.writes``."""
    return any(fnmatch.fnmatch(rel, pattern) for pattern in study.writes)


def _captured(fd_file, fn):
    """Run ``fn()`` with file descriptors 1 and 2, and ``sys.stdout``/``sys.stderr`` (line-buffered on them),
    sent to ``fd_file``."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved_fds, saved_streams = (os.dup(1), os.dup(2)), (sys.stdout, sys.stderr)
    os.dup2(fd_file.fileno(), 1)
    os.dup2(fd_file.fileno(), 2)
    sys.stdout, sys.stderr = (open(fd, "w", buffering=1, encoding="utf-8", errors="replace", closefd=False)
                              for fd in (1, 2))
    try:
        return fn()
    finally:
        sys.stdout.close()
        sys.stderr.close()
        sys.stdout, sys.stderr = saved_streams
        for fd, saved in zip((1, 2), saved_fds, strict=True):
            os.dup2(saved, fd)
            os.close(saved)


def run_one(study, out):
    """In a worker: run ``study`` into a fresh harness on ``out``; returns (results, output text, changed .h5
    files relative to ``out``, seconds)."""
    name = study.name
    hs = Harness(out=out)
    before = audits.snapshot(out)
    t0 = time.time()

    def body():
        try:
            study.fn(hs)
        except Exception as e:  # a study that cannot run is a failed requirement, not a crash
            hs.not_run(name, str(e).splitlines()[0][:300] if str(e) else repr(e))

    with tempfile.TemporaryFile(mode="w+", encoding="utf-8", errors="replace") as f:
        _captured(f, body)
        f.seek(0)
        text = f.read()
    changed = [os.path.relpath(p, out) for p in audits.written_after(out, before)]
    return hs.results, text, changed, time.time() - t0


def segments(studies):
    """The table cut into runs of studies that may share the pool, an ``alone`` study being a run by itself."""
    runs, current = [], []
    for s in studies:
        if s.alone:
            runs += [current] if current else []
            runs.append([s])
            current = []
        else:
            current.append(s)
    return runs + ([current] if current else [])


def _child(study, out, path):
    """A worker process (forked: ``study`` is inherited, not pickled): :func:`run_one`, its result pickled
    to ``path``."""
    result = run_one(study, out)
    with open(path, "wb") as f:
        pickle.dump(result, f)


def _collect(name, path, exitcode):
    """The pickled result of a finished worker; a worker that died is a failed ``<name>-run``."""
    try:
        with open(path, "rb") as f:
            return pickle.load(f)
    except (OSError, EOFError, pickle.UnpicklingError):
        return [Result(f"{name}-run", f"`{name}` shall run", False, f"worker exited {exitcode}",
                       "verification/run_all.py", "—")], "", [], 0.0


def _segment(ctx, seg, out, jobs, tmp):
    """Run one segment's studies, at most ``jobs`` at a time (forked processes, no thread in the parent);
    yields (study, result) in the segment's order."""
    queue, running, finished = list(seg), {}, {}
    for s in seg:
        while s.name not in finished:
            while queue and len(running) < jobs:
                nxt = queue.pop(0)
                path = os.path.join(tmp, f"{nxt.name}.pickle")
                running[nxt.name] = (ctx.Process(target=_child, args=(nxt, out, path)), path)
                running[nxt.name][0].start()
            ready = mp_wait([p.sentinel for p, _ in running.values()])
            for name, (p, path) in list(running.items()):
                if p.sentinel in ready:
                    p.join()
                    finished[name] = _collect(name, path, p.exitcode)
                    del running[name]
        yield s, finished.pop(s.name)


def execute(studies, out, jobs):
    """Run ``studies`` with at most ``jobs`` at a time; yields (study, result of :func:`run_one`) in the
    table's order, each as soon as it and the ones before it are done."""
    if jobs <= 1:
        for s in studies:
            yield s, run_one(s, out)
        return
    ctx = multiprocessing.get_context("fork")
    with tempfile.TemporaryDirectory() as tmp:
        for seg in segments(studies):
            yield from _segment(ctx, seg, out, jobs, tmp)


def run(hs, studies, jobs=DEFAULT_JOBS, echo=print):
    """Run the ``studies`` into the harness ``hs`` (its output directory shared by all) and audit the files
    each wrote; the results land in ``hs`` in the table's order whatever the finishing order."""
    changed_all = set()
    for study, (results, text, changed, seconds) in execute(studies, hs.out, jobs):
        echo(f"\n{'=' * 30} {study.name} ({seconds:.0f} s) {'=' * 30}\n{text}", end="")
        sys.stdout.flush()
        hs.adopt(results)
        changed_all.update(changed)
        mine = sorted(os.path.join(hs.out, p) for p in changed if owns(study, p))
        audits.record(hs, study.name, mine)
    undeclared = sorted(os.path.join(hs.out, p) for p in changed_all if not any(owns(s, p) for s in studies))
    audits.record(hs, "other", undeclared)
