#!/usr/bin/env python3
"""Manufactured cases with nonzero boundary data (scene keys `u` of a dirichlet part, `gap` of a contact
part): derive, check and write verification/cases/mms_data_*.toml.

    .venv/bin/python verification/mms/cases_boundary.py            # derive, check, write the scenes
    .venv/bin/python verification/mms/cases_boundary.py --check    # derive and check only
    .venv/bin/python verification/mms/cases_boundary.py --out DIR  # write into DIR instead

The cases are tresca_py/mms/boundary.py, the derivation and checks tresca_py/mms/boundary_checks.py.
"""
from tresca_py.mms.boundary_checks import main

if __name__ == "__main__":
    main()
