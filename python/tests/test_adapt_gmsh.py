"""The independent re-implementations (scikit-fem and dolfinx) accept an adapted mesh through the Gmsh file
`tresca-cr adapt --out DIR --gmsh` writes, and agree with the Rust solver on it to <= 1e-8 (the cross-check's
bar; measured 1.1e-12 and 2.9e-13 on level 6 of the L-shape, tresca_py.verify.adapted_reimpl)."""
import os

import pytest

from tresca_py.common import BIN, case, run
from tresca_py.verify import adapted_reimpl


def test_reimplementations_agree_with_rust_on_an_adapted_gmsh_mesh(tmp_path):
    """The system shall write each adapted level's mesh as Gmsh, and scikit-fem and dolfinx shall solve the
    scene on it and agree with the Rust solver (and the adapt run's own level file) to <= 1e-8."""
    if not os.path.exists(BIN):
        pytest.skip("target/release/tresca-cr is not built (cargo build --release)")
    d = str(tmp_path / "levels")
    run([BIN, "adapt", case("lshape_adapt"), "--levels", "5", "--out", d, "--gmsh"])
    assert adapted_reimpl.level_count(d) == 5
    triangles = [adapted_reimpl.gmsh_matches_level(d, k) for k in range(5)]
    assert triangles == sorted(triangles) and triangles[-1] > triangles[0], "the levels are refined"
    pairs = adapted_reimpl.agreement(case("lshape_adapt"), d, 4)
    assert set(pairs) == {"rust-skfem", "rust-dolfinx", "adapt-rust"}
    for name, cmp in pairs.items():
        assert adapted_reimpl.worst(cmp) <= 1e-8 and cmp["flags"] == 0, (name, cmp["du"], cmp["dsig"])


def test_a_gmsh_file_of_another_level_is_refused(tmp_path):
    """The system shall name the level whose Gmsh file does not hold its results file's mesh."""
    if not os.path.exists(BIN):
        pytest.skip("target/release/tresca-cr is not built (cargo build --release)")
    d = tmp_path / "levels"
    run([BIN, "adapt", case("lshape_adapt"), "--levels", "2", "--out", str(d), "--gmsh"])
    os.replace(d / "level_0.msh", d / "level_1.msh")
    with pytest.raises(ValueError, match="level 1"):
        adapted_reimpl.gmsh_matches_level(str(d), 1)
