"""Hertz verification (issue 40 item 3): a plane-strain elastic cylinder on a rigid plane, frictionless
unilateral contact. ``formulas`` (Hertz's half-space solution), ``mesh`` (graded quarter disc written as Gmsh
4.1), ``scene`` (the scene text), ``extract`` (contact half-width, peak pressure and profile errors from a
results file)."""
