"""What each re-implementation route models (issue 40), so that a cross-check row of a scene outside a route says
"not supported by <route>: <why>" instead of failing on it or skipping it silently.

    skfem        scripts/skfem_solve.py: every scene of the Rust solver, but a floating body (no Dirichlet part)
                 only with normal unknowns (a unilateral or Coulomb part: ``tresca_py.skfem_cr.floating``)
    dolfinx      scripts/dolfinx_solve.py, serially or under mpirun: as skfem, but Tresca thresholds only: PETSc
                 TAO solves a bound-constrained QP with fixed bounds, and Coulomb's bound F·P moves with the
                 unknown P (``tresca_py.dolfinx_cr.edges``)
    distributed  scripts/dolfinx_distributed.py: bilateral Tresca contact of a body held by a Dirichlet part (its
                 contact unknowns are the tangential ones alone, condensed by MUMPS across the ranks; no normal
                 unknowns, no rigid motions: ``tresca_py.dolfinx_cr.distributed``)

A route must refuse a scene outside its scope with exit status 2 and a message naming the part (``refused``
checks it): the support is stated here once and enforced there.
"""
from tresca_py.scene import load_scene

ROUTES = ("skfem", "dolfinx", "distributed")


def _floating(scene):
    return not any(b.kind == "dirichlet" for b in scene.boundaries)


def scope(route, scene):
    """(part, reason) where ``route`` does not model ``scene`` (a ``tresca_py.scene.Scene``), else None; part is the
    name of the boundary part concerned, or None for the scene as a whole (a floating body)."""
    if route not in ROUTES:
        raise ValueError(f"unknown route {route!r} (known: {', '.join(ROUTES)})")
    for b in scene.boundaries:
        if b.kind != "contact":
            continue
        if route != "skfem" and b.coulomb is not None:
            return b.name, f"Coulomb friction on part '{b.name}' (the {route} route takes fixed Tresca thresholds)"
        if route == "distributed" and b.law == "unilateral":
            return b.name, f"unilateral contact on part '{b.name}' (the distributed route has no normal unknowns)"
        if route == "distributed" and b.traction is not None:
            return b.name, f"a surface load on the contact part '{b.name}' (not modelled by the distributed route)"
    if _floating(scene) and (route == "distributed" or not scene.normal_unknowns):
        why = "no rigid motions" if route == "distributed" else "floating only with a unilateral or Coulomb part"
        return None, f"a floating body, no Dirichlet part (the {route} route: {why})"
    return None


def unsupported(route, path):
    """``scope`` of the scene file ``path``: (part, reason) or None."""
    return scope(route, load_scene(path))


def refused(returncode, message, part):
    """True if a route's run ended as a refusal of an unsupported scene should: exit status 2 with an ``error:``
    line naming ``part`` (the part of ``scope``; a floating body's refusal names the missing Dirichlet part)."""
    named = f"'{part}'" in message if part else "dirichlet" in message.lower()
    return returncode == 2 and "error:" in message and named
