"""The independent re-implementation (scripts/skfem_solve.py) accepts an adapted mesh through the Gmsh
file `tresca-cr adapt --out DIR --gmsh` writes, and agrees with the Rust solver on it to <= 1e-8
(scripts/compare.py's tolerance for the cross-checks; measured 1.3e-13 on level 5)."""
import os
import subprocess
import sys

import pytest

from tresca_py.common import BIN, SCRIPTS, case


def test_skfem_agrees_with_rust_on_an_adapted_gmsh_mesh(tmp_path):
    if not os.path.exists(BIN):
        pytest.skip("target/release/tresca-cr is not built (cargo build --release)")
    scene = case("lshape_adapt")
    d = tmp_path / "levels"
    subprocess.run([BIN, "adapt", scene, "--levels", "5", "--out", str(d), "--gmsh"], check=True,
                   capture_output=True)
    with open(scene) as f:
        text = f.read().replace('file = "lshape.msh"', f'file = "{d / "level_4.msh"}"')
    adapted = tmp_path / "adapted.toml"
    adapted.write_text(text)
    rust, skfem = str(tmp_path / "rust.h5"), str(tmp_path / "skfem.h5")
    subprocess.run([BIN, "run", str(adapted), "-q", "-o", rust], check=True, capture_output=True)
    subprocess.run([sys.executable, os.path.join(SCRIPTS, "skfem_solve.py"), str(adapted), "-o", skfem],
                   check=True, capture_output=True)
    cmp = subprocess.run([sys.executable, os.path.join(SCRIPTS, "compare.py"), rust, skfem, "--tol", "1e-8"],
                         capture_output=True, text=True)
    assert cmp.returncode == 0 and "PASS" in cmp.stdout, cmp.stdout + cmp.stderr
    # the level's own results file (same mesh, vertices labelled for bisection) agrees with the run too
    cmp = subprocess.run([sys.executable, os.path.join(SCRIPTS, "compare.py"), str(d / "level_4.h5"), rust,
                          "--tol", "1e-8"], capture_output=True, text=True)
    assert cmp.returncode == 0 and "PASS" in cmp.stdout, cmp.stdout + cmp.stderr
