"""Files: saved solutions (``archive``, numpy only) and ParaView output (``vtk``, needs meshio).

``vtk`` is imported only when output is asked for (``solve(output=)``,
``write_vtk``), so ``import beamsolver`` never imports meshio.
"""
from .archive import FORMAT_VERSION, load, save

__all__ = ["load", "save", "write_vtk", "FORMAT_VERSION"]


def write_vtk(solution, folder, steps=None, refine=8, compression="zlib"):
    """Write ``solution`` (all steps, or ``steps``) as VTU/PVD files to ``folder``; see ``io.vtk``."""
    from .vtk import write_vtk as _write
    return _write(solution, folder, steps=steps, refine=refine, compression=compression)
