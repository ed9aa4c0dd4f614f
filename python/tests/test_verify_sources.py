"""The verification reads the CLI's --json summary or the results file, never its printed messages, and keeps
no module-level mutable state."""
import ast
import glob
import os

import pytest

from tresca_py.common import ROOT

SOURCES = sorted(glob.glob(os.path.join(ROOT, "verification", "*.py"))
                 + glob.glob(os.path.join(ROOT, "python", "tresca_py", "verify", "*.py")))


def names(node):
    return {n.attr for n in ast.walk(node) if isinstance(n, ast.Attribute)} | \
        {n.id for n in ast.walk(node) if isinstance(n, ast.Name)}


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: os.path.relpath(p, ROOT))
def test_no_regex_over_printed_output(path):
    """The system shall not match regular expressions against a process's standard output."""
    tree = ast.parse(open(path, encoding="utf-8").read())
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Attribute)
            and isinstance(node.func.value, ast.Name)
            and node.func.value.id == "re"
            and any("stdout" in names(a) for a in node.args)
        ):
            pytest.fail(f"{os.path.relpath(path, ROOT)}:{node.lineno}: re.{node.func.attr} over stdout")


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: os.path.relpath(p, ROOT))
def test_no_module_level_mutable_state(path):
    """The system shall keep no mutable list, dict or set bound at module level and run no process at import
    (constants are tuples, strings, numbers or frozen tables written in capitals)."""
    tree = ast.parse(open(path, encoding="utf-8").read())
    for node in tree.body:
        if isinstance(node, ast.Assign):
            targets = [t.id for t in node.targets if isinstance(t, ast.Name)]
            value = node.value
            if isinstance(value, ast.Call) and "subprocess" in names(value.func):
                pytest.fail(f"{os.path.relpath(path, ROOT)}:{node.lineno}: runs a process at import")
            empty = isinstance(value, (ast.List, ast.Dict, ast.Set)) and not (
                getattr(value, "elts", None) or getattr(value, "keys", None))
            if empty:
                pytest.fail(f"{os.path.relpath(path, ROOT)}:{node.lineno}: {targets} is an empty mutable container "
                            "at module level (state)")
            if any(not t.isupper() for t in targets) and isinstance(value, (ast.List, ast.Dict, ast.Set)):
                pytest.fail(f"{os.path.relpath(path, ROOT)}:{node.lineno}: {targets}: module-level container")
