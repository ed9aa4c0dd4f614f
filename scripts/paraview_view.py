"""One command to look at a tresca-cr run in ParaView (pvpython 5.11 and newer):
``xvfb-run -a pvpython scripts/paraview_view.py run.h5 [-o view.png] [--time T] [--frames DIR] [--scale S]``.

A thin entry point; the view is built by ``tresca_py.paraview_view``. pvpython runs ParaView's own Python,
which does not see the project's venv: there the package is loaded from its place in this repository (the
modules pvpython runs need only the standard library and ParaView)."""
import importlib.util
import os
import sys


def package_module():
    try:
        from tresca_py import paraview_view
    except ModuleNotFoundError:
        pkg = os.path.join(os.path.dirname(os.path.realpath(__file__)), os.pardir, "python", "tresca_py")
        spec = importlib.util.spec_from_file_location("tresca_py", os.path.join(pkg, "__init__.py"),
                                                      submodule_search_locations=[pkg])
        module = importlib.util.module_from_spec(spec)
        sys.modules["tresca_py"] = module
        spec.loader.exec_module(module)
        from tresca_py import paraview_view
    return paraview_view


if __name__ == "__main__":
    sys.exit(package_module().main())
