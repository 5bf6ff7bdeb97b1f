"""Output of a run: writers behind one protocol (``Writer``), formats in a registry (``FORMATS``).

``solve(output=folder)`` opens ``open_output(folder, system, checkpoint)``: the checkpoint
``solution.npz`` (``io.archive.ArchiveWriter``, always first, whatever the formats) and one
writer per format of ``DEFAULT_FORMATS`` (``"vtk"``: ``io.vtk.StepWriter``), as one ``Writers``.
A new format is ``register("name", factory)`` with ``factory(folder, system)`` returning a
``Writer`` (and ``default=True`` to write it in every ``solve(output=folder)``): it never
owns, and so can never lose, the checkpoint.
"""
from pathlib import Path
from typing import Protocol

from ..errors import InputError
from .archive import ArchiveWriter

__all__ = ["Writer", "Writers", "FORMATS", "DEFAULT_FORMATS", "register", "open_output"]


class Writer(Protocol):
    """``write(solution, step)``: step ``step`` of ``solution`` converged (called in order, once each);
    ``close()``: the run ended (wait for pending files, raise their failure); optional ``entries``
    (step -> time) of the steps written, which lets a stopped run write its last step once."""

    def write(self, solution, step): ...

    def close(self): ...


def _vtk(folder, system):
    from .vtk import StepWriter          # meshio-free, but only imported when output is asked for
    return StepWriter(folder, system, checkpoint=None)


FORMATS = {"vtk": _vtk}       # name -> factory(folder, system) -> Writer
DEFAULT_FORMATS = ["vtk"]     # the formats of solve(output=folder)


def register(name, factory, default=False):
    """Add the output format ``name`` (``factory(folder, system)`` -> ``Writer``); with ``default``
    ``solve(output=folder)`` writes it too."""
    if not isinstance(name, str) or not name or not callable(factory):
        raise InputError(f"register: need a format name (str) and a callable factory, got {name!r}, {factory!r}")
    FORMATS[name] = factory
    if default and name not in DEFAULT_FORMATS:
        DEFAULT_FORMATS.append(name)


class Writers:
    """Several writers as one ``Writer``: each step goes to every writer in order (the archive
    first: a run killed in between never has files listing a step its checkpoint lacks); ``close``
    closes them all in the reverse order (the archive's last save after every file, as the
    uninterrupted run would have it) and then raises the first failure.  ``entries``: the steps
    every writer took."""

    def __init__(self, writers):
        self.writers = list(writers)
        self.entries = {}

    def write(self, solution, step):
        for w in self.writers:
            w.write(solution, step)
        self.entries[step] = float(solution.times[step])

    def close(self):
        failure = None
        for w in reversed(self.writers):
            try:
                w.close()
            except BaseException as e:         # close the others first, then raise the first failure
                failure = failure or e
        if failure is not None:
            raise failure


def open_output(folder, system, checkpoint=60.0, formats=None):
    """The writers of ``solve(output=folder)``: ``ArchiveWriter(folder, checkpoint)`` (``None``:
    saved only at the end or when the run stops) and one per format of ``formats`` (default
    ``DEFAULT_FORMATS``), as ``Writers``."""
    names = DEFAULT_FORMATS if formats is None else list(formats)
    unknown = [n for n in names if n not in FORMATS]
    if unknown:
        raise InputError(f"output: unknown format(s) {unknown}; known: {sorted(FORMATS)}")
    formats = [FORMATS[n](folder, system) for n in names]
    # the folder is created and checked once: by a format's writer (as io.vtk.StepWriter), else here
    checked = any(Path(getattr(w, "folder", "")) == Path(folder) for w in formats)
    archive = ArchiveWriter(folder, float("inf") if checkpoint is None else checkpoint, checked=checked)
    return Writers([archive] + formats)
