"""T1 finds every Rust test binary that holds study-sized tests, wherever the test file sits under tests/."""
import pytest

from tresca_py.verify.study_tests import binary_of, rust_binaries

STUDY = '#[test]\n#[ignore = "study-sized: long"]\nfn slow() {}\n'


def tree(root, files):
    for rel, text in files.items():
        p = root / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text, encoding="utf-8")
    return str(root)


def test_files_map_to_their_binaries():
    """The system shall attribute tests/NAME.rs, tests/NAME/main.rs and the modules beside them to the binary
    NAME, and tests/common/ to none."""
    assert binary_of("tests/cli.rs") == "cli"
    assert binary_of("tests/library/main.rs") == "library"
    assert binary_of("tests/library/unilateral.rs") == "library"
    assert binary_of("tests/hostile/budget.rs") == "hostile"
    assert binary_of("tests/common/mod.rs") is None


def test_study_sized_tests_are_found_in_any_binary(tmp_path):
    """The system shall run the study-sized tests of a gathered binary's module and of a plain test file, and
    no binary without them."""
    root = tree(tmp_path, {"tests/library/main.rs": "mod a;\n", "tests/library/a.rs": STUDY,
                           "tests/cli.rs": STUDY, "tests/plain.rs": "#[test]\nfn quick() {}\n",
                           "tests/common/mod.rs": STUDY})
    assert rust_binaries(root) == ["cli", "library"]


@pytest.mark.parametrize("other", ["#[ignore]", '#[ignore = "timing: prints only"]'])
def test_a_binary_with_other_ignored_tests_is_refused(tmp_path, other):
    """The system shall refuse a binary holding study-sized tests beside other ignored ones, which
    `--ignored` would run too."""
    root = tree(tmp_path, {"tests/output.rs": STUDY + f"#[test]\n{other}\nfn timing() {{}}\n"})
    with pytest.raises(ValueError, match="output"):
        rust_binaries(root)


def test_the_tree_has_its_study_sized_binaries():
    """The system shall find the study-sized tests of this repository (tests/expr_exactness.rs holds some)."""
    assert "expr_exactness" in rust_binaries()
