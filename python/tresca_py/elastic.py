"""Plane-strain Lamé constants: the one formula every solver, view and derivation of the package uses
(no dependency beyond Python, so the system interpreters of ParaView and GetFEM import it too)."""


def lame(E, nu):
    """Plane-strain Lamé constants (lambda, mu) of Young's modulus E and Poisson's ratio nu."""
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
