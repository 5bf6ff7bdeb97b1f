"""beamsolver: quasi-static geometrically exact beams on SE(3) with frictional contact."""
from . import contact, elements
from .model import geometry, motion
from .lie import se3
from .stepping.arclength import ArcLength
from .errors import ConditioningWarning, ConvergenceError, GeometryWarning, InputError, MaterialRangeWarning, StabilityWarning, StabilizationWarning
from .io import load
from .results.linearize import Linearization, linearize
from .model.model import Beam, Model
from .results.solution import Solution
from .model.section import Section
from .driver import Convergence, solve
from .version import __version__
from .app.sweep_engine import sweep   # dask is imported when a sweep runs, not here
from .nonlinear.jit_warmup import listen

listen()        # the first compilation of a process prints a line and a progress bar (jit_warmup)


__all__ = ["Model", "Beam", "Section", "Solution", "solve", "Convergence", "InputError",
           "ConvergenceError", "MaterialRangeWarning", "StabilityWarning", "StabilizationWarning", "ConditioningWarning", "GeometryWarning",
           "load", "linearize", "sweep", "Linearization", "se3", "geometry",
           "motion", "contact", "elements", "ArcLength", "__version__"]


# documented module paths of the flat layout (``import beamsolver.geometry``,
# ``beamsolver.stabilize.energy``...) name the modules of the layered packages
import sys as _sys  # noqa: E402

from .model import blocks, cables  # noqa: E402
from .results import topology  # noqa: E402
from .stepping import stabilize  # noqa: E402
from .app import viz  # noqa: E402   (pyvista and matplotlib are imported when a picture is made)

for _name in ("se3", "geometry", "motion", "cables", "topology", "stabilize", "blocks", "viz"):
    _sys.modules[f"{__name__}.{_name}"] = globals()[_name]
del _name, _sys
