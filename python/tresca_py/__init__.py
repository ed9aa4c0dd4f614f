"""tresca_py: the Python half of tresca-cr, one installed package (`pip install -e python`, done by `make venv`).

Each concept lives in one module; the scripts in `scripts/` and `verification/` are thin entry points that
import from here. No module keeps mutable state at import time.
"""
