"""Rust names and src/ paths in comments and documents must exist (tresca_py.docnames, part of make lint)."""
import os

from tresca_py.common import ROOT
from tresca_py.docnames import check_names


def tree(tmp_path, comment):
    """A small crate: friction/mod.rs (fn classify), solve/{mod,factor}.rs (struct Factor), and one Python
    file and one Rust file carrying ``comment``."""
    files = {
        "Cargo.toml": '[package]\nname = "x"\n[dependencies]\nfaer = "1"\nhdf5-metno = "1"\n',
        "src/lib.rs": "pub mod friction;\npub mod solve;\n",
        "src/friction/mod.rs": "pub fn classify() {}\n",
        "src/solve/mod.rs": "pub mod factor;\npub use factor::Factor;\n",
        "src/solve/factor.rs": "pub struct Factor;\nimpl Factor { pub fn solve_in_place(&self) {} }\n",
        "python/pkg/mod.py": f'"""{comment}"""\n',
        "src/solve/user.rs": f"//! {comment}\nuse contact::classify; // code, not a comment\n",
    }
    for rel, text in files.items():
        p = tmp_path / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    return str(tmp_path)


def refs(root):
    return sorted({(os.path.basename(s.doc), s.ref) for s in check_names(root)})


def test_the_lint_shall_fail_on_a_renamed_module(tmp_path):
    root = tree(tmp_path, "the rule of `contact::classify`")
    assert refs(root) == [("mod.py", "contact::classify"), ("user.rs", "contact::classify")]


def test_the_lint_shall_fail_on_a_removed_item_or_file(tmp_path):
    root = tree(tmp_path, "friction::decide, solve::factor::Cholesky and src/factor.rs")
    assert {r for _, r in refs(root)} == {"friction::decide", "solve::factor::Cholesky", "src/factor.rs"}


def test_the_lint_shall_accept_existing_names_reexports_and_other_crates(tmp_path):
    root = tree(tmp_path, "friction::classify, solve::factor::Factor::solve_in_place, solve::Factor, "
                          "crate::friction, src/solve/{mod,factor}.rs, faer::Mat, hdf5_metno::File, "
                          "std::mem::take, f64::signum, Factor::solve_in_place, a::b")
    assert refs(root) == []


def test_the_repository_shall_name_no_stale_rust_name():
    assert [str(s) for s in check_names(ROOT)] == []
