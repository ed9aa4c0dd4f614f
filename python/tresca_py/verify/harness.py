"""The one harness of ``make verify``: it records each requirement's result, writes the reports, and keeps
a clean clone clean.

Everything a verification run writes goes under ``out/verify/`` (:func:`out_dir`): the tables, CSVs and
plots meant for ``reference/`` are staged in ``out/verify/reference/`` (:meth:`Harness.path`,
:meth:`Harness.write`), the summary in ``out/verify/summary.md`` and ``out/verify/results.json``. ``make
reference`` copies the staged files into the tracked ``reference/`` (:func:`publish`).

A result's id must belong to a requirement declared in :mod:`tresca_py.verify.requirements`, which gives
its default statement, command and reference file. A study that cannot run at all is recorded with
:meth:`Harness.not_run` (id ``<study>-run``), a failed requirement too.
"""
import json
import os
import shutil
import subprocess
import sys
from dataclasses import asdict, dataclass

from tresca_py.common import ROOT
from tresca_py.verify.requirements import find


def out_dir():
    """``out/verify/`` of the repository (created)."""
    d = os.path.join(ROOT, "out", "verify")
    os.makedirs(os.path.join(d, "reference"), exist_ok=True)
    return d


@dataclass(frozen=True)
class Result:
    id: str
    statement: str
    passed: bool
    measured: str
    command: str
    reference: str


class Harness:
    """Results of one verification run and where its files go (``out``: default :func:`out_dir`)."""

    def __init__(self, out=None, echo=True):
        self.out = out or out_dir()
        self.staged = os.path.join(self.out, "reference")
        os.makedirs(self.staged, exist_ok=True)
        self.results = []
        self.echo = echo

    def path(self, name):
        """Where a file meant for ``reference/NAME`` is staged."""
        return os.path.join(self.staged, name)

    def write(self, name, text):
        """Stage ``reference/NAME`` with ``text``."""
        with open(self.path(name), "w", encoding="utf-8") as f:
            f.write(text)

    def require(self, rid, passed, measured, statement=None, command=None, reference=None):
        """Record one result; the declared requirement of ``rid`` gives the defaults."""
        req = find(rid)
        r = Result(rid, statement or req.sentence, bool(passed), str(measured), command or req.command,
                   reference or req.reference or "—")
        self._record(r)
        return r.passed

    def not_run(self, name, why, command="verification/run_all.py"):
        """A study or script that could not run: a failed result ``<name>-run``."""
        self._record(Result(f"{name}-run", f"`{name}` shall run", False, str(why)[:300], command, "—"))

    def adopt(self, results):
        """Append results recorded (and echoed) by another harness, e.g. a worker's (:mod:`.pool`)."""
        self.results.extend(results)

    def _record(self, r):
        self.results.append(r)
        if self.echo:
            print(f"[{'PASS' if r.passed else 'FAIL'}] {r.id}: {r.statement}\n        measured: {r.measured}",
                  flush=True)

    def record_list(self, path, command, name, keep=lambda r: True):
        """Record the requirement list a script wrote as JSON to ``path`` (a list of objects with id,
        statement, passed, measured, command and reference; see :meth:`dump`)."""
        try:
            with open(path, encoding="utf-8") as f:
                reqs = json.load(f)
        except (OSError, ValueError) as e:
            self.not_run(name, f"no requirement list: {e}", command)
            return
        for r in filter(keep, reqs):
            self.require(r["id"], r["passed"], r["measured"], r.get("statement"), r.get("command"),
                         r.get("reference"))

    def run_script(self, cmd, json_path, name, keep=lambda r: True):
        """Run a check script that writes its requirement list to ``json_path`` (removed first: a crashed
        script cannot report a stale list) and record it."""
        if os.path.exists(json_path):
            os.remove(json_path)
        p = subprocess.run([str(c) for c in cmd], cwd=ROOT, capture_output=True, text=True)
        print(p.stdout[-3000:])
        if not os.path.exists(json_path):
            self.not_run(name, f"exit {p.returncode}: {p.stderr.strip()[-300:]}", " ".join(map(str, cmd)))
            return
        self.record_list(json_path, " ".join(map(str, cmd)), name, keep)

    @property
    def failed(self):
        return [r for r in self.results if not r.passed]

    def dump(self, path):
        """The results as a JSON list (what :meth:`record_list` reads)."""
        with open(path, "w", encoding="utf-8") as f:
            json.dump([asdict(r) for r in self.results], f, indent=1, ensure_ascii=False)

    def table(self):
        lines = ["| requirement | statement | result | measured | command | reference |", "|---|---|---|---|---|---|"]
        for r in self.results:
            cell = r.measured.replace("|", "\\|")
            lines.append(f"| {r.id} | {r.statement} | {'PASS' if r.passed else 'FAIL'} | {cell} | `{r.command}` | "
                         f"{r.reference} |")
        return "\n".join(lines) + "\n"

    def report(self, header="", partial=False):
        """Write ``summary.md`` (``summary_partial.md`` for a partial run, which ``make reference`` does not
        publish) and ``results.json`` into the output directory, print the summary and return the exit
        status (1 when any requirement failed or none was recorded)."""
        text = ("<!-- generated by verification/run_all.py -->\n# Verification summary\n\n" + header + "\n\n"
                + self.table())
        name = "summary_partial.md" if partial else "summary.md"
        with open(os.path.join(self.out, name), "w", encoding="utf-8") as f:
            f.write(text)
        self.dump(os.path.join(self.out, "results.json"))
        print("\n" + "=" * 100 + "\nSUMMARY")
        for r in self.results:
            print(f"  {'PASS' if r.passed else 'FAIL'}  {r.id:<22} {r.measured[:70]}")
        print(f"{len(self.results) - len(self.failed)} passed, {len(self.failed)} failed; "
              f"{os.path.relpath(self.out, ROOT)}/{name}")
        return 1 if self.failed or not self.results else 0


def publish(out=None, reference=None):
    """``make reference``: copy the staged files and folders of ``out/verify/reference/`` (and the summary)
    into the tracked ``reference/``; returns the names copied."""
    out = out or out_dir()
    reference = reference or os.path.join(ROOT, "reference")
    staged = os.path.join(out, "reference")
    names = sorted(os.listdir(staged)) if os.path.isdir(staged) else []
    for n in names:
        src, dst = os.path.join(staged, n), os.path.join(reference, n)
        if os.path.isdir(src):   # a study's folder (reference/adaptive/): its files replace those of the same name
            shutil.copytree(src, dst, dirs_exist_ok=True)
        else:
            shutil.copy2(src, dst)
    if os.path.exists(os.path.join(out, "summary.md")):
        shutil.copy2(os.path.join(out, "summary.md"), os.path.join(reference, "summary.md"))
        names.append("summary.md")
    return names


def main(argv=None):
    """``python -m tresca_py.verify.harness publish``: :func:`publish`, then regenerate the README table."""
    from tresca_py.verify import readme
    if (argv if argv is not None else sys.argv[1:]) != ["publish"]:
        print("usage: python -m tresca_py.verify.harness publish")
        return 2
    names = publish()
    print(f"reference/: {len(names)} files from out/verify/reference/" + (f" ({', '.join(names)})" if names else ""))
    return readme.main(["--write"])


if __name__ == "__main__":
    sys.exit(main())
