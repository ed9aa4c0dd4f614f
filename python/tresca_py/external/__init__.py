"""Verification against external codes on the continuous problem (issue 30 section 3).

``problem``   -- scene TOML -> a plain, JSON-serialisable problem description (own reader, no solver code);
``getfem_solver`` -- GetFEM 5.4 P1/P2 solver, standalone (runs under Debian's /usr/bin/python3);
``skfem_nitsche`` -- an independent conforming-P2 Nitsche solver in scikit-fem;
``tresca``    -- tresca-cr's column (``tresca-cr study --csv`` and its results files);
``richardson`` -- limits and GCI bands; ``requirements`` -- the X-ext requirements.
"""
