"""The Python Richardson limits (tresca_py.external.richardson) use tresca-cr's constants: the tolerance of
the fourth-level check and Roache's safety factors are read from src/study/richardson.rs and must be equal."""
import os
import re

from tresca_py.common import ROOT
from tresca_py.external import richardson

RUST = os.path.join(ROOT, "src", "study", "richardson.rs")


def rust_const(name):
    """The value of `pub const NAME: f64 = VALUE;` in src/study/richardson.rs."""
    with open(RUST, encoding="utf-8") as fh:
        m = re.search(rf"^pub const {name}: f64 = ([0-9.eE+-]+);", fh.read(), re.M)
    assert m, f"{RUST}: no `pub const {name}: f64`"
    return float(m.group(1))


def test_the_python_richardson_check_shall_use_the_rust_constants():
    for name in ("RATIO_TOL", "FS_THREE", "FS_TWO"):
        assert getattr(richardson, name) == rust_const(name), name


def test_the_constant_reader_shall_fail_on_a_missing_constant():
    try:
        rust_const("NO_SUCH_CONSTANT")
    except AssertionError:
        return
    raise AssertionError("a missing constant was not reported")
