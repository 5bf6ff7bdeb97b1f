"""beamsolver: quasi-static geometrically exact beams on SE(3) with frictional contact."""
from . import contact, elements, geometry, motion, se3
from .arclength import ArcLength
from .errors import (ConditioningWarning, ConvergenceError, InputError, MaterialRangeWarning, StabilityWarning,
                     StabilizationWarning)
from .io import load
from .linear import Linearization, linearize
from .model import Beam, Model
from .results import Solution
from .section import Section
from .solver import Convergence, solve
from .version import __version__
from .sweep_engine import sweep   # dask is imported when a sweep runs, not here
from .jit_warmup import listen

listen()        # the first compilation of a process prints a line and a progress bar (jit_warmup)


__all__ = ["Model", "Beam", "Section", "Solution", "solve", "Convergence", "InputError",
           "ConvergenceError", "MaterialRangeWarning", "StabilityWarning", "StabilizationWarning", "ConditioningWarning",
           "load", "linearize", "sweep", "Linearization", "se3", "geometry",
           "motion", "contact", "elements", "ArcLength", "__version__"]
