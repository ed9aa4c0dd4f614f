#!/usr/bin/env python3
"""External codes on the continuous problem (issue 30 §3): GetFEM P1/P2, the scikit-fem P2 Nitsche solver and
tresca-cr on six scenes (one a Gmsh mesh), each at five uniform refinements; Richardson limits with GCI bands,
pairwise agreement, true-error orders; writes reference/external.{md,csv} and reference/external_{dof,wall}.png.

    verification/external/run.py [--scene NAME ...] [--code CODE ...] [--from-rows out/external/rows.json]
"""
import argparse
import json
import os
import sys
import time
from pathlib import Path

# One BLAS/OpenMP thread: on the shared 2-core machine a threaded BLAS made the scikit-fem solver's small dense
# solves 7× slower (measured at load 13: Example 5.1 refine 4, 12.0 s against 1.7 s).
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

from tresca_py.external import report, requirements, suite  # noqa: E402 (after the thread settings above)

ROOT = Path(__file__).resolve().parents[2]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", action="append", choices=[s.name for s in suite.SCENES])
    ap.add_argument("--code", action="append", choices=suite.CODES)
    ap.add_argument("--out", default=str(ROOT / "out" / "external"))
    ap.add_argument("--reference", default=str(ROOT / "reference"))
    ap.add_argument("--binary", default=str(ROOT / "target" / "release" / "tresca-cr"))
    ap.add_argument("--from-rows", help="re-analyse a previous run's rows.json instead of running")
    ap.add_argument("--requirements-json", help="also write the requirement list there (for make verify's harness)")
    args = ap.parse_args(argv)
    scenes = [s for s in suite.SCENES if not args.scene or s.name in args.scene]
    codes = tuple(args.code or suite.CODES)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    if args.from_rows:
        saved = json.loads(Path(args.from_rows).read_text())
        rows, notes, elapsed = saved["rows"], saved["notes"], saved["elapsed_s"]
    else:
        rows, notes = [], {}
        for sc in scenes:
            print(f"{sc.name}: {sc.path}, refine {sc.levels}, {sc.steps} steps", flush=True)
            try:
                r, n = suite.run_scene(sc, codes, out, args.binary)
            except (RuntimeError, ValueError) as err:
                print(f"error: {err}", file=sys.stderr)
                return 1
            rows += r
            notes[sc.name] = n
        elapsed = time.perf_counter() - t0
        (out / "rows.json").write_text(json.dumps({"rows": rows, "notes": notes, "elapsed_s": elapsed}))
    reqs = requirements.evaluate(rows, scenes)
    report.write_all(rows, scenes, notes, reqs, elapsed, Path(args.reference), out)
    if args.requirements_json:
        Path(args.requirements_json).write_text(json.dumps(
            [{"id": rid, "statement": f"The solvers shall: {text}", "passed": bool(ok), "measured": detail,
              "command": cmd, "reference": "reference/external.md"} for rid, text, ok, detail, cmd in reqs],
            indent=1, ensure_ascii=False))
    for rid, text, ok, detail, _ in reqs:
        print(f"{'PASS' if ok else 'FAIL'}  {rid}: {text} — {detail}")
    print(f"{sum(r[2] for r in reqs)}/{len(reqs)} requirements pass; suite {elapsed:.0f} s")
    return 0 if all(r[2] for r in reqs) else 1


if __name__ == "__main__":
    sys.exit(main())
