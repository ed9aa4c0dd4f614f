"""Every path the documentation names exists: README.md, docs/*.md and the README.md files under verification/.

A reference is any token with a slash whose first part is a tracked top-level entry of the repository
(`src/`, `verification/`, `reference/`, …) or a folder of `src/` (the README's concept table writes
`solve/factor.rs` for `src/solve/cholesky/factor.rs`). It resolves against the repository root, then `src/`.
Shell braces are expanded (`friction/{ssn,uzawa}.rs`), globs must match at least one file, and a
`:line` or `:line-line` suffix is dropped. Tokens with a placeholder (`<name>`, `…`, `...`) are passed
over, as are HDF5 paths (`tresca/steps/checksum`) and outputs (`out/…`), whose first part is not a
folder of the repository.
"""

from __future__ import annotations

import glob
import os
import re
from dataclasses import dataclass

# a token with at least one slash: word characters, dots, dashes, globs and shell braces
_TOKEN = re.compile(r"(?<![\w./<{-])((?:[\w.*{},-]+/)+[\w.*{},-]*)")
_LINE_SUFFIX = re.compile(r":\d+(?:-\d+)?$")
_BRACES = re.compile(r"\{([^{}]*)\}")


@dataclass(frozen=True)
class Missing:
    """A reference in `doc` at `line` that names no file or folder."""

    doc: str
    line: int
    ref: str

    def __str__(self) -> str:
        return f"{self.doc}:{self.line}: `{self.ref}` does not exist"


def default_docs(root: str) -> list[str]:
    """The documents checked: README.md, every docs/*.md and every README.md under verification/."""
    docs = [os.path.join(root, "README.md")]
    docs += sorted(glob.glob(os.path.join(root, "docs", "*.md")))
    docs += sorted(glob.glob(os.path.join(root, "verification", "**", "README.md"), recursive=True))
    return [d for d in docs if os.path.isfile(d)]


def expand_braces(ref: str) -> list[str]:
    """`a/{b,c}.rs` → [`a/b.rs`, `a/c.rs`] (nested groups too)."""
    m = _BRACES.search(ref)
    if not m:
        return [ref]
    out = []
    for alt in m.group(1).split(","):
        out += expand_braces(ref[: m.start()] + alt + ref[m.end():])
    return out


def _roots(root: str) -> tuple[set[str], set[str]]:
    top = {e for e in os.listdir(root) if e not in {".git", "target", ".venv", "out"}}
    src = os.path.join(root, "src")
    sub = {e for e in os.listdir(src) if os.path.isdir(os.path.join(src, e))} if os.path.isdir(src) else set()
    return top, sub


def _exists(root: str, ref: str) -> bool:
    for base in (root, os.path.join(root, "src")):
        p = os.path.join(base, ref)
        if any(c in ref for c in "*?["):
            if glob.glob(p):
                return True
        elif os.path.exists(p):
            return True
    return False


def references(text: str, root: str) -> list[tuple[int, str]]:
    """The (line, reference) pairs of `text` that the check applies to (see the module's doc)."""
    top, sub = _roots(root)
    out = []
    for lineno, line in enumerate(text.splitlines(), 1):
        for m in _TOKEN.finditer(line):
            ref = _LINE_SUFFIX.sub("", m.group(1).rstrip(".,;:"))
            if "<" in ref or "…" in ref or "..." in ref:
                continue
            first = ref.split("/", 1)[0]
            if first in top or first in sub:
                out.append((lineno, ref))
    return out


def check(root: str, docs: list[str] | None = None) -> list[Missing]:
    """Every reference of `docs` (default: [`default_docs`]) that does not exist under `root`."""
    missing = []
    for doc in docs if docs is not None else default_docs(root):
        with open(doc, encoding="utf-8") as f:
            text = f.read()
        rel = os.path.relpath(doc, root)
        for lineno, ref in references(text, root):
            for one in expand_braces(ref):
                if not _exists(root, one):
                    missing.append(Missing(rel, lineno, one))
    return missing
