"""tresca_py.adapt_plot: the figures of `tresca-cr adapt` from its CSV tables, and one error line (exit 2)
for a directory without level files or a CSV without an error column."""
import os

from tresca_py import adapt_plot

HEAD = "level,unknowns,estimator,error,vs_next,vs_reference\n"


def _csv(path, rows):
    with open(path, "w") as f:
        f.write(HEAD + "".join(rows))
    return str(path)


def test_rates_picture_is_written(tmp_path):
    a = _csv(tmp_path / "a.csv", ["0,10,1.0,,0.3,0.4\n", "1,40,0.5,,0.15,0.2\n", "2,160,0.25,,,0.1\n"])
    u = _csv(tmp_path / "u.csv", ["0,10,1.0,,0.3,0.4\n", "1,40,0.6,,,0.25\n"])
    out = tmp_path / "r.png"
    assert adapt_plot.main(["rates", a, u, "-o", str(out)]) == 0
    assert os.path.getsize(out) > 1000


def test_bad_inputs_give_one_error_line(tmp_path, capsys):
    assert adapt_plot.main(["meshes", str(tmp_path), "-o", str(tmp_path / "o")]) == 2
    assert "no level_<k>.h5 files" in capsys.readouterr().err
    a = _csv(tmp_path / "a.csv", ["0,10,1.0,,,\n"])
    assert adapt_plot.main(["rates", a, a, "-o", str(tmp_path / "r.png")]) == 2
    assert "no error column" in capsys.readouterr().err
