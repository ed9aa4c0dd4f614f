"""What the studies of ``make verify`` share: running ``tresca-cr study`` into the harness's staged
reference files, the order check, Markdown tables and log-log plots.

Observed orders (``rate_ok``): successive ratios log(e_i/e_{i+1})/log(h_i/h_{i+1}) and a least-squares fit
over all levels (:func:`tresca_py.common.orders`); a requirement on an order holds only if there are at least
four levels and the fit AND the last two successive orders (the asymptotic range) lie in the band.
"""
import csv
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from tresca_py.common import BIN, cmdline, orders, run, short_path  # noqa: E402


def req(hs, rid, statement, passed, measured, command, reference):
    """``hs.require`` with the arguments in the order the studies state them."""
    return hs.require(rid, passed, measured, statement=statement, command=command, reference=reference)


def study(hs, scene, levels, name, reference=None, solver=None, extra=()):
    """Run `tresca-cr study`, keep its CSV as reference/NAME.csv (staged by the harness `hs`), return (rows, command).
    Numbers become floats, empty fields None, text fields (verdicts, size) stay strings."""
    out = hs.path(f"{name}.csv")
    cmd = [BIN, "study", scene, "--levels", ",".join(f"{r}:{n}" for r, n in levels), "--csv", out,
           "--force"]
    if reference:
        cmd += ["--reference", f"{reference[0]}:{reference[1]}"]
    if solver:
        cmd += ["--solver", solver]
    cmd += list(extra)
    p, _ = run(cmd)
    print(p.stdout)
    rows = list(csv.DictReader(open(out)))

    def value(v):
        if v == "":
            return None
        try:
            return float(v)
        except ValueError:
            return v

    for r in rows:
        for k, v in r.items():
            r[k] = value(v)
    return rows, cmdline(cmd).replace(short_path(hs.staged) + "/", "reference/")


def rate_ok(x, e, p, tol):
    succ, fit = orders(x, e)
    ok = len(e) >= 4 and abs(fit - p) <= tol and all(abs(s - p) <= tol for s in succ[-2:])
    return ok, f"fit {fit:.3f}, successive {', '.join(f'{s:.3f}' for s in succ)} ({len(e)} levels)"


def table_md(name, title, rows, cols, xcol="h"):
    """Markdown table with successive orders next to each error column."""
    lines = [f"## {title}", "", "| refine | N | h | k | DOF | " + " | ".join(f"{c} | order" for c in cols) + " |",
             "|" + "---|" * (5 + 2 * len(cols))]
    for i, r in enumerate(rows):
        cells = [
            f"{int(r['refine'])}",
            f"{int(r['steps'])}",
            f"{r['h']:.4e}",
            f"{r['k']:.4e}",
            f"{int(r['paper_dofs'])}",
        ]
        for c in cols:
            v = r[c]
            o = "-"
            if i > 0 and v and rows[i - 1][c]:
                o = f"{math.log(rows[i - 1][c] / v) / math.log(rows[i - 1][xcol] / r[xcol]):.3f}"
            cells += [f"{v:.4e}" if v is not None else "-", o]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def plot(hs, name, title, x, series, xlabel, slopes):
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    for label, e in series:
        ax.loglog(x, e, "o-", label=label)
    for p in slopes:
        e0 = series[0][1][0]
        ax.loglog(x, [e0 * (v / x[0]) ** p for v in x], "k--", lw=0.8, label=f"slope {p}")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("error")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(hs.path(f"{name}.png"), dpi=120)
    plt.close(fig)


# ---------------------------------------------------------------------------------------------------
