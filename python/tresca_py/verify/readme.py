"""verification/README.md's requirement table, generated from :data:`tresca_py.verify.requirements.REQUIREMENTS`.

The table sits between the markers ``<!-- requirements:begin -->`` and ``<!-- requirements:end -->``;
``make reference`` rewrites it (``python -m tresca_py.verify.readme --write``) and a pytest test checks that
the committed README holds exactly the generated table.
"""
import argparse
import os
import sys

from tresca_py.common import ROOT
from tresca_py.verify.requirements import REQUIREMENTS

README = os.path.join(ROOT, "verification", "README.md")
BEGIN, END = "<!-- requirements:begin -->", "<!-- requirements:end -->"


def command_cell(command):
    """A shell command in backticks; prose ("as P2") as it is."""
    return command if command.startswith("as ") else f"`{command}`"


def table(requirements=REQUIREMENTS):
    """The Markdown table: id, statement, command, reference file."""
    lines = ["| id | requirement (the solver shall …) | command | reference file |", "|---|---|---|---|"]
    for r in requirements:
        ref = f"`{r.reference}`" if r.reference else "—"
        lines.append(f"| {r.id} | {r.statement} | {command_cell(r.command)} | {ref} |")
    return "\n".join(lines) + "\n"


def with_table(text, requirements=REQUIREMENTS):
    """``text`` (the README) with the part between the markers replaced by the generated table."""
    if BEGIN not in text or END not in text:
        raise ValueError(f"the README lacks the markers {BEGIN} and {END}")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    return f"{head}{BEGIN}\n{table(requirements)}{END}{tail}"


def main(argv=None):
    ap = argparse.ArgumentParser(description="generate verification/README.md's requirement table")
    ap.add_argument("--write", action="store_true", help="rewrite the README (default: exit 1 when it is stale)")
    args = ap.parse_args(argv)
    text = open(README, encoding="utf-8").read()
    new = with_table(text)
    if args.write:
        if new != text:
            open(README, "w", encoding="utf-8").write(new)
        print(f"{os.path.relpath(README, ROOT)}: requirement table {'updated' if new != text else 'current'}")
        return 0
    if new != text:
        print(f"{os.path.relpath(README, ROOT)}: the requirement table is stale (make reference)")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
