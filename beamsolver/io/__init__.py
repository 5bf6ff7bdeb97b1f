"""Files: saved solutions (``archive``, numpy only) and ParaView output (``vtk``, numpy and zlib: ``vtu``).

``vtk`` is imported only when output is asked for (``solve(output=)``,
``write_vtk``) or the submodule is first used (``bs.io.vtk.StepWriter``), so
``import beamsolver`` never imports it.
"""
import importlib

from .archive import FORMAT_VERSION, load, save

__all__ = ["load", "save", "write_vtk", "FORMAT_VERSION"]


def write_vtk(solution, folder, steps=None, refine=8, compression="zlib"):
    """Write ``solution`` (all steps, or ``steps``) as VTU/PVD files to ``folder``; see ``io.vtk``."""
    from .vtk import write_vtk as _write
    return _write(solution, folder, steps=steps, refine=refine, compression=compression)


def __getattr__(name):
    """``bs.io.vtk`` and ``bs.io.paraview`` without an explicit import, loaded on first use."""
    if name in ("vtk", "paraview"):
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
