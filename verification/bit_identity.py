"""Bit-identity check for refactors: a refactor changes no number.
The logic is in tresca_py/verify/bit_identity.py; this is its entry point.

    python verification/bit_identity.py run DIR [--bin PATH] [--threads N]   # every case's results into DIR
    python verification/bit_identity.py compare DIR_A DIR_B     # compare them dataset by dataset
    python verification/bit_identity.py compare DIR_A DIR_B --rel 1e-10   # floats within a relative tolerance
"""
import sys

from tresca_py.verify.bit_identity import main

if __name__ == "__main__":
    sys.exit(main())
