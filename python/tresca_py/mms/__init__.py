"""Manufactured solutions for tresca-cr, derived once: from an exact displacement u(x, y, t), sympy gives
grad u, sigma(u) (plane strain), f = -div sigma(u), g = sigma(u) n and u0, printed in the solver's expression
syntax (exmex) and written as scene TOML.

Modules: ``blocks`` (piecewise building blocks PosPow/SStep with exact derivatives), ``exmex`` (the printers),
``elasticity`` (sigma, f, side normals, local contact-side fields), ``derive`` (all data of a case),
``checks`` (read-back and pointwise strong-form checks), ``cases`` (the verification cases and the self-test),
``scene_toml`` (the scene file), ``elastic_scene`` (the plain-elasticity scenes of gen_elastic.py).
Entry points: verification/mms/derive.py, verification/cases/gen_elastic.py, verification/bench/make_mms_poly.py.
"""
