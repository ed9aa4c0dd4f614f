"""The targets table (issues 7 and 13) and the files: reference/performance.md and .csv, or with
--mms-only section 6 spliced into the existing report."""
import csv
import os
import shutil
import time

from tresca_py.bench.report.measure import fmt_t, med
from tresca_py.common import REF


def targets_section(b, tg13):
    """The targets table (issues 7 and 13); returns its rows."""
    b.md += ["## Targets (issues 7 and 13)", "", "| target | measured | result |", "|---|---|---|"]
    tg = []
    kf, py, growth = b.kf, b.py, b.growth
    fin_s, fin_w = b.ex[(kf, "ssn", "solve")], b.ex[(kf, "ssn", "write")]
    if kf == 4:
        tg.append(("Example 5.1 finest (6,208 DOF, 640 steps) solved < 0.1 s",
                   f"{fmt_t(fin_s.wall)} process, {fmt_t(med(fin_s.cli))} CLI (ssn)", fin_s.wall < 0.1))
        tg.append(("Example 5.1 finest written in full < 0.3 s",
                   f"{fmt_t(fin_w.wall)} process, {fmt_t(med(fin_w.cli))} CLI (ssn)", fin_w.wall < 0.3))
        if py:
            for name, want in [("skfem", 20), ("dolfinx", 5)]:
                w, o, rw, rs, du = py[(kf, name)]
                ok = rw >= want and rs >= want and du < 1e-8
                tg.append((f"≥ {want}× faster than {name} at equal accuracy (finest level)",
                           f"{rw:.1f}× (process, both written), "
                           f"{rs:.1f}× (own solve total vs Rust solve-only process); "
                           f"max du {du:.1e}", ok))
    if growth and growth[-1][0] >= 1e6:
        n, w1, rss, st, step, w5, rss5 = growth[-1]
        tg.append((f"a 10⁶-DOF step < 2 s ({n} unknowns)",
                   f"step after set-up {fmt_t(step)}; a whole 1-step run {fmt_t(w1)} (factorisation {fmt_t(st[2])}, "
                   f"assembly {fmt_t(st[1])}), peak {rss / 1024 ** 2:.2f} GB", step < 2.0))
        tg.append((f"(stricter reading) a whole 1-step run at {n} unknowns < 2 s", fmt_t(w1), w1 < 2.0))
    if kf == 4:
        tg.append(("(issue 13) Example 5.1 finest solved < 25 ms (process)", f"{fmt_t(fin_s.wall)} (CPU "
                                                                             f"{fmt_t(fin_s.cpu)})",
                   fin_s.wall < 0.025))
        tg.append(("(issue 13) Example 5.1 finest written in full, per-step commits < 80 ms (process)",
                   f"{fmt_t(fin_w.wall)} (CPU {fmt_t(fin_w.cpu)})", fin_w.wall < 0.08))
    tg += tg13
    for t, m, ok in tg:
        b.md.append(f"| {t} | {m} | {'PASS' if ok else 'FAIL'} |")
    b.md += ["", f"Load average at the end: {' '.join(open('/proc/loadavg').read().split()[:3])}.", ""]
    return tg


def write_report(b):
    """reference/performance.md and reference/performance.csv."""
    os.makedirs(REF, exist_ok=True)
    with open(os.path.join(REF, "performance.md"), "w") as f:
        f.write("\n".join(b.md) + "\n")
    keys = sorted({k for r in b.csvrows for k in r})
    with open(os.path.join(REF, "performance.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(b.csvrows)
    shutil.rmtree(b.tmp, ignore_errors=True)
    print("wrote reference/performance.md, reference/performance.csv")


def splice_section_6(b, tg):
    """--mms-only: put the new section 6 (from b.md) into reference/performance.md in place of the old one,
    and its targets into the targets table (rows matched by their target text); sections 1-5 stay."""
    md = b.md
    path = os.path.join(REF, "performance.md")
    old = open(path).read().split("\n")
    i = next(k for k, line in enumerate(old) if line.startswith("## 6."))
    j = next(k for k, line in enumerate(old) if line.startswith("## Targets"))
    sec = md[next(k for k, line in enumerate(md) if line.startswith("## 6.")):]
    note = (f"Section 6 alone regenerated on {time.strftime('%Y-%m-%d', time.gmtime())} by "
            "`.venv/bin/python verification/bench/report.py --mms-only --repeats "
            f"{b.R}` (binary `{b.version}`, load average "
            "at its start "
            f"{' '.join(b.la0)}); sections 1-5 and the other target rows are from the last full `make bench`.")
    new = old[:i] + [sec[0], "", note] + sec[1:] + old[j:]
    for t, m, ok in tg:
        row = f"| {t} | {m} | {'PASS' if ok else 'FAIL'} |"
        k = next((k for k, line in enumerate(new) if line.startswith(f"| {t} |")), None)
        if k is not None:
            new[k] = row
        else:
            last = max(k for k, line in enumerate(new) if line.startswith("| (issue 13)"))
            new.insert(last + 1, row)
    with open(path, "w") as f:
        f.write("\n".join(new))
