"""Check a tresca-cr results file through three independent readers (VTK's vtkHDFReader, meshio and VTK's
XDMF readers, h5py): ``.venv/bin/python scripts/check_results.py run.h5 [--xdmf run.xdmf]``.

A thin entry point; the checks live in ``tresca_py.check`` (``reference`` is re-exported for
verification/paraview_check.py)."""
import sys

from tresca_py.check import main, reference  # noqa: F401

if __name__ == "__main__":
    sys.exit(main())
