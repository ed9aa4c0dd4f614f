"""Every Rust name and `src/…rs` path that a comment or a document names exists (part of `make lint`, through
verification/check_doc_paths.py).

Scanned: the Python files of python/, scripts/ and verification/ (all their text: comments and docstrings;
not python/tests/, whose fixtures name made-up modules on purpose),
the comments (`//`, `//!`, `///`) of the Rust files of src/, tests/, examples/ and benches/, and the
documents of :func:`tresca_py.doccheck.default_docs`. CHANGELOG.md (history) and reference/ (generated) are
not scanned.

* A path `src/…/x.rs` (shell braces expanded) exists as a file.
* A name `a::b::…` whose first part is snake_case names one of our modules: `a` is a module file
  `src/…/a.rs` or `src/…/a/mod.rs` (or `crate`/`tresca_cr`: the crate root). Each following part is
  either a submodule of it (`a/b.rs`, `a/b/mod.rs`, or `mod b` inside its file) or an item its file
  defines or re-exports (`fn b`, `struct b`, `enum`, `trait`, `type`, `const`, `static`, `macro_rules! b`,
  `pub use …b`); the parts after an item (methods, variants) are not followed.
* Not ours, so not checked: placeholders (a part of one letter: `a::b`), CamelCase first parts (types:
  `Factor::solve_in_place`), primitive types
  (`f64::signum`), `std`/`core`/`alloc`, and the crates of Cargo.toml (`faer::`, `hdf5::`, `exmex::`, …).
"""
from __future__ import annotations

import glob
import os
import re
import tomllib
from dataclasses import dataclass

from tresca_py.doccheck import Missing, default_docs, expand_braces

_NAME = re.compile(r"(?<![\w:])((?:[A-Za-z_]\w*::)+[A-Za-z_]\w*)")
_SRC_PATH = re.compile(r"(?<![\w./-])(src/[\w./{},-]*\.rs)\b")
_PRIMITIVES = {"f32", "f64", "i8", "i16", "i32", "i64", "i128", "isize", "u8", "u16", "u32", "u64", "u128",
               "usize", "bool", "char", "str"}
_EXTERNAL = {"std", "core", "alloc", "self", "super", "Self"}
_ITEM = r"(?:fn|struct|enum|trait|type|const|static|mod|macro_rules!|union)\s+{}\b"


@dataclass(frozen=True)
class Stale(Missing):
    """A Rust name or source path in `doc` at `line` that names nothing in src/."""

    def __str__(self) -> str:
        return f"{self.doc}:{self.line}: `{self.ref}` names no module, item or file of src/"


def crates(root: str) -> set[str]:
    """The external crates of Cargo.toml (dependencies of every kind), as Rust spells them."""
    path = os.path.join(root, "Cargo.toml")
    if not os.path.isfile(path):
        return set()
    with open(path, "rb") as fh:
        doc = tomllib.load(fh)
    names = set()
    for key in ("dependencies", "dev-dependencies", "build-dependencies"):
        names |= {n.replace("-", "_") for n in doc.get(key, {})}
    return names


def scanned_files(root: str) -> list[tuple[str, str]]:
    """(path, kind) of every file scanned; kind "py", "rs" (comments only) or "md"."""
    out = []
    for d in ("python", "scripts", "verification"):
        out += [(p, "py") for p in sorted(glob.glob(os.path.join(root, d, "**", "*.py"), recursive=True))
                if os.sep + "tests" + os.sep not in p]
    for d in ("src", "tests", "examples", "benches"):
        out += [(p, "rs") for p in sorted(glob.glob(os.path.join(root, d, "**", "*.rs"), recursive=True))]
    return out + [(p, "md") for p in default_docs(root)]


def comment_lines(text: str, kind: str) -> list[tuple[int, str]]:
    """(line number, text scanned) of a file: a Rust file's comments, every line of the others."""
    lines = text.splitlines()
    if kind != "rs":
        return list(enumerate(lines, 1))
    return [(i, line[line.index("//"):]) for i, line in enumerate(lines, 1) if "//" in line]


class Modules:
    """The module tree of src/: module name -> the (file, directory of its submodules) pairs."""

    def __init__(self, root: str):
        self.src = os.path.join(root, "src")
        self.by_name: dict[str, list[tuple[str, str]]] = {}
        for p in glob.glob(os.path.join(self.src, "**", "*.rs"), recursive=True):
            name, d = os.path.splitext(os.path.basename(p))[0], os.path.dirname(p)
            if name == "mod":
                self.by_name.setdefault(os.path.basename(d), []).append((p, d))
            elif name not in ("lib", "main"):
                self.by_name.setdefault(name, []).append((p, os.path.join(d, name)))
        roots = [os.path.join(self.src, f) for f in ("lib.rs", "main.rs")]
        self.root = [(p, self.src) for p in roots if os.path.isfile(p)]
        self._text: dict[str, str] = {}

    def text(self, path: str) -> str:
        if path not in self._text:
            with open(path, encoding="utf-8") as fh:
                self._text[path] = fh.read()
        return self._text[path]

    def submodule(self, d: str, name: str) -> list[tuple[str, str]]:
        for p in (os.path.join(d, name + ".rs"), os.path.join(d, name, "mod.rs")):
            if os.path.isfile(p):
                return [(p, os.path.join(d, name))]
        return []

    def defines(self, path: str, name: str) -> bool:
        text = self.text(path)
        if re.search(_ITEM.format(re.escape(name)), text):
            return True
        return any(re.search(rf"\b{re.escape(name)}\b", u) for u in re.findall(r"pub(?:\([^)]*\))? use [^;]*;", text))

    def resolves(self, parts: list[str], candidates: list[tuple[str, str]]) -> bool:
        """True if some candidate module resolves the rest of the path ``parts``."""
        if not parts:
            return bool(candidates)
        for path, d in candidates:
            sub = self.submodule(d, parts[0])
            if sub:
                if self.resolves(parts[1:], sub):
                    return True
            elif self.defines(path, parts[0]):
                return True
        return False


def ours(first: str, external: set[str]) -> bool:
    """True if a name starting with ``first`` is one of this crate's module paths (see the module's doc)."""
    return first[:1].islower() and first not in _PRIMITIVES | _EXTERNAL | external


def check_names(root: str, files: list[tuple[str, str]] | None = None) -> list[Stale]:
    """Every stale Rust name and src/ path of ``files`` (default :func:`scanned_files`)."""
    mods, external = Modules(root), crates(root)
    out = []
    for path, kind in files if files is not None else scanned_files(root):
        with open(path, encoding="utf-8") as fh:
            text = fh.read()
        rel = os.path.relpath(path, root)
        for lineno, line in comment_lines(text, kind):
            for m in _SRC_PATH.finditer(line):
                out += [Stale(rel, lineno, p) for p in expand_braces(m.group(1))
                        if not glob.glob(os.path.join(root, p))]
            for m in _NAME.finditer(line):
                parts = m.group(1).split("::")
                if not ours(parts[0], external) or any(len(p) == 1 for p in parts):
                    continue
                first = mods.root if parts[0] in ("crate", "tresca_cr") else mods.by_name.get(parts[0], [])
                if not mods.resolves(parts[1:], first):
                    out.append(Stale(rel, lineno, m.group(1)))
    return out
