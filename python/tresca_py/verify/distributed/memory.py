"""D2: peak resident memory of the big case at -n 1 and -n 2, and the requirement it makes."""
import datetime
import json
import os

import numpy as np

from tresca_py import compare
from tresca_py.common import ROOT, cmdline
from tresca_py.common import short_path as rel
from tresca_py.dolfinx_cr.distributed.output import setup_times
from tresca_py.verify import cross_check  # scenes, quick levels
from tresca_py.verify.distributed.runs import TOL, attrs, dist_cmd, parse_rss, run
from tresca_py.verify.distributed.scaling import scaling_model


MEM_JSON = os.path.join(ROOT, "reference", "distributed_memory.json")

# Memory: the bound: the largest rank at -n 2 holds at most 60 % of the -n 1 peak (perfect
# spreading would give 50 % plus the per-process constant of Python, dolfinx and PETSc, ~0.2 GB).
MEM_RATIO = 0.6

BIG = dict(case="paper_example_5_1", refine=8, steps=3)


def memory(work, binary, with_rust):
    """D2: the big case at -n 1 and -n 2; returns a dict of measurements."""
    scene = os.path.join(cross_check.CASES_DIR, f"{BIG['case']}.toml")
    meas = dict(case=BIG["case"], refine=BIG["refine"], steps=BIG["steps"], runs={}, commands=[],
                date=datetime.date.today().isoformat(), load_before=os.getloadavg()[1])
    for n in (1, 2):
        out = os.path.join(work, f"big_np{n}.h5")
        cmd = dist_cmd(scene, out, BIG["refine"], BIG["steps"], n, timed=True, extra=["--frame-every", "0"])
        print(f"  running {cmdline(cmd)}", flush=True)
        p, wall = run(cmd, timeout=3600)
        meas["commands"].append(cmdline(cmd))
        if p.returncode != 0:
            meas["runs"][str(n)] = dict(error=(p.stderr or p.stdout).strip()[-400:])
            print(f"  -n {n} FAILED: {meas['runs'][str(n)]['error']}", flush=True)
            continue
        a = attrs(out)
        rss = parse_rss(p.stderr)
        meas["runs"][str(n)] = dict(
            wall=wall, rss_time_mb=rss, rss_self_mb=[float(x) for x in np.atleast_1d(a["peak_rss_mb"])],
            setup_time=float(a["setup_time"]), setup_times=setup_times(a),
            setup_peak_mb=json.loads(a["setup_peak_rss_mb"]), step_median=float(a["step_time_median"]),
            total=float(a["total_time"]), unknowns=int(a["n_dofs"]), n_contact=int(a["n_contact"]),
            mumps=json.loads(a["mumps"]), file=rel(out))
        print(f"  -n {n}: RSS per rank {', '.join(f'{x:.0f}' for x in rss)} MB; set-up {a['setup_time']:.1f} s, "
              f"step {a['step_time_median']:.2f} s", flush=True)
    if all(str(n) in meas["runs"] and "error" not in meas["runs"][str(n)] for n in (1, 2)):
        r = compare.compare_files(os.path.join(work, "big_np1.h5"), os.path.join(work, "big_np2.h5"))
        meas["agree_1_2"] = dict(du=r["du"], dE=r["dE"], dsig=r["dsig"], flags=r["flags"])
        meas["commands"].append(f".venv/bin/python scripts/compare.py {rel(os.path.join(work, 'big_np1.h5'))} "
                                f"{rel(os.path.join(work, 'big_np2.h5'))} --strict-flags")
    if with_rust:
        rs = os.path.join(work, "big_rust.h5")
        cmd = ["/usr/bin/time", "-f", "RSS %M KB wall %e s", binary, "run", scene, "-o", rs, "--force", "-q",
               "--refine", str(BIG["refine"]), "--steps", str(BIG["steps"]), "--frame-every", str(BIG["steps"])]
        print(f"  running {cmdline(cmd)}", flush=True)
        p, wall = run(cmd)
        meas["commands"].append(cmdline(cmd))
        if p.returncode == 0:
            rss = parse_rss(p.stderr)
            meas["rust"] = dict(wall=wall, rss_mb=rss[0] if rss else None)
            r = compare.compare_files(rs, os.path.join(work, "big_np2.h5"))
            meas["rust"]["agree_np2"] = dict(du=r["du"], dE=r["dE"], dsig=r["dsig"], flags=r["flags"])
            os.remove(rs)
    return meas


def check_d2(hs, args, self_cmd):
    """D2: the memory of -n 2 against -n 1 (measured with --memory, else the last measurement); returns it."""
    meas = None
    if args.memory:
        print("D2: memory at -n 1 and -n 2", flush=True)
        meas = memory(args.work, args.bin, args.with_rust)
        ok_runs = all(str(n) in meas["runs"] and "error" not in meas["runs"][str(n)] for n in (1, 2))
        if ok_runs:
            meas["model"] = scaling_model(meas)
        with open(args.memory_json or MEM_JSON, "w") as f:
            json.dump(meas, f, indent=1)
    elif os.path.exists(MEM_JSON):
        with open(MEM_JSON) as f:
            meas = json.load(f)
    if meas is not None:
        ok_runs = all(str(n) in meas["runs"] and "error" not in meas["runs"][str(n)] for n in (1, 2))
        if ok_runs:
            m1 = max(meas["runs"]["1"]["rss_time_mb"])
            m2 = max(meas["runs"]["2"]["rss_time_mb"])
            ag = meas.get("agree_1_2", {})
            agree_ok = ag and max(ag["du"], ag["dE"], ag["dsig"]) <= TOL and ag["flags"] == 0
            big_ok = meas["runs"]["1"]["unknowns"] >= 10 ** 6
            ok = m2 <= MEM_RATIO * m1 and agree_ok and big_ok
            d2_meas = (f"{meas['runs']['1']['unknowns']} unknowns: peak RSS -n 1 "
                       f"{m1:.0f} MB, -n 2 largest rank {m2:.0f} MB "
                       "(ratio "
                       f"{m2 / m1:.2f}); -n 1 vs -n 2 du {ag.get('du', float('nan')):.1e}, flags {ag.get('flags')}")
        else:
            ok = False
            d2_meas = "; ".join(f"-n {n}: {r.get('error', 'ok')}" for n, r in meas["runs"].items())
        if not args.memory:
            d2_meas += f" (measured {meas['date']}, not re-run: give --memory)"
        hs.require("D2-distributed-memory", ok, d2_meas,
                   statement=(f"on ≥ 10⁶ unknowns the peak resident memory of the largest rank at mpirun -n 2 shall be "
                              f"at most {MEM_RATIO} × the -n 1 peak, the two runs agreeing within {TOL:g}"),
                   command=self_cmd + " --memory", reference="reference/distributed.md")
    return meas
