"""One requirement of `make verify` (:class:`Requirement`); the rows are in :mod:`tresca_py.verify.requirements`."""
import re
from dataclasses import dataclass
from typing import Optional


@dataclass(frozen=True)
class Requirement:
    id: str
    statement: str
    command: str
    reference: Optional[str]
    pattern: Optional[str] = None

    @property
    def sentence(self):
        """The statement as a sentence: "The solver shall …"."""
        return f"The solver shall {self.statement}"

    def matches(self, rid):
        """True when a recorded result id ``rid`` belongs to this requirement."""
        pattern = self.pattern or re.escape(self.id) + r"(-.+)?"
        return re.fullmatch(pattern, rid) is not None
