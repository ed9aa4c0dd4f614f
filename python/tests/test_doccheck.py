"""The system shall report every path the documentation names that does not exist, and no other."""

import os

from tresca_py.doccheck import check, expand_braces


def _tree(tmp_path, doc_text):
    (tmp_path / "src" / "solve").mkdir(parents=True)
    (tmp_path / "src" / "solve" / "factor.rs").write_text("")
    (tmp_path / "src" / "solve" / "free.rs").write_text("")
    (tmp_path / "verification").mkdir()
    (tmp_path / "verification" / "run_all.py").write_text("")
    (tmp_path / "README.md").write_text(doc_text)
    return str(tmp_path)


def test_existing_references_pass(tmp_path):
    root = _tree(
        tmp_path,
        "See `src/solve/factor.rs:12-20`, `solve/{factor,free}.rs`, verification/run_all.py and "
        "`src/solve/*.rs`.\nHDF5 `tresca/steps/checksum`, outputs `out/x.md`, `reference/<name>.md`.\n",
    )
    assert check(root) == []


def test_missing_references_are_named_with_their_line(tmp_path):
    root = _tree(tmp_path, "ok `src/solve/factor.rs`\n`src/expr.rs` and `solve/{factor,gone}.rs`\n")
    missing = check(root)
    assert [(m.doc, m.line, m.ref) for m in missing] == [
        ("README.md", 2, "src/expr.rs"),
        ("README.md", 2, "solve/gone.rs"),
    ]
    assert str(missing[0]) == "README.md:2: `src/expr.rs` does not exist"


def test_docs_folder_is_checked(tmp_path):
    root = _tree(tmp_path, "")
    os.mkdir(os.path.join(root, "docs"))
    with open(os.path.join(root, "docs", "scene.md"), "w") as f:
        f.write("`verification/nothing.py`\n")
    assert [m.ref for m in check(root)] == ["verification/nothing.py"]


def test_brace_expansion():
    assert expand_braces("a/{b,c}/{d,e}.rs") == ["a/b/d.rs", "a/b/e.rs", "a/c/d.rs", "a/c/e.rs"]
