"""Issue 40's speed section of ``make bench``: semismooth Newton iterations per step on unilateral/Coulomb scenes
from refine 0 up, and the cost of a unilateral Tresca run against the bilateral one on the same mesh and loads.

    .venv/bin/python verification/bench/contact.py [--ratio-refine 8] [--max-refine 6] [--rounds 3]
                                                     [--level-budget 120] [--write reference/performance.md]
                                                     [--iterations-only]

* **Iterations**: each scene of ``ITERATION_SCENES`` that exists in the checkout (the Coulomb block of
  reference/external.md, the manufactured Coulomb and moving-front unilateral Tresca cases, Hertz at a/R = 0.05
  and 0.1; ``mms_signorini_coulomb`` stands in for a missing Coulomb block) runs at refine 0, 1, … (solve only,
  ``--json``); per level the mean and the largest iteration count of the steps 1…N (step 0 is the initial
  state, solved by none), step 1's (from λ = 0) and the largest of steps 2…N (from the previous step's
  solution). The levels stop at ``--max-refine``, or after a level whose run took more than a quarter of
  ``--level-budget`` seconds (the next one takes about four times as long). Issue 40 asks that they do not grow
  with the mesh.
* **Cost ratio**: Example 5.1 at ``--ratio-refine`` as it is (bilateral bottom) and with ``law = "unilateral"``
  on its bottom, solve only, interleaved ``--rounds`` times; the ratio of the median wall times (and of the
  set-up and the steps apart). Issue 40 asks ≤ 1.5 at 1.57 M unknowns (refine 8).
"""
import argparse
import os
import statistics
import tempfile

from tresca_py.bench.factorisation import write_section
from tresca_py.bench.timing import timed
from tresca_py.common import BIN, CASES, ROOT, load1

HEADING = "## 11. Contact with normal unknowns: iterations and cost (issue 40)"
ITERATION_SCENES = (("Coulomb block", "coulomb_block.toml", "mms_signorini_coulomb.toml"),
                    ("Floating Coulomb block", "floating_coulomb_block.toml", None),
                    ("Manufactured Coulomb", "mms_signorini_coulomb.toml", None),
                    ("Manufactured Tresca, moving fronts", "mms_signorini_moving.toml", None),
                    ("Hertz a/R = 0.05", "hertz_a05.toml", None),
                    ("Hertz a/R = 0.1", "hertz_a10.toml", None))
EX51 = os.path.join(CASES, "paper_example_5_1.toml")
BOTTOM = 'name = "bottom"\nkind = "contact"\n'


def scene_of(name, fallback, cases=CASES):
    """(path, note) of an iteration scene in ``cases``: the case itself, else its stand-in, else (None, why)."""
    path = os.path.join(cases, name)
    if os.path.exists(path):
        return path, ""
    if fallback:
        return os.path.join(CASES, fallback), f"{name} absent from this checkout: {fallback} instead"
    return None, f"{name} absent from this checkout"


def iterations(path, max_refine, level_budget):
    """Rows (refine, unknowns, steps, mean and max iterations per step, step 1's, the largest of steps 2…N,
    wall) of one scene from refine 0."""
    rows = []
    for k in range(max_refine + 1):
        t = timed([BIN, "run", path, "--refine", str(k), "-q"], summary=True)
        r = t.summary["run"]
        its = [s["iterations"] for s in r["step_stats"] if s["n"] > 0]
        rows.append((k, r["unknowns"], len(its), statistics.mean(its), max(its), its[0], max(its[1:], default="—"),
                     t.wall))
        print(f"  refine {k}: {r['unknowns']} unknowns, {statistics.mean(its):.2f} iterations a step "
              f"(max {max(its)}), {t.wall:.2f} s", flush=True)
        if t.wall > level_budget / 4:
            break
    return rows


def unilateral_scene(directory):
    """Example 5.1 with ``law = "unilateral"`` on its bottom (the same mesh and loads), written into directory."""
    text = open(EX51).read()
    if BOTTOM not in text:
        raise SystemExit(f"error: {EX51}: its bottom contact part is not where this bench expects it")
    path = os.path.join(directory, "paper_example_5_1_unilateral.toml")
    with open(path, "w") as fh:
        fh.write(text.replace(BOTTOM, BOTTOM + 'law = "unilateral"\n'))
    return path


def cost_ratio(refine, rounds):
    """{kind: [(wall, set-up, iterations, unknowns)] per round} for the bilateral and the unilateral run,
    interleaved."""
    runs = {"bilateral": [], "unilateral": []}
    with tempfile.TemporaryDirectory(prefix="tresca-bench-contact-") as d:
        scenes = {"bilateral": EX51, "unilateral": unilateral_scene(d)}
        for i in range(rounds):
            for kind, path in scenes.items():
                t = timed([BIN, "run", path, "--refine", str(refine), "-q"], summary=True)
                r = t.summary["run"]
                runs[kind].append((t.wall, sum(r["setup"].values()), r["iterations"], r["unknowns"]))
                print(f"  round {i + 1} {kind}: {t.wall:.2f} s ({r['unknowns']} unknowns, load {load1():.2f})",
                      flush=True)
    return runs


def section(its, ratio, refine, rounds):
    """The markdown section of reference/performance.md."""
    md = [HEADING, "",
          "`verification/bench/contact.py` (`tresca_py/bench/contact.py`), solve-only runs (`tresca-cr run SCENE "
          "--refine k -q --json`).", "",
          "Semismooth Newton iterations per step (steps 1…N; issue 40: they must not grow with the mesh):", "",
          "| scene | refine | unknowns | steps | iterations a step (mean) | max | step 1 | max of steps 2… | wall |",
          "|---|---|---|---|---|---|---|---|---|"]
    for label, note, rows in its:
        if not rows:
            md.append(f"| {label} | — | — | — | — | — | — | — | {note} |")
        for k, n, steps, mean, mx, first, later, wall in rows:
            md.append(f"| {label} | {k} | {n} | {steps} | {mean:.2f} | {mx} | {first} | {later} | {wall:.2f} s |")
        if rows and note:
            md.append(f"| ({note}) | | | | | | | | |")
    if ratio is None:
        return "\n".join(md) + "\n"
    med = {k: [statistics.median(x[i] for x in v) for i in range(2)] for k, v in ratio.items()}
    (bw, bs), (uw, us) = med["bilateral"], med["unilateral"]
    n = ratio["bilateral"][0][3]
    its_b, its_u = ratio["bilateral"][0][2], ratio["unilateral"][0][2]
    md += ["", f"Cost of unilateral contact: Example 5.1 at refine {refine} ({n} unknowns), its bottom bilateral "
           "(the scene) and `law = \"unilateral\"` (same mesh and loads), interleaved, median of "
           f"{rounds} round(s) (issue 40: ≤ 1.5× at 1.57 M unknowns, refine 8):", "",
           "| run | wall | set-up | steps | iterations in all |", "|---|---|---|---|---|",
           f"| bilateral | {bw:.2f} s | {bs:.2f} s | {bw - bs:.2f} s | {its_b} |",
           f"| unilateral | {uw:.2f} s | {us:.2f} s | {uw - us:.2f} s | {its_u} |",
           f"| ratio | **{uw / bw:.2f}** | {us / bs:.2f} | {(uw - us) / max(bw - bs, 1e-9):.2f} | |", ""]
    return "\n".join(md) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ratio-refine", type=int, default=8, help="Example 5.1's level of the cost ratio (8: 1.57 M)")
    ap.add_argument("--max-refine", type=int, default=6, help="the finest level of the iteration counts")
    ap.add_argument("--level-budget", type=float, default=120.0,
                    help="stop the iteration levels after one that took more than a quarter of this (seconds)")
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds of the cost ratio")
    ap.add_argument("--cases", default=CASES, help="where the iteration scenes are (default verification/cases)")
    ap.add_argument("--write", default=None, help="put the section into this markdown file")
    ap.add_argument("--iterations-only", action="store_true", help="the iteration counts only (no cost ratio)")
    a = ap.parse_args(argv)
    its = []
    for label, name, fallback in ITERATION_SCENES:
        path, note = scene_of(name, fallback, a.cases)
        print(f"== iterations: {label} ({note or os.path.relpath(path, ROOT)})", flush=True)
        its.append((label, note, iterations(path, a.max_refine, a.level_budget) if path else []))
    if not a.iterations_only:
        print(f"== cost ratio: Example 5.1 at refine {a.ratio_refine}", flush=True)
    ratio = None if a.iterations_only else cost_ratio(a.ratio_refine, a.rounds)
    text = section(its, ratio, a.ratio_refine, a.rounds)
    print(text)
    if a.write:
        write_section(a.write, text, HEADING)
