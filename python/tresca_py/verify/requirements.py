"""The requirements of `make verify`, declared once: id, statement, command and reference file.

The rows are kept by concern, in table order: :mod:`tresca_py.verify.requirements_orders` (the
discretisation's orders and same-scheme agreement), :mod:`tresca_py.verify.requirements_estimates` (the
paper's example, error estimates, adaptivity) and :mod:`tresca_py.verify.requirements_tools` (files,
cross-checks, planner, stability, the suite itself); a row is :class:`tresca_py.verify.requirement.Requirement`.

``verification/README.md``'s table is generated from this list (:mod:`tresca_py.verify.readme`, run by
``make reference``; a pytest test checks the README is current), and the harness
(:mod:`tresca_py.verify.harness`) takes every recorded result's default statement, command and reference
from here and refuses an id that is not declared.

A requirement is one row: ``id``; ``statement``, completing "The solver shall …"; ``command``, the command
that checks it (a shell line, or prose such as "as P2"); ``reference``, the file it writes (``None`` when
its evidence is the command's output). Most requirements record results under their own id or ``id-…``
(``E1-rect-energy``); a family (one row for the cross-check's ``X-<case>-r<k>``) gives a ``pattern``, a
regular expression a recorded id must match in full.
"""
from tresca_py.verify.requirement import Requirement
from tresca_py.verify.requirements_estimates import ESTIMATES
from tresca_py.verify.requirements_orders import ORDERS
from tresca_py.verify.requirements_tools import TOOLS

__all__ = ("Requirement", "REQUIREMENTS", "find")

#: every requirement, in the order of verification/README.md's table
REQUIREMENTS = ORDERS + ESTIMATES + TOOLS


def find(rid):
    """The requirement a recorded result id belongs to; KeyError when none declares it."""
    found = [r for r in REQUIREMENTS if r.matches(rid)]
    if len(found) != 1:
        raise KeyError("result id "
                       f"{rid!r} matches {len(found)} declared requirements (tresca_py/verify/requirements.py)")
    return found[0]
