"""ParaView output: one ``.vtu`` per converged step and ``.pvd`` collections.

Files in the output folder (``solve(model, output=folder)``, or
``write_vtk(solution, folder)`` for a saved solution):

- ``beams_<k>.vtu``: the beams as ``line`` cells, each element refined into
  ``refine`` segments with the SE(3) interpolation (``io.lines``); point
  data ``displacement``, ``e1``, ``e2``, ``e3``, ``radius``, ``beam_id``;
  cell data ``N, Q2, Q3, T, M2, M3``, ``strain`` (6, minus the reference strain:
  ``Solution.strains - eps0``, zero at rest), ``equivalent_strain`` and ``utilisation``
  (the material range: ``Solution.utilisation``), ``element``.
- ``contact_<k>.vtu`` (scenes with contact only): one vertex per active
  contact point (``normal_force > 0``; the candidates the search found open
  are left out, so a Glyph draws contacts only), with ``gap``,
  ``normal_force``, ``tangential_force`` (3), ``stick`` (1 stick, 0 slip or
  frictionless), ``slip_increment`` (2), ``normal`` (3), ``kind``, ``status``
  (``contact.OPEN``/``STICK``/``SLIP``: 0/1/2; the stick/slip map).  A step
  without contact has no points and one empty poly-vertex cell (VTK type 2):
  meshio cannot read a file without cells, and skips that one with a warning.
- ``beams.pvd`` and ``contact.pvd``: the collections with the pseudo-times,
  or with the step numbers when the pseudo-times do not increase from step to
  step (an arc-length run, ``solve(path="arc-length")``, goes back in ``t``
  past a limit point; ParaView sorts a collection by its times).
- ``solution.npz``: the ``Solution``, written by its own writer (``io.archive.ArchiveWriter``;
  ``solve(output=folder)`` puts it in front of every format of ``io.writers``), saved at the end
  of the run (also when it stops with ``ConvergenceError``) and every ``checkpoint`` seconds of
  wall time (``0``: after every step), for ``beamsolver info`` and ``solve(..., restart=folder)``.
  A ``StepWriter`` given a ``checkpoint`` (its default) keeps one itself.

Every file is written under a temporary name in the same folder, given the
mode ``open()`` would give it (``0666 & ~umask``), and then renamed
(``os.replace``, atomic on POSIX), and the ``.pvd`` files are
rewritten after every step: a run that stops at any moment leaves only
complete files, and ``.pvd`` files that list exactly the steps written.
A writer first removes the numbered files its folder's ``beams.pvd`` and
``contact.pvd`` list (the previous run's series; nothing else; the collections at
once, the files they listed in the writing thread before any new file), so ParaView
never groups two runs; a writer that saves ``solution.npz`` (``checkpoint`` not ``None``)
also removes the previous one at once, so a run that fails before its first save leaves no
other run's result behind.
The VTU files are written by ``io.vtu`` (numpy and zlib; meshio's binary layout, read
by meshio, pyvista and ParaView) with two-point ``line`` cells, which meshio reads (it
cannot read VTK poly-lines, type 4); for smooth tubes ParaView joins them into
poly-lines with *Triangle Strips* before the Tube filter (docs/guide/output.md, "ParaView by hand"; or io.paraview).
"""
from xml.sax.saxutils import quoteattr

import numpy as np

from ..errors import InputError
from ..results.files import previous_series
from .archive import ARCHIVE, ArchiveWriter
from .folder import atomic as _atomic, output_folder as _output_folder
from .lines import LineLayout
from .vtu import write_vtu

__all__ = ["StepWriter", "write_vtk", "write_pvd"]

BEAMS = "beams"
CONTACT = "contact"
SERIES = rf"({BEAMS}|{CONTACT})_[0-9]+\.vtu"     # names of the numbered files of a run
CONTACT_FIELDS = {"gap": (), "normal_force": (), "tangential_force": (3,), "stick": (),
                  "slip_increment": (2,), "normal": (3,), "kind": (), "status": ()}
INT_FIELDS = ("stick", "kind", "status")


def write_pvd(path, entries):
    """Atomically write a ParaView collection of ``(time, file name)`` entries."""
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
             "  <Collection>"]
    for t, name in entries:
        lines.append(f'    <DataSet timestep="{float(t)!r}" group="" part="0" file={quoteattr(name)}/>')
    lines += ["  </Collection>", "</VTKFile>", ""]
    text = "\n".join(lines)

    def write(tmp):
        with open(tmp, "w") as f:
            f.write(text)
    _atomic(path, write)


class StepWriter:
    """Writes the steps of a ``Solution`` as they converge (used by ``solve(output=)``).

    ``folder``: created if missing; ``system``: the ``assembly.System`` (or
    ``None`` when writing a loaded solution); ``refine``: segments drawn per
    element; ``compression``: ``"zlib"``, ``"lzma"`` or ``None``;
    ``checkpoint``: seconds between saves of ``solution.npz`` by the ``io.archive.ArchiveWriter``
    it then keeps (``None``: never save it, as for exporting a loaded solution, or when the
    archive has its own writer, as in ``solve(output=folder)``).

    ``write`` takes what it needs from the solution at once and leaves the files (encoding,
    compression, file system) to one background thread, which writes the steps in order, each
    step's VTU files before the collections that list it, so the solver goes on meanwhile (the
    metadata operations of a busy disk cost milliseconds a file).  ``close`` waits for them.  A
    failure there (``InputError``: full disk, permissions) stops the writing of later steps and
    is raised by the next ``write`` or by ``close``.
    """

    def __init__(self, folder, system=None, refine=8, compression="zlib", contact=None, checkpoint=60.0):
        self.folder = _output_folder(folder)
        stale = previous_series(self.folder, (f"{BEAMS}.pvd", f"{CONTACT}.pvd"), SERIES)
        for name in (f"{BEAMS}.pvd", f"{CONTACT}.pvd"):
            (self.folder / name).unlink(missing_ok=True)
        # this run's archive replaces the last one's, also when it saves nothing
        self.archive = None if checkpoint is None else ArchiveWriter(self.folder, checkpoint, checked=True)
        self.refine = refine
        self.compression = compression
        if contact is None and system is not None:
            contact = bool(system.model.contacts)
        self.contact = contact     # None: decided from the solution's model description
        self.layout = None
        self.entries = {}          # step -> time
        self.width = 4
        self.checkpoint = checkpoint
        self._pool = None          # the writing thread (started by the first write)
        self._jobs = []            # futures of the steps not yet known to be written
        self._failure = None       # the first error of the writing thread: nothing is written after it
        self._reported = False     # whether ``write`` or ``close`` raised it
        if stale:                  # the previous run's files, unlisted now: removed before any new one is written
            self._enqueue(_remove, stale)

    def _name(self, kind, step):
        return f"{kind}_{step:0{self.width}d}.vtu"

    def write(self, solution, step):
        """Write step ``step`` of ``solution`` and rewrite the collections (in the background)."""
        self._raise_failure()
        if self.layout is None:
            self.layout = LineLayout(solution.description, self.refine)
            if self.contact is None:
                self.contact = int(solution.description.get("n_contact_declarations", 0)) > 0
        lay = self.layout
        rec = solution.step(step)
        t = rec.time
        pdata, points = lay.point_data(rec.poses)
        pdata.update(mode_fields(lay, rec.stats))
        cdata = lay.cell_data(rec.section_forces, rec.strains)
        files = [(self.folder / self._name(BEAMS, step), (points, "line", lay.segments, pdata, cdata))]
        if self.contact:
            table = rec.contact
            pos, cpdata = contact_points(table) if len(active_points(table)) else (None, None)
            files.append((self.folder / self._name(CONTACT, step),
                          None if pos is None else (pos, "vertex", np.arange(len(pos)).reshape(-1, 1), cpdata, None)))
        # the archive first, then the collections: a run killed in between never has a .pvd that
        # lists a step its solution.npz lacks (with checkpoint=0 both list the same steps)
        if self.archive is not None:
            self.archive.write(solution, step)
        self.entries[step] = t
        self._submit(files, self._collections())

    def _submit(self, files, collections):
        self._enqueue(self._write_step, files, collections)

    def _enqueue(self, job, *args):
        """Run ``job(*args)`` in the writing thread after the jobs before it (none after a failure)."""
        if self._pool is None:
            from concurrent.futures import ThreadPoolExecutor
            self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="beamsolver-output")
        self._jobs = [j for j in self._jobs if not j.done()]
        self._jobs.append(self._pool.submit(self._guarded, job, *args))

    def _guarded(self, job, *args):
        if self._failure is not None:
            return
        try:
            job(*args)
        except BaseException as e:
            self._failure = e

    def _write_step(self, files, collections):
        """The files of one step, then its collections (in the writing thread)."""
        for path, mesh in files:
            if mesh is None:
                _atomic(path, _write_empty_points)
            else:
                _atomic(path, lambda tmp, m=mesh: write_vtu(tmp, *m, self.compression))
        for path, entries in collections:
            write_pvd(path, entries)

    def _raise_failure(self):
        """Raise the writing thread's failure, if any (every call: nothing more is written)."""
        if self._failure is not None:
            self._reported = True
            raise self._failure

    def save(self):
        """Save the solution written so far to ``solution.npz`` (atomically; with a ``checkpoint``)."""
        if self.archive is not None:
            self.archive.save()

    def _collections(self):
        """``[(path, entries)]`` of the ``.pvd`` files listing the steps written so far."""
        steps = sorted(self.entries)
        times = [self.entries[k] for k in steps]
        if np.any(np.diff(times) <= 0.0):       # not increasing: ParaView would reorder; step numbers
            times = [float(k) for k in steps]
        kinds = (BEAMS, CONTACT) if self.contact else (BEAMS,)
        return [(self.folder / f"{kind}.pvd", [(t, self._name(kind, k)) for t, k in zip(times, steps)])
                for kind in kinds]

    def close(self):
        """Wait for the files of every step, save ``solution.npz``, then raise the writing thread's
        failure if no ``write`` has raised it yet."""
        for j in self._jobs:
            j.result()
        self._jobs = []
        if self._pool is not None:
            self._pool.shutdown(wait=True)
            self._pool = None
        try:
            self.save()
        finally:
            if self._failure is not None and not self._reported:
                self._raise_failure()


def _remove(paths):
    for p in paths:
        p.unlink(missing_ok=True)


def mode_fields(layout, stats):
    """Point data ``mode_j_u``, ``mode_j_rotation`` (j = 1..k) of a step's recorded modes (``solve(modes=k)``)."""
    modes = np.asarray(stats.get("modes", ()), dtype=float)
    out = {}
    for j, m in enumerate(modes if modes.ndim == 3 else ()):
        f = layout.node_field(m)
        out[f"mode_{j + 1}_u"] = np.ascontiguousarray(f[:, :3])
        out[f"mode_{j + 1}_rotation"] = np.ascontiguousarray(f[:, 3:])
    return out


def active_points(table):
    """Indices of the contact points of a step's table that carry force (``normal_force > 0``)."""
    return np.flatnonzero(np.asarray(table.get("normal_force", np.zeros(0)), dtype=float) > 0)


def contact_points(table):
    """The active contact points of one step (``active_points``): positions ``(k, 3)`` and point
    data (``CONTACT_FIELDS``), for a VTU of vertex cells."""
    pos = np.asarray(table.get("position", np.zeros((0, 3))), dtype=float).reshape(-1, 3)
    n = len(pos)
    on = active_points(table) if "normal_force" in table else np.arange(n)
    pos = pos[on]
    k = len(pos)
    pdata = {}
    for name, shape in CONTACT_FIELDS.items():
        v = np.asarray(table[name]).reshape((n,) + shape)[on] if name in table else np.zeros((k,) + shape)
        if name in INT_FIELDS:
            v = v.astype(np.int32)
        else:
            v = v.astype(float)
        pdata[name] = v.reshape((k,) + shape)
    return pos, pdata


def _write_empty_points(path):
    """A VTU with no points, the contact arrays (empty) and one empty poly-vertex cell.

    meshio (5.3) can neither write this nor read a file without cells, nor an empty
    ``format="ascii"`` array without text (hence the blank); ParaView and pyvista read both.
    """
    arrays = "".join(f'<DataArray type="{"Int32" if k in INT_FIELDS else "Float64"}" Name="{k}" '
                     f'NumberOfComponents="{int(np.prod(shape))}" format="ascii"> </DataArray>\n'
                     for k, shape in CONTACT_FIELDS.items())
    text = ('<?xml version="1.0"?>\n'
            '<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">\n'
            '<UnstructuredGrid>\n<Piece NumberOfPoints="0" NumberOfCells="1">\n'
            '<Points>\n<DataArray type="Float64" NumberOfComponents="3" format="ascii"> </DataArray>\n'
            '</Points>\n<Cells>\n<DataArray type="Int64" Name="connectivity" format="ascii"> </DataArray>\n'
            '<DataArray type="Int64" Name="offsets" format="ascii">0</DataArray>\n'
            '<DataArray type="UInt8" Name="types" format="ascii">2</DataArray>\n</Cells>\n'
            f'<PointData>\n{arrays}</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n')
    with open(path, "w") as f:
        f.write(text)


def _steps(steps, n):
    """The step numbers ``steps`` (a list of integers in ``-n .. n - 1``) as ``0 .. n - 1``; else ``InputError``."""
    if isinstance(steps, (str, bytes)) or not hasattr(steps, "__iter__"):
        raise InputError(f"write_vtk: steps must be a list of step numbers or None, got {steps!r}")
    out = []
    for k in steps:
        if isinstance(k, (bool, np.bool_)) or not isinstance(k, (int, np.integer)):
            raise InputError(f"write_vtk: steps must be integers, got {k!r} in {steps!r}")
        if not -n <= k < n:
            raise InputError(f"write_vtk: step {k} out of range (the solution has steps 0..{n - 1})")
        out.append(int(k) % n)
    return out


def write_vtk(solution, folder, steps=None, refine=8, compression="zlib"):
    """Write the steps (default all; a list of step numbers, negative from the end) of a (saved or
    fresh) ``solution`` to ``folder``; returns the .pvd path."""
    n = len(solution)
    chosen = range(n) if steps is None else _steps(steps, n)
    writer = StepWriter(folder, None, refine=refine, compression=compression, checkpoint=None)
    for k in chosen:
        writer.write(solution, k)
    writer.close()
    return writer.folder / f"{BEAMS}.pvd"
