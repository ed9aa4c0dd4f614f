"""The planner's own CPU against the CPU of the plan it recommends (issue 32: at most 5 %), for binaries
compared interleaved in one run. A benchmark (make bench), never a requirement.

Per case, ``rounds`` rounds: each round one `tresca-cr plan SCENE --target T` per binary, and every other
round one run of the plan each binary recommended (so the plan's CPU is a median of about rounds/2): the
uniform plan's `run … -q` line, and with the adaptive route recommended also its `adapt --target η` line.
CPU = user + sys of the child (getrusage). Scenes without their ``[exact]`` (a user's run evaluates no true
error). Prints one line per case and binary: the planner's median CPU, each plan's, the ratios, the load.
"""
import argparse
import os
import re
import statistics
import subprocess
import tempfile

from tresca_py.common import BIN, ROOT, case, child_cpu, load1, strip_exact

CASES = [("mms_stop", "5.6e-3", ()), ("mms_stop", "2e-3", ()), ("mms_front", "3e-3", ()),
         ("mms_rotated", "3e-3", ()), ("paper_example_5_1", "1e-4", ()),
         ("paper_example_5_1", "1e-4", ("--uniform-only",))]
UNIFORM = re.compile(r"run it: tresca-cr run \S+ --refine (\d+) --steps (\d+) --solver (\w+) --tol (\S+)")
ADAPTIVE = re.compile(r"run it: tresca-cr adapt \S+ --target (\S+) --theta (\S+) --steps (\d+)")


def cpu(cmd):
    """CPU seconds and stdout of one process."""
    c0 = child_cpu()
    p = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, cwd=ROOT)
    return child_cpu() - c0, p.stdout


def recommended(binary, scene, out):
    """The commands of the plans a planner's output recommends, by route."""
    cmds = {}
    if m := UNIFORM.search(out):
        cmds["uniform"] = [binary, "run", scene, "--refine", m[1], "--steps", m[2], "--solver", m[3], "--tol", m[4],
                           "-q"]
    if a := ADAPTIVE.search(out):
        cmds["adaptive"] = [binary, "adapt", scene, "--target", a[1], "--theta", a[2], "--steps", a[3]]
    return cmds


def measure(binaries, name, target, extra, rounds, tmp):
    scene = os.path.join(tmp, f"{name}.toml")
    with open(scene, "w") as f:
        f.write(strip_exact(open(case(name)).read()))
    planner = {b: [] for b in binaries}
    plans, loads, chosen = {}, [], {}
    for rnd in range(rounds):
        for b in binaries:
            loads.append(load1())
            c, out = cpu([b, "plan", scene, "--target", target, *extra])
            planner[b].append(c)
            cmds = recommended(b, scene, out)
            chosen[b] = "adaptive" if "adaptive" in cmds else "uniform"
            if rnd % 2 == 0:
                for route, cmd in cmds.items():
                    plans.setdefault((b, route, " ".join(str(c) for c in cmd[3:] if c != "-q")), []).append(cpu(cmd)[0])
    for b in binaries:
        pm = statistics.median(planner[b])
        line = (f"{name} {target} {' '.join(extra)} [{os.path.basename(b)}] planner {pm:.3f} s "
                f"({min(planner[b]):.3f}-{max(planner[b]):.3f}); recommends {chosen[b]}")
        for (bb, route, cfg), v in plans.items():
            if bb == b:
                rm = statistics.median(v)
                line += f"; {route} [{cfg}] {rm:.3f} s (n = {len(v)}): ratio {pm / rm:.3f}"
        print(f"{line}; load {min(loads):.1f}-{max(loads):.1f}", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", nargs="+", default=[BIN], help="binaries compared interleaved")
    ap.add_argument("--rounds", type=int, default=6)
    ap.add_argument("--cases", nargs="*", help="scene names (default: all five cases)")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="tresca-share-") as tmp:
        for name, target, extra in CASES:
            if not args.cases or name in args.cases:
                measure([os.path.abspath(b) for b in args.bin], name, target, extra, args.rounds, tmp)
