"""The state of a stability check and its runs of the release CLI on derived scenes."""
import atexit
import os
import re
import shutil
import tempfile

import h5py

from tresca_py.common import BIN, ROOT
from tresca_py.verify import summary as cli_summary

NEAR = os.path.join(ROOT, "verification", "cases", "near_incompressible.toml")
EX51 = os.path.join(ROOT, "verification", "cases", "paper_example_5_1.toml")
MMS_EL = os.path.join(ROOT, "verification", "cases", "mms_elastic.toml")


class Stability:
    """The state of one stability check: a temporary directory for the derived scenes and their results
    files (removed at exit), the results files written (all checked for NaN/Inf at the end) and the
    harness recording one requirement per case, S1, S2, … in order."""

    def __init__(self, hs):
        self.tmp = tempfile.mkdtemp(prefix="tresca-stab-")
        atexit.register(shutil.rmtree, self.tmp, True)  # the runs' files are intermediate
        self.h5_files = []
        self.hs = hs
        self.rows = []  # (case, expected, measured, passed) for reference/stability.md

    def check(self, case, expected, measured, passed):
        self.rows.append((case, expected, measured, bool(passed)))
        self.hs.require(f"S{len(self.rows)}-stability", passed, measured, statement=f"{case}: {expected}",
                        command="verification/stability.py", reference="reference/stability.md")


def sub(text, pattern, repl, count=1):
    new, n = re.subn(pattern, repl, text, count=count, flags=re.M)
    assert n >= 1, f"pattern {pattern!r} not found"
    return new


def write(st, text, name):
    p = os.path.join(st.tmp, name)
    open(p, "w").write(text)
    return p


def run(st, scene, *extra, out=None):
    """Run the CLI with a --json summary; return dict(rc, stderr, err = (energy, H1, L2) max over the time
    nodes or None, iters, res = the summed iterations and the max residual or None, h5 path)."""
    cmd = [BIN, "run", scene, "-q"] + [str(e) for e in extra]
    if out:
        out = os.path.join(st.tmp, out)
        cmd += ["-o", out, "--force"]
        st.h5_files.append(out)
    summary, p = cli_summary.run(cmd, check=False)
    r = dict(rc=p.returncode, stderr=p.stderr.strip(), h5=out, err=None, iters=None, res=None)
    if p.returncode == 0 and summary is not None:
        r["err"] = cli_summary.max_errors(summary)
        r["iters"], r["res"] = summary["run"]["iterations"], summary["run"]["max_residual"]
    return r


def h5(path, name):
    with h5py.File(path, "r") as f:
        return f[name][()]
