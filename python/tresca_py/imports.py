"""The Rust crate's import graph: which file of `src/` uses which, its circles and its upward imports.

A file's module path follows from its place (`src/solve/free.rs` is `solve::free`, `src/fem/mod.rs` is `fem`,
`src/lib.rs` and `src/main.rs` are the root). Its imports are every `crate::…` and `super::…` path in its code
(comments and strings removed; `use` trees with braces expanded), each resolved to the deepest module that
exists. An edge a → b is kept when b is neither a nor the crate root (`lib.rs`). Two findings:

* **circles**: the strongly connected components of more than one file (Tarjan's algorithm);
* **upward imports**: a path that resolves to the crate root itself (`crate::<macro>!`, `crate::<Type>`
  re-exported by `lib.rs`), from any file other than `lib.rs` and `main.rs`.

A folder's `mod.rs` declares its children (`mod sub;` is not an edge; neither are its `pub use sub::…`
re-exports, which name no `crate::`/`super::` path), while a child that imports its own folder's `mod.rs`
(`use super::*`) is an ordinary edge.

>>> _expand("crate::{a::{b, c}, d}")
['crate::a::b', 'crate::a::c', 'crate::d']
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field

_COMMENT = re.compile(r"//[^\n]*|/\*.*?\*/", re.S)
_STRING = re.compile(r'r#*"(?:.|\n)*?"#*|"(?:\\.|[^"\\])*"')
_USE = re.compile(r"\buse\s+((?:crate|super|self)(?:::[^;]*)?);", re.S)
_PATH = re.compile(r"\b((?:crate|super)(?:::\w+)+)(!?)")


_TEST_MOD = re.compile(r"#\[cfg\(test\)\]\s*mod\s+\w+\s*\{")


def _strip_tests(code: str) -> str:
    """Remove inline `#[cfg(test)] mod … { … }` blocks (their `super` is the file's own module)."""
    while m := _TEST_MOD.search(code):
        depth, j = 1, m.end()
        while depth and j < len(code):
            depth += {"{": 1, "}": -1}.get(code[j], 0)
            j += 1
        code = code[: m.start()] + code[j:]
    return code


def _expand(tree: str) -> list[str]:
    """`a::{b, c::{d}}` → [`a::b`, `a::c::d`]; `as` renames and `self` are resolved."""
    tree = re.sub(r"\s+", "", tree)
    if "{" not in tree:
        tree = re.sub(r"as\w+$", "", tree.replace(" as ", "as"))
        return [tree[:-6] if tree.endswith("::self") else tree]
    i = tree.index("{")
    head, body = tree[:i], tree[i + 1:-1]
    parts, depth, start = [], 0, 0
    for j, ch in enumerate(body + ","):
        if ch == "{":
            depth += 1
        elif ch == "}":
            depth -= 1
        elif ch == "," and depth == 0:
            if body[start:j]:
                parts.append(body[start:j])
            start = j + 1
    out = []
    for p in parts:
        out += _expand(head + p)
    return out


def module_of(rel: str) -> tuple[str, ...]:
    """Module path of a file relative to `src/`: `fem/mod.rs` → ('fem',), `lib.rs` → ()."""
    parts = rel[:-3].split("/")
    if parts[-1] == "mod" or parts == ["lib"] or parts == ["main"]:
        parts = parts[:-1]
    return tuple(parts)


@dataclass
class Graph:
    """Files of `src/` by module path, and their resolved imports."""

    files: dict[tuple[str, ...], str] = field(default_factory=dict)
    edges: dict[str, set[str]] = field(default_factory=dict)
    upward: list[tuple[str, str]] = field(default_factory=list)

    def circles(self) -> list[list[str]]:
        """The strongly connected components with more than one file, each sorted."""
        index, low, stack, on, out = {}, {}, [], set(), []

        def visit(v: str) -> None:
            index[v] = low[v] = len(index)
            stack.append(v)
            on.add(v)
            for w in sorted(self.edges.get(v, ())):
                if w not in index:
                    visit(w)
                    low[v] = min(low[v], low[w])
                elif w in on:
                    low[v] = min(low[v], index[w])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))

        for v in sorted(self.edges):
            if v not in index:
                visit(v)
        return sorted(out)


def _resolve(path: str, here: tuple[str, ...], files: dict) -> tuple[tuple[str, ...], bool]:
    """The deepest existing module a path names, and whether it named an item of the crate root."""
    parts = path.split("::")
    if parts[0] == "crate":
        base, rest = (), parts[1:]
    else:
        base, rest = here, parts
        while rest and rest[0] == "super":
            base, rest = base[:-1], rest[1:]
    mod = base
    for p in rest:
        if mod + (p,) in files:
            mod = mod + (p,)
        else:
            break
    return mod, (mod == () and bool(rest))


def build(src: str) -> Graph:
    """Read every `.rs` file under `src` and resolve its `crate::`/`super::` paths."""
    g = Graph()
    for dirpath, _, names in os.walk(src):
        for n in names:
            if n.endswith(".rs"):
                rel = os.path.relpath(os.path.join(dirpath, n), src).replace(os.sep, "/")
                g.files[module_of(rel)] = rel
    for mod, rel in sorted(g.files.items()):
        with open(os.path.join(src, rel), encoding="utf-8") as f:
            code = _strip_tests(_STRING.sub('""', _COMMENT.sub("", f.read())))
        paths = [p for u in _USE.findall(code) for p in _expand(u)]
        paths += [m.group(1) for m in _PATH.finditer(code)]
        g.edges.setdefault(rel, set())
        for p in paths:
            if rel == "main.rs" and p.startswith("crate"):
                continue  # the binary's own crate root is main.rs, not the library
            target, root_item = _resolve(p, mod, g.files)
            if root_item and rel not in ("lib.rs", "main.rs"):
                g.upward.append((rel, p))
            t = g.files.get(target)
            if t is None or t == rel or target == ():
                continue  # itself, or the crate root
            g.edges[rel].add(t)
    g.upward = sorted(set(g.upward))
    return g


def report(g: Graph) -> str:
    """Circles and upward imports as text, one finding a line."""
    lines = [f"files: {len(g.files)}, import edges: {sum(len(e) for e in g.edges.values())}"]
    circles = g.circles()
    lines.append(f"circles: {len(circles)}")
    lines += ["  " + " ↔ ".join(c) for c in circles]
    lines.append(f"upward imports (to the crate root): {len(g.upward)}")
    lines += [f"  {a}: {p}" for a, p in g.upward]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Command line of scripts/import_graph.py."""
    import argparse

    ap = argparse.ArgumentParser(description="circles and upward imports of the Rust crate")
    ap.add_argument("--src", default=os.path.join(os.path.dirname(__file__), "..", "..", "src"))
    ap.add_argument("--check", action="store_true", help="exit 1 when there is a circle or an upward import")
    args = ap.parse_args(argv)
    g = build(os.path.normpath(args.src))
    print(report(g))
    return 1 if args.check and (g.circles() or g.upward) else 0
