"""The distributed DOLFINx 0.11 + PETSc/MUMPS re-implementation (scripts/dolfinx_distributed.py).

Modules: ``mesh`` (distributed meshes and boundary parts), ``problem`` (space, constraints, assembly),
``data`` (boundary data ``u``/``gap``: the lifting), ``consistency`` (data that do not fit together refused),
``linear`` (factorisation and contact condensation), ``output`` (per-rank parts + virtual datasets), ``main``
(the command line and the time loop).

Same discrete problem as scripts/dolfinx_solve.py and the Rust solver (README, Problem 2 of Porwal &
Wadhawan), but nothing of size O(mesh) is held by one rank:

* Mesh.  Structured scenes: every rank generates a contiguous slab of the scene's points and triangles
  (the scene's numbering and diagonal convention, README "Scenes") and ``dolfinx.mesh.create_mesh``
  partitions and distributes them.  (``dolfinx.mesh.create_rectangle`` would build the whole triangle
  mesh on rank 0 first: C++ ``build_tri`` generates on rank 0 only.)  Sides are tagged on the unit square
  and the points then mapped bilinearly onto the corners.  Gmsh scenes: the file is read on rank 0 with
  meshio (the wheel has no ``gmsh`` module, which ``dolfinx.io.gmsh`` needs; dolfinx's reader also reads
  on rank 0), red-refined there ``refine`` times (dolfinx's own ``refine`` bisects, a different mesh) and
  distributed by ``create_mesh``; facet tags follow with ``dolfinx.io.distribute_entity_data``.
* Space and constraints.  V = vector CR ("CR", 1, (2,)).  a_h and the loads are assembled by dolfinx
  into a distributed PETSc matrix / vector.  The constrained space (zero on Gamma_D midpoints, u.n = 0
  on Gamma_C midpoints) is imposed by a block-diagonal rotation R (identity except [tau n] on contact
  edges): K_r = R^T K R (``PtAP``), then the Dirichlet unknowns and the contact normal unknowns are
  removed by ``zeroRowsColumns`` (unit diagonal, zero right-hand side).  u = R r.
* Factorisation.  K_r is factored once by MUMPS Cholesky through PETSc (``--ksp mumps``, the default),
  or used by CG + GAMG (``--ksp cg-gamg``, rtol 1e-13; for the measured comparison only).
* Contact condensation.  Only the contact unknowns are gathered: C = E^T K_r^{-1} E (n_c x n_c) is the
  contact block of K_r^{-1}, computed by MUMPS as selected entries of the inverse (ICNTL(30), PETSc's
  MatMumpsGetInverseTranspose through ctypes: petsc4py does not wrap it), delivered to rank 0; no dense
  n x n_c block exists.  (``--condense matsolve``: blocked multi-right-hand-side MatMatSolve instead,
  ``--rhs-block`` columns at a time; at 1.57M unknowns on 1 rank, blocks of 32: 76 s and +0.95 GB for C,
  against 10 s and no extra memory for the selected entries.)
  Per step: u_f = K_r^{-1} l^n (distributed; with boundary data l^n + b_D - a_h(u_L, .), module ``data``),
  d = E^T u_f - s^{n-1} gathered to rank 0 (n_c numbers),
  the friction problem solved there by PETSc TAO TRON (``tresca_py.dolfinx_cr.friction.TaoBoxQP``),
  mu broadcast, u^n = u_f - K_r^{-1} E mu (distributed); the displacement written is R u^n + u_L(t_n).
* True errors are assembled distributed (the UFL forms of ``tresca_py.dolfinx_cr.forms``).
* Output, without gathering the field: each rank writes its owned edges (points, triangles, edges,
  midpoints, u at every step) to ``OUT.h5.parts/rank<r>.h5`` with serial h5py; rank 0 writes ``OUT.h5``
  with the contact data, statistics and attributes and HDF5 *virtual datasets* that concatenate the
  parts, so ``OUT.h5`` has the ``/tresca`` layout of ``tresca_py.results`` (``read`` accepts it; why not
  ``results.write``: module ``output``) (h5py, any HDF5 >= 1.10 reader, and
  scripts/compare.py open it as one file; the parts must stay beside it).  The displacement as
  discontinuous P1 goes to ``OUT_vtk/displacement.pvd`` through dolfinx's parallel VTKFile
  (one .vtu piece per rank and frame + .pvtu/.pvd sidecars; read by ParaView and VTK's
  vtkXMLPUnstructuredGridReader).

Edges are numbered by dolfinx's global CR dof-block numbering (owned ranges in rank order), so the
numbering depends on the number of ranks; tools match edges by midpoint coordinates (scripts/compare.py).
"""
