"""The import-graph check (scripts/import_graph.py, part of `make lint`)."""

from tresca_py.imports import _expand, build


def _tree(tmp_path, files):
    for rel, code in files.items():
        p = tmp_path / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(code)
    return build(str(tmp_path))


def test_finds_a_circle_between_siblings(tmp_path):
    """The system shall report two sibling files that import each other as a circle."""
    g = _tree(tmp_path, {
        "lib.rs": "pub mod fem;",
        "fem/mod.rs": "pub mod space; pub mod lifting;",
        "fem/space.rs": "use super::lifting::BoundaryData;\npub struct CrSpace;",
        "fem/lifting.rs": "use crate::fem::space::CrSpace;\npub struct BoundaryData;",
    })
    assert g.circles() == [["fem/lifting.rs", "fem/space.rs"]]


def test_one_way_imports_and_test_modules_are_not_circles(tmp_path):
    """The system shall not count one-way imports, comments, strings or inline test modules as a circle."""
    g = _tree(tmp_path, {
        "lib.rs": "pub mod fem;",
        "fem/mod.rs": "pub mod space; pub mod lifting;",
        "fem/space.rs": '// crate::fem::lifting\nconst S: &str = "crate::fem::lifting";\n'
                        "#[cfg(test)]\nmod tests { use crate::fem::lifting::X; fn f() { {} } }",
        "fem/lifting.rs": "use crate::fem::space::CrSpace;",
    })
    assert g.circles() == []
    assert g.edges["fem/lifting.rs"] == {"fem/space.rs"}


def test_upward_import_to_the_crate_root(tmp_path):
    """The system shall report a path that names an item of the crate root from a module below it."""
    g = _tree(tmp_path, {"lib.rs": "pub mod scene;", "scene/mod.rs": "crate::named_enum!(A);"})
    assert g.upward == [("scene/mod.rs", "crate::named_enum")]


def test_use_trees_expand():
    """The system shall expand nested `use` trees, `self` and renames."""
    assert _expand("crate::a::{b::{self, c as d}, e}") == ["crate::a::b", "crate::a::b::c", "crate::a::e"]
