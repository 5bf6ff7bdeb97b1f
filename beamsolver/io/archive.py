"""Saved results: one ``.npz`` file per ``Solution`` (``Solution.save`` / ``beamsolver.load``).

The format (keys, version, checks) lives in ``beamsolver.results.solution_file`` and is documented
there; this module is its public face in ``io``: ``save(solution, path)``, ``load(path)``
(a ``Solution``), ``read(path)`` (the fields as a dict), ``saved_times(path)``, and the
checkpoint of a run as a writer of its own, ``ArchiveWriter`` (``io.writers``).
Imports run one way: ``io.archive`` -> ``results`` -> ``solution_file``.
"""
import time
from pathlib import Path

from ..results.solution import Solution, load
from ..results.solution_file import FORMAT, FORMAT_VERSION, check_archive, read, saved_times
from ..results.solution_file import save as _save

__all__ = ["save", "load", "read", "saved_times", "check_archive", "ArchiveWriter", "ARCHIVE", "FORMAT",
           "FORMAT_VERSION"]

ARCHIVE = "solution.npz"      # the checkpoint's name in an output folder


def save(solution, path):
    """Write ``solution`` to ``path`` (``.npz`` is appended if missing); returns the ``Path``."""
    if not isinstance(solution, Solution):
        from ..errors import InputError
        raise InputError(f"save: solution must be a beamsolver Solution, got {type(solution).__name__}")
    return _save(solution, path)


class ArchiveWriter:
    """The checkpoint of a run: ``folder/solution.npz`` (``ARCHIVE``), a writer (``io.writers.Writer``).

    ``write(solution, step)`` saves the solution (atomically) when ``checkpoint`` seconds of wall
    time have passed since the last save (``0``: every step; ``inf``: never before ``close``);
    ``close`` saves it.  ``checked``: the folder exists and was found writable (by a writer of
    the same run), else it is created and checked here.  The folder's previous archive is removed
    at once, so a run that fails before its first save leaves no other run's result behind.  ``entries``: step -> time written."""
    archives = True

    def __init__(self, folder, checkpoint=60.0, checked=False):
        from .folder import output_folder
        self.folder = Path(folder) if checked else output_folder(folder)   # checked: by another writer
        self.path = self.folder / ARCHIVE
        self.path.unlink(missing_ok=True)
        self.checkpoint = checkpoint
        self.entries = {}
        self._solution = None
        self._saved_at = time.perf_counter()

    def write(self, solution, step):
        self._solution = solution
        if time.perf_counter() - self._saved_at >= self.checkpoint:
            self.save()
        self.entries[step] = float(solution.times[step])

    def save(self):
        """Save the solution written so far (nothing before the first ``write``)."""
        if self._solution is not None:
            self._solution.save(self.path)
            self._saved_at = time.perf_counter()

    def close(self):
        self.save()
