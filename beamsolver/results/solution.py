"""The ``Solution`` of a solve: a public, validated record of every converged pseudo-time step.

The data model is the docstring of ``Solution``.  ``append`` (one step) and
``Solution.from_steps`` (all at once) check shapes, finiteness and increasing times and
raise ``InputError`` naming the field and the value.  ``step(k)`` gives one step as a
``Step`` record.  ``save`` writes everything to a versioned ``.npz`` file (format
documented in ``beamsolver.results.solution_file``); ``load`` reads it.
"""
import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..model.material_range import element_properties as _properties
from ..model.material_range import utilisation as _utilisation
from .solution_file import read as _read_file
from .solution_file import save as _save_file

__all__ = ["Solution", "Step", "describe_model", "load", "STEP_ARRAYS"]

STEP_ARRAYS = ("times", "poses", "reactions", "section_forces", "strains")


def load(path):
    """Read a ``Solution`` written by ``Solution.save`` (``model`` and ``system`` are ``None``).

    ``path``: the ``.npz`` file (the suffix may be left out) or an output folder holding
    ``solution.npz``; a file that is not such an archive, or is damaged, raises ``InputError``
    naming it (``solution_file.read``).
    """
    fields = _read_file(path)
    try:
        return Solution.from_steps(**fields)
    except InputError as e:
        raise InputError(f"load({str(path)!r}): damaged beamsolver result: {e}") from None


def describe_model(model, system=None):
    """Arrays describing ``model`` for drawing and summaries (no callables, no objects).

    ``poses0`` (n, 4, 4); ``enodes`` (n_el, 2); ``L`` (n_el,); ``eps0`` (n_el, 6);
    ``element_beam`` (n_el,); ``node_beam`` (n,) (-1 for nodes of ``add_node``);
    ``beam_first_node``, ``beam_n_nodes``, ``beam_radius`` (n_beams,); ``beam_C``
    (n_beams, 6, 6); ``beam_E``, ``beam_G`` (moduli), ``beam_yield_stress``,
    ``beam_yield_strain`` (n_beams,) (inf: no limit; ``material_range``);
    ``beam_name`` (str); ``constrained_nodes`` and
    ``constraint_kind`` ('clamp', 'fix' or 'prescribe'); ``load_nodes``;
    ``joins`` (k, 2); ``n_contact_declarations``; ``beam_element`` (n_beams,) element type names
    (``elements.TYPES``; element ``j`` of a beam with ``k``-node elements has its nodes
    ``first + (k - 1) j + (0 .. k - 1)``; ``enodes`` holds the first and the last).
    """
    if system is not None:
        enodes, L, eps0 = system.enodes, system.L, system.eps0
    else:
        enodes, L, eps0, _ = model.element_table()
    beams = model.beams
    n = model.n_nodes
    node_beam = np.full(n, -1, dtype=np.int64)
    element_beam = np.zeros(len(L), dtype=np.int64)
    for b in beams:
        node_beam[b.nodes] = b.id
        element_beam[b.elements] = b.id
    cons = sorted(model.constraints.items())
    return dict(
        poses0=np.array(model.poses0, dtype=float), enodes=np.array(enodes, dtype=np.int64),
        L=np.array(L, dtype=float), eps0=np.array(eps0, dtype=float),
        element_beam=element_beam, node_beam=node_beam,
        beam_first_node=np.array([b.first for b in beams], dtype=np.int64),
        beam_n_nodes=np.array([len(b.nodes) for b in beams], dtype=np.int64),
        beam_radius=np.array([b.section.radius for b in beams], dtype=float),
        beam_C=np.array([b.section.C for b in beams], dtype=float).reshape(-1, 6, 6),
        beam_E=np.array([b.section.E for b in beams], dtype=float),
        beam_G=np.array([b.section.G for b in beams], dtype=float),
        beam_yield_stress=np.array([_limit(b.section.yield_stress) for b in beams], dtype=float),
        beam_yield_strain=np.array([_limit(b.section.yield_strain) for b in beams], dtype=float),
        beam_name=np.array([b.name or "" for b in beams], dtype=str),
        beam_element=np.array([b.element_type.name for b in beams], dtype=str),
        constrained_nodes=np.array([c[0] for c in cons], dtype=np.int64),
        constraint_kind=np.array([c[1][0] for c in cons], dtype=str),
        load_nodes=np.array([ld.node for ld in model.loads], dtype=np.int64),
        joins=np.array(model.joins, dtype=np.int64).reshape(-1, 2),
        n_contact_declarations=np.int64(len(model.contacts)))


def _limit(value):
    return np.inf if value is None else value


@dataclass(frozen=True)
class Step:
    """One recorded step of a ``Solution`` (``Solution.step(k)``): views, not copies."""
    index: int
    time: float
    poses: np.ndarray           # (n, 4, 4)
    reactions: np.ndarray       # (n, 6)
    section_forces: np.ndarray  # (n_el, 6)
    strains: np.ndarray         # (n_el, 6)
    stats: dict
    contact: dict
    extra: dict                 # name -> value of this step (names without a value here left out)


class _Growing:
    """A ``(s, *shape)`` array grown one step at a time, read as one array (a view).

    A full buffer is not copied: the next steps go to a new chunk as large as everything so
    far (so there are O(log s) chunks and each step is written once).  Reading joins the
    chunks into one buffer with room for as many steps again, so reads after every append
    copy O(s) only when a chunk was added: appending and reading stay amortised O(1).
    """

    def __init__(self, shape, dtype=float):
        self.chunks, self.starts = [np.empty((4,) + tuple(shape), dtype=dtype)], [0]

    @classmethod
    def holding(cls, rows):
        """A copy of the array ``rows`` (one row per step)."""
        g = cls(rows.shape[1:], rows.dtype)
        g.chunks = [np.array(rows) if len(rows) else g.chunks[0]]
        return g

    def put(self, k, value):
        """Write step ``k`` (``k`` >= the start of the last chunk: a step is written in order)."""
        if k - self.starts[-1] >= len(self.chunks[-1]):
            self.chunks.append(np.empty((max(k, 4),) + self.chunks[0].shape[1:], dtype=self.chunks[0].dtype))
            self.starts.append(k)
        self.chunks[-1][k - self.starts[-1]] = value

    def view(self, n):
        """The first ``n`` steps, read-only."""
        if len(self.chunks) > 1:
            one = np.empty((max(2 * n, 4),) + self.chunks[0].shape[1:], dtype=self.chunks[0].dtype)
            ends = self.starts[1:] + [n]
            for c, a, b in zip(self.chunks, self.starts, ends):
                one[a:b] = c[:b - a]
            self.chunks, self.starts = [one], [0]
        v = self.chunks[0][:n]
        v.flags.writeable = False
        return v


def _array(where, name, value, shape, what):
    """``value`` as a finite float array of ``shape`` (``InputError`` naming ``name`` otherwise)."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{where}: {name} must be an array of numbers of shape {shape} ({what}), "
                         f"got {type(value).__name__}") from None
    if a.shape != shape:
        raise InputError(f"{where}: {name} must have shape {shape} ({what}), got {a.shape}")
    if not np.isfinite(a).all():
        i = tuple(int(j) for j in np.argwhere(~np.isfinite(a))[0])
        raise InputError(f"{where}: {name} must be finite, got {a[i]} at index {i}")
    return a


def _time(where, t, last):
    if isinstance(t, (bool, np.bool_)) or not isinstance(t, (int, float, np.integer, np.floating)) \
            or not math.isfinite(t):
        raise InputError(f"{where}: times must be finite numbers, got t = {t!r}")
    if last is not None and not t > last:
        raise InputError(f"{where}: times must increase, got t = {float(t)!r} after {last!r}")
    return float(t)


def _table(where, contact):
    """A contact point table: dict of ``str`` -> arrays with equal first dimension."""
    if contact is None:
        return {}
    if not isinstance(contact, dict) or not all(isinstance(k, str) for k in contact):
        raise InputError(f"{where}: contact must be a dict of arrays keyed by name (or None), "
                         f"got {type(contact).__name__}")
    table = {k: np.asarray(v) for k, v in contact.items()}
    rows = {k: (v.shape[0] if v.ndim else None) for k, v in table.items()}
    if len(set(rows.values())) > 1 or None in rows.values():
        raise InputError(f"{where}: contact arrays must have one row per contact point, got rows {rows}")
    return table


def _extra(where, extra):
    """Per-step values by name: numbers, bools, strings or arrays of them (what ``save`` stores)."""
    if extra is None:
        return {}
    if not isinstance(extra, dict) or not all(isinstance(k, str) and k for k in extra):
        raise InputError(f"{where}: extra must be a dict keyed by non-empty names, got {extra!r}")
    out = {}
    for k, v in extra.items():
        a = np.asarray(v)
        if a.dtype.kind not in "biufU":
            raise InputError(f"{where}: extra[{k!r}] must be a number, bool, string or array of them, got {v!r}")
        out[k] = a if isinstance(v, (list, tuple, np.ndarray)) else v.item() if isinstance(v, np.generic) else v
    return out


class Solution:
    """Results at every converged pseudo-time step (public, validated).

    Data model (all public; arrays are read-only views, appending a step is amortised O(1)):

    ===================  ==========================================================================
    field                content
    ===================  ==========================================================================
    ``times``            ``(s,)`` pseudo-times (step 0: the state at ``t_start``), strictly increasing
                         unless ``path`` is ``"arc-length"`` (then ``t`` may go back)
    ``poses``            ``(s, n, 4, 4)`` node poses (finite)
    ``reactions``        ``(s, n, 6)`` global force and moment on every node (non-zero where constrained)
    ``section_forces``   ``(s, n_el, 6)`` ``N, Q2, Q3, T, M2, M3`` in the section frame
    ``strains``          ``(s, n_el, 6)`` element strain ``h / L``, reference included
                         (``(1, 0, 0, 0, 0, 0)`` for a straight beam at rest), so ``section_forces
                         = C (strains - description["eps0"])``; the VTU ``strain`` is that difference
    ``stats``            list of ``s`` dicts: ``iterations``, ``residuals``, ``wall_time``, ``dt``,
                         ``cutbacks``, and whatever the solver adds (``failed_dt``, ``warnings``,
                         ``timings``; by default ``stable``, ``negative_eigenvalues``,
                         ``lowest_eigenvalue`` and, where ``stable`` is ``None`` or not the step's own
                         tangent's, ``stable_note``: ``stepping.stability``; with exact stick ``changes``,
                         per Newton iteration the groups whose stick / slip branch changed)
    ``contacts``         list of ``s`` contact point tables (dicts of arrays of equal length ``k``,
                         one row per contact point the search found; ``{}`` for a step without
                         contact): ``position`` (k, 3) midway between the contour points, ``gap``,
                         ``normal_force`` and ``tangential_force`` (k, 3) on the slave (integrated
                         over the point's ``weight``, a length), ``status`` (``contact.OPEN`` 0: no
                         normal force, ``STICK`` 1, ``SLIP`` 2: sliding or frictionless), ``stick``
                         (True for status STICK only), ``slip_increment`` (k, 2) of the step,
                         ``kind`` (0 line, 1 orthogonal, 2 point), ``angle`` between the tangents
                         (degrees), ``slave_element``, ``master_element``, ``xi1``, ``xi2``,
                         ``normal`` (k, 3)
    ``extra``            dict ``name -> list`` of ``s`` per-step values (arrays or numbers; ``None``
                         where a step has none): room for per-step data of any kind (buckling modes,
                         path-following data) without a new field; with exact stick
                         (``add_contact(stick="exact")``) the nodal table of the mortar groups,
                         ``mortar_node``, ``mortar_master_beam``, ``mortar_normal_force``,
                         ``mortar_tangential_force`` (g, 3), ``mortar_status``, ``mortar_slip``
                         (``contact.system.ContactSystem.nodal_results``): the forces whose Coulomb
                         cone the law holds (the point table's tractions are interpolated from them)
    ``description``      arrays describing the model (``describe_model``)
    ``converged``        bool; ``message`` (str) why not, and warnings
    ``off_equilibrium``  bool: the run reached its end but its final state is not an equilibrium of
                         the model (``solve(stabilize=)``: the viscous forces still carry load);
                         ``converged`` is then False.  ``status`` (read-only) says which:
                         ``"converged"``, ``"off-equilibrium"`` or ``"stopped"``
    ``resume``           stepping state after the last step (``stepping.next_step``), for restart;
                         ``path`` (read-only) is its ``"path"`` entry, ``"load"`` by default
    ``contact_state``    committed history of the contributions (contact, ...) at the last step
                         (dict of arrays, keys ``name/key``: ``Problem.get_state``), for restart
    ``model, system``    the ``Model`` and its assembly (``None`` for a loaded solution)
    ===================  ==========================================================================

    ``Solution(model, system=None, description=None)`` starts empty; ``solve`` appends a
    step at each converged increment.  ``description`` (for a solution without a model)
    fixes the node and element counts every step must match.
    """

    def __init__(self, model=None, system=None, description=None):
        self.model = model
        self.system = system
        self._description = description
        self._n = 0
        self._last_time = None
        self._arrays = {}
        self._stats, self._contacts, self._extra = [], [], {}
        self.converged = True
        self.off_equilibrium = False
        self.message = ""
        self.resume = {}
        self.contact_state = {}

    @classmethod
    def from_steps(cls, description, times, poses, reactions, section_forces, strains, stats=None,
                   contacts=None, extra=None, converged=True, message="", resume=None, contact_state=None,
                   model=None, system=None, off_equilibrium=False):
        """A ``Solution`` holding the given steps (arrays with one row per step), each checked as by
        ``append``; ``stats``/``contacts`` lists and ``extra`` lists default to empty entries."""
        where = "Solution.from_steps"
        s = len(times) if hasattr(times, "__len__") else None
        if s is None:
            raise InputError(f"{where}: times must be a sequence of numbers, got {times!r}")
        given = dict(poses=poses, reactions=reactions, section_forces=section_forces, strains=strains,
                     stats=stats if stats is not None else [{}] * s,
                     contacts=contacts if contacts is not None else [None] * s)
        given.update({f"extra[{k!r}]": v for k, v in (extra or {}).items()})
        for name, v in given.items():
            if not hasattr(v, "__len__") or len(v) != s:
                raise InputError(f"{where}: {name} must have one entry per step ({s} times), "
                                 f"got {len(v) if hasattr(v, '__len__') else repr(v)}")
        sol = cls(model, system, description)
        sol.resume = dict(resume or {})          # first: its "path" says whether times must increase
        for k in range(s):
            ex = {n: v[k] for n, v in (extra or {}).items() if v[k] is not None}
            sol._append(f"{where} (step {k})", times[k], poses[k], reactions[k], section_forces[k], strains[k],
                        given["stats"][k], given["contacts"][k], ex)
        sol.converged, sol.message = bool(converged), str(message)
        sol.off_equilibrium = bool(off_equilibrium) and not sol.converged
        sol.contact_state = dict(contact_state or {})
        return sol

    @property
    def description(self):
        if self._description is None:
            self._description = describe_model(self.model, self.system)
        return self._description

    def save(self, path):
        """Write every field to ``path`` (.npz), atomically (temporary name, then rename).

        Read it back with ``beamsolver.load``; the format is documented in ``beamsolver.results.solution_file``.
        """
        return _save_file(self, path)

    def copy_steps(self, model=None, system=None):
        """A new ``Solution`` of ``model``/``system`` holding copies of these steps."""
        new = Solution(model, system, self._description if model is None else None)
        n = new._n = self._n
        new._last_time = self._last_time
        for name, g in self._arrays.items():
            new._arrays[name] = _Growing.holding(g.view(n))
        new._stats, new._contacts = list(self.stats), list(self.contacts)
        new._extra = {k: list(v) for k, v in self.extra.items()}
        new.resume = dict(self.resume)
        new.contact_state = dict(self.contact_state)
        new.converged, new.message, new.off_equilibrium = self.converged, self.message, self.off_equilibrium
        return new

    def append(self, t, H, reactions, sigma, strain, stats, contact=None, extra=None):
        """Record one converged step: time ``t``, poses ``H`` ``(n, 4, 4)``, ``reactions`` ``(n, 6)``,
        section forces ``sigma`` and strains ``strain`` ``(n_el, 6)``, ``stats`` (dict), ``contact``
        (point table or None), ``extra`` (dict name -> value).  ``InputError`` names a bad field."""
        self._append("Solution.append", t, H, reactions, sigma, strain, stats, contact, extra)

    def _counts(self, H):
        if self._n:
            return self._arrays["poses"].chunks[0].shape[1], self._arrays["section_forces"].chunks[0].shape[1]
        if self._description is not None:
            return len(self._description["poses0"]), len(self._description["enodes"])
        if self.system is not None:
            return len(self.system.poses0), len(self.system.L)
        return np.shape(H)[0] if np.ndim(H) == 3 else 0, None

    def _append(self, where, t, H, reactions, sigma, strain, stats, contact, extra):
        n = self._n
        nn, ne = self._counts(H)
        if ne is None:
            ne = np.shape(sigma)[0] if np.ndim(sigma) == 2 else 0
        values = dict(times=_time(where, t, self._last_time if self.path == "load" else None),
                      poses=_array(where, "poses", H, (nn, 4, 4), "one pose per node"),
                      reactions=_array(where, "reactions", reactions, (nn, 6), "force and moment per node"),
                      section_forces=_array(where, "section_forces", sigma, (ne, 6), "per element"),
                      strains=_array(where, "strains", strain, (ne, 6), "per element"))
        if stats is None:
            stats = {}
        if not isinstance(stats, dict):
            raise InputError(f"{where}: stats must be a dict, got {type(stats).__name__}")
        contact, extra = _table(where, contact), _extra(where, extra)
        self._trim()
        for name, v in values.items():
            if name not in self._arrays:
                self._arrays[name] = _Growing(np.shape(v))
            self._arrays[name].put(n, v)
        self._stats.append(stats)
        self._contacts.append(contact)
        for name in extra:
            self._extra.setdefault(name, [None] * n)
        for name, series in self._extra.items():
            series.append(extra.get(name))
        self._last_time = values["times"]
        self._n = n + 1        # last: a step interrupted above is not recorded (``_trim``)

    def _trim(self):
        """Drop what a step interrupted inside ``append`` left behind."""
        n = self._n
        if len(self._stats) != n or len(self._contacts) != n or any(len(v) != n for v in self._extra.values()):
            del self._stats[n:], self._contacts[n:]
            for v in self._extra.values():
                del v[n:]

    def _view(self, name):
        if name in self._arrays:
            return self._arrays[name].view(self._n)
        nn, ne = self._counts(None)
        shape = dict(times=(), poses=(nn or 0, 4, 4), reactions=(nn or 0, 6))
        return np.zeros((0,) + shape.get(name, (ne or 0, 6)))

    @property
    def times(self):
        """``(s,)`` pseudo-times (read-only view)."""
        return self._view("times")

    @property
    def poses(self):
        """``(s, n, 4, 4)`` node poses (read-only view)."""
        return self._view("poses")

    @property
    def reactions(self):
        """``(s, n, 6)`` global force and moment on every node (read-only view)."""
        return self._view("reactions")

    @property
    def section_forces(self):
        """``(s, n_el, 6)`` section forces ``N, Q2, Q3, T, M2, M3`` (read-only view)."""
        return self._view("section_forces")

    @property
    def strains(self):
        """``(s, n_el, 6)`` element strains ``h / L``, reference included (read-only view)."""
        return self._view("strains")

    @property
    def stats(self):
        """List of per-step dicts (``iterations``, ``residuals``, ``wall_time``, ...)."""
        self._trim()
        return self._stats

    @property
    def contacts(self):
        """List of per-step contact point tables (``{}`` without contact)."""
        self._trim()
        return self._contacts

    @property
    def extra(self):
        """Dict ``name -> list`` of per-step values (``None`` where a step has none)."""
        self._trim()
        return self._extra

    @property
    def path(self):
        """How the steps were taken: ``"load"`` (pseudo-time steps: ``times`` strictly increase) or
        ``"arc-length"`` (along the equilibrium path: ``t`` may go back past a limit point), as
        ``resume["path"]`` records it (absent: ``"load"``)."""
        return self.resume.get("path", "load") if isinstance(self.resume, dict) else "load"

    @property
    def n_steps(self):
        return self._n - 1

    def __len__(self):
        """Number of recorded steps (``n_steps + 1``)."""
        return self._n

    def _step(self, step):
        n = self._n
        if isinstance(step, (bool, np.bool_)) or int(step) != step or not -n <= step < n:
            raise InputError(f"Solution: step {step!r} out of range (the solution has steps 0..{n - 1})")
        return int(step) % n

    def _node(self, node):
        nn = self._arrays["poses"].chunks[0].shape[1] if self._n else 0
        if isinstance(node, (bool, np.bool_)) or int(node) != node or not 0 <= node < nn:
            raise InputError(f"Solution: unknown node id {node!r} (nodes 0..{nn - 1})")
        return int(node)

    def step(self, k=-1):
        """Step ``k`` as a ``Step`` record (views into the solution's arrays)."""
        k = self._step(k)
        return Step(k, float(self.times[k]), self.poses[k], self.reactions[k], self.section_forces[k],
                    self.strains[k], self.stats[k], self.contacts[k],
                    {name: v[k] for name, v in self.extra.items() if v[k] is not None})

    def pose(self, node, step=-1):
        """Pose ``(4, 4)`` of ``node`` at ``step``."""
        return self.poses[self._step(step)][self._node(node)].copy()

    def position(self, node, step=-1):
        """Global position ``(3,)`` of ``node`` at ``step``."""
        return self.poses[self._step(step)][self._node(node), :3, 3].copy()

    def rotation(self, node, step=-1):
        """Rotation ``(3, 3)`` (section axes as columns) of ``node`` at ``step``."""
        return self.poses[self._step(step)][self._node(node), :3, :3].copy()

    def reaction(self, node, step=-1):
        """Global force and moment ``(6,)`` exerted by the support on ``node`` (moment about the node)."""
        return self.reactions[self._step(step)][self._node(node)].copy()

    def displacement(self, step=-1):
        """Node displacements ``(n, 3)`` at ``step`` from step 0."""
        P = self.poses
        return P[self._step(step)][:, :3, 3] - P[0][:, :3, 3]

    def cut_resultant(self, beams, position, axis=(0.0, 0.0, 1.0), origin=(0.0, 0.0, 0.0), point=None,
                      bending_axis=(0.0, 1.0, 0.0), step=-1):
        """Axial force, torque and bending moments across the material cut ``(x_ref - origin) . axis =
        position`` through ``beams`` at ``step`` (``None``: every step): ``resultants.cut_resultant``."""
        from .resultants import cut_resultant
        return cut_resultant(self, beams, position, axis, origin, point, bending_axis, step)

    def contact(self, step=-1):
        """Per active contact point: dict of arrays (empty when the scene has no contact)."""
        return self.contacts[self._step(step)]

    def equivalent_strain(self, step=-1):
        """Largest von Mises equivalent surface strain ``(n_el,)`` of every element at ``step``
        (axial, bending, torsion and transverse shear; ``beamsolver.model.material_range``)."""
        return _utilisation(self.strains[self._step(step)], self.description["eps0"],
                            _properties(self.description))[0]

    def utilisation(self, step=-1):
        """Utilisation ``(n_el,)`` of every element at ``step``: von Mises surface stress over the
        section's ``yield_stress``, or equivalent strain over its ``yield_strain``, or the
        equivalent strain itself for a section without a limit (``beamsolver.model.material_range``)."""
        return _utilisation(self.strains[self._step(step)], self.description["eps0"],
                            _properties(self.description))[1]

    def material_summary(self):
        """One line: the largest equivalent surface strain over all steps and elements, where it
        occurs, and the largest utilisation of the sections given a limit (``material_range``)."""
        d = self.description
        props = _properties(d)
        eq, u = _utilisation(self.strains, d["eps0"], props)
        if eq.size == 0:
            return "material range: no elements"
        k, e = np.unravel_index(int(np.argmax(eq)), eq.shape)
        b = int(d["element_beam"][e])
        name = str(d["beam_name"][b]) or f"beam {b}"
        first = int(np.flatnonzero(np.asarray(d["element_beam"]) == b)[0])
        text = (f"material range: largest equivalent surface strain {eq[k, e]:.3g} ({name!r} element "
                f"{e - first}, step {k})")
        limited = np.isfinite(props[3]) | np.isfinite(props[4])
        if limited.any():
            um = float(u[:, limited].max())
            text += f"; utilisation of the sections' limits up to {um:.3g} ({'within' if um <= 1 else 'BEYOND'} range)"
        else:
            text += "; no section has a limit"
        return text

    def modes(self, step=-1):
        """``(eigenvalues (k,), modes (k, n_nodes, 6))`` recorded at ``step`` by ``solve(modes=k)``:
        the lowest eigenvalues of the scaled tangent and each mode's global displacement and
        rotation vector per node (unit-free size 1, ``bifurcation``); ``k = 0`` where none were."""
        s = self.stats[self._step(step)]
        n = self.poses.shape[1]
        lam = np.asarray(s.get("mode_eigenvalues", ()), dtype=float)
        return lam, np.asarray(s.get("modes", np.zeros((0, n, 6))), dtype=float).reshape(len(lam), n, 6)

    @property
    def status(self):
        """``"converged"`` (every step converged, the final state an equilibrium), ``"off-equilibrium"``
        (the run reached its end off equilibrium: ``off_equilibrium``) or ``"stopped"`` (a
        ``ConvergenceError`` or an interruption)."""
        if self.converged:
            return "converged"
        return "off-equilibrium" if self.off_equilibrium else "stopped"

    def mark_off_equilibrium(self, text):
        """Record that the final state is not an equilibrium of the model, ``text`` saying why."""
        self.converged, self.off_equilibrium = False, True
        self.message = text if not self.message else self.message + "; " + text

    @property
    def iterations(self):
        return np.array([s.get("iterations", 0) for s in self.stats])

    def summary(self):
        """One line: steps (step 0 not counted), Newton iterations (step 0's included and named: the same
        total a script summing ``stats[k]["iterations"]`` prints), cut-backs, wall time."""
        it = self.iterations
        wall = sum(s.get("wall_time", 0.0) for s in self.stats)
        end = f"{self.times[-1]:.6g}" if self._n else "-"
        first = f" ({int(it[0])} at step 0)" if len(it) and it[0] else ""
        return (f"{self.n_steps} steps to t = {end}, Newton iterations "
                f"total {int(it.sum())}{first}, max {int(it.max(initial=0))}, "
                f"cut-backs {sum(s.get('cutbacks', 0) for s in self.stats)}, wall time {wall:.3f} s")

    def __repr__(self):
        return f"Solution({self.summary()})"
