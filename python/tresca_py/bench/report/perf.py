"""Section 5: the perf profile of the Example 5.1 finest run, solve-only and written."""
import os
import shutil

from tresca_py.bench.report.measure import EX51
from tresca_py.bench.report.profile import perf_profile
from tresca_py.common import BIN


def perf_section(b):
    if b.args.no_perf or not shutil.which("perf"):
        return
    kf = b.kf
    print("== 5. perf", flush=True)
    b.md += ["## 5. Profile of the Example 5.1 finest run", "",
             "`perf record -F 20000 -g -- tresca-cr run paper_example_5_1.toml --refine "
             f"{kf} --steps {40 * 2 ** kf} -q "
             "[-o out.h5 --force]`, `perf report --stdio --no-children --sort symbol` (self time; symbols ≥ 0.7 %), "
             "and the self time grouped by what it does.", ""]
    for label, extra in [("solve-only", []), ("written", ["-o", os.path.join(b.tmp, "perf.h5"), "--force"])]:
        cmd = [BIN, "run", EX51, "--refine", str(kf), "--steps", str(40 * 2 ** kf), "-q"] + extra
        lines, groups = perf_profile(cmd, b.tmp, label)
        if lines is None:
            b.md += [f"perf failed: {groups}", ""]
            continue
        b.md += [f"### {label}", "", "Grouped self time:", "", "| share | where |", "|---|---|"]
        for g, p in sorted(groups.items(), key=lambda kv: -kv[1]):
            if p >= 0.5:
                b.md.append(f"| {p:.1f} % | {g} |")
        b.md += ["", "Top symbols (self):", "", "```"] + lines[:25] + ["```", ""]
