"""Saved results: one ``.npz`` file per ``Solution`` (``Solution.save`` / ``beamsolver.load``).

The format (keys, version, checks) lives in ``beamsolver.results.solution_file`` and is documented
there; this module is its public face in ``io``: ``save(solution, path)``, ``load(path)``
(a ``Solution``), ``read(path)`` (the fields as a dict), ``saved_times(path)``.
Imports run one way: ``io.archive`` -> ``results`` -> ``solution_file``.
"""
from ..results.solution import Solution, load
from ..results.solution_file import FORMAT, FORMAT_VERSION, check_archive, read, saved_times
from ..results.solution_file import save as _save

__all__ = ["save", "load", "read", "saved_times", "check_archive", "FORMAT", "FORMAT_VERSION"]


def save(solution, path):
    """Write ``solution`` to ``path`` (``.npz`` is appended if missing); returns the ``Path``."""
    if not isinstance(solution, Solution):
        from ..errors import InputError
        raise InputError(f"save: solution must be a beamsolver Solution, got {type(solution).__name__}")
    return _save(solution, path)
