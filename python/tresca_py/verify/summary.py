"""The CLI's machine-readable summary (``tresca-cr run|study|plan|check ... --json FILE``; the schema is
documented field by field in src/cli/summary.rs). The verification reads it, never the human messages.
"""
import json
import os
import subprocess
import tempfile

from tresca_py.common import ROOT, cmdline

SCHEMA = 1
# the set-up phases in the order of a results file's `setup_times` (src/stepping/mod.rs SetupTimes::as_array)
PHASES = ("space", "assembly", "factorisation", "superposition", "condensation")


def load(path):
    """The summary at ``path`` (checked: its schema version is the one this reader knows)."""
    with open(path, encoding="utf-8") as f:
        s = json.load(f)
    if s.get("schema") != SCHEMA:
        raise ValueError(f"{path}: summary schema {s.get('schema')!r}, this reader knows {SCHEMA}")
    return s


def run(cmd, check=True, env=None):
    """Run a ``tresca-cr`` command with ``--json`` into a temporary file; returns (summary or None,
    completed process). ``check``: a non-zero exit raises RuntimeError with the command and its stderr (a
    plan's refusal, exit 3, is not an error). The summary is None when the command wrote none (an input
    refused before any work)."""
    fd, path = tempfile.mkstemp(prefix="tresca-summary-", suffix=".json")
    os.close(fd)
    os.remove(path)
    try:
        p = subprocess.run([str(c) for c in cmd] + ["--json", path], cwd=ROOT, capture_output=True, text=True,
                           env=env)
        if check and p.returncode not in (0, 3):
            raise RuntimeError(f"{cmdline(cmd)} failed ({p.returncode}):\n{p.stderr}")
        s = load(path) if os.path.exists(path) else None
        return s, p
    finally:
        if os.path.exists(path):
            os.remove(path)


def setup_times(s):
    """A run's or check's set-up phases as a list in the results file's order (:data:`PHASES`)."""
    part = s["run"] or s["check"]
    return [part["setup"][k] for k in PHASES]


def max_errors(s):
    """A run's true errors, max over the time nodes, as (energy, H1, L2); None without ``[exact]``."""
    e = s["run"]["max_errors"]
    return None if e is None else (e["energy"], e["h1"], e["l2"])
