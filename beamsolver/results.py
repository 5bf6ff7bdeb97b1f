"""The ``Solution`` of a solve: poses, reactions, section forces and statistics per converged step.

A ``Solution`` also carries a plain description of its model (``describe_model``:
arrays only, enough to redraw and summarise it without the ``Model``), the
stepping state needed to restart (``resume``) and, for scenes with contact,
the committed contact history of the last step.  ``save`` writes it all to a
versioned ``.npz`` file (``beamsolver.io.archive``); ``beamsolver.load`` reads it.
"""
import numpy as np

from .errors import InputError

__all__ = ["Solution", "describe_model", "load"]


def load(path):
    """Read a ``Solution`` written by ``Solution.save`` (``model`` and ``system`` are ``None``).

    ``path``: the ``.npz`` file (the suffix may be left out) or an output folder holding
    ``solution.npz``; a file that is not such an archive, or is damaged, raises ``InputError``
    naming it (``io.archive.read``).
    """
    from .io.archive import read
    fields = read(path)
    sol = Solution(None, None, fields.pop("description"))
    for name, value in fields.items():
        setattr(sol, name, value)
    return sol


def describe_model(model, system=None):
    """Arrays describing ``model`` for drawing and summaries (no callables, no objects).

    ``poses0`` (n, 4, 4); ``enodes`` (n_el, 2); ``L`` (n_el,); ``eps0`` (n_el, 6);
    ``element_beam`` (n_el,); ``node_beam`` (n,) (-1 for nodes of ``add_node``);
    ``beam_first_node``, ``beam_n_nodes``, ``beam_radius`` (n_beams,); ``beam_C``
    (n_beams, 6, 6); ``beam_name`` (str); ``constrained_nodes`` and
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
        beam_name=np.array([b.name or "" for b in beams], dtype=str),
        beam_element=np.array([b.element_type.name for b in beams], dtype=str),
        constrained_nodes=np.array([c[0] for c in cons], dtype=np.int64),
        constraint_kind=np.array([c[1][0] for c in cons], dtype=str),
        load_nodes=np.array([ld.node for ld in model.loads], dtype=np.int64),
        joins=np.array(model.joins, dtype=np.int64).reshape(-1, 2),
        n_contact_declarations=np.int64(len(model.contacts)))


class Solution:
    """Results at every converged pseudo-time step (step 0: the state at ``t_start``, see ``solve``).

    Attributes: ``times`` ``(n_steps + 1,)``; ``poses`` ``(n_steps + 1, n_nodes, 4, 4)``;
    ``reactions`` ``(n_steps + 1, n_nodes, 6)`` global force and moment on every
    node (non-zero on constrained nodes); ``section_forces`` and ``strains``
    ``(n_steps + 1, n_elements, 6)`` in the section frame, ``strains`` the element
    strain ``h / L`` itself, reference included (``(1, 0, 0, 0, 0, 0)`` for a straight
    beam at rest), so ``section_forces = C (strains - description["eps0"])``; the
    VTU field ``strain`` is that difference (``io.lines``); ``stats`` a list of
    dicts per step (``iterations``, ``residuals``, ``wall_time``, ``dt``,
    ``cutbacks``; ``failed_dt``, the sizes of the failed attempts, after a cut-back);
    ``contacts`` a list per step of contact point tables.

    ``description``: arrays describing the model (``describe_model``);
    ``resume``: the stepping state after the last step (``t0``, ``t_end``,
    ``steps``, ``dt``, ``easy``, ``failed``, ``wait``: ``stepping.next_step``), used by
    ``solve(..., restart=)``;
    ``contact_state``: committed history of the contributions (contact, ...) at the
    last step (dict of arrays, keys ``name/key``: ``Problem.get_state``; empty
    without any).  ``model`` and ``system`` are ``None`` for
    a loaded solution.
    """

    def __init__(self, model, system=None, description=None):
        self.model = model
        self.system = system
        self._description = description
        self._times, self._poses, self._reactions = [], [], []
        self._sigma, self._strain, self.stats, self.contacts = [], [], [], []
        self.converged = True
        self.message = ""
        self.resume = {}
        self.contact_state = {}

    @property
    def description(self):
        if self._description is None:
            self._description = describe_model(self.model, self.system)
        return self._description

    def save(self, path):
        """Write every step, the statistics, contact data and model description to ``path`` (.npz).

        The file is written under a temporary name and renamed, so ``path`` is
        always a complete file.  Read it back with ``beamsolver.load``; the
        format is documented in ``beamsolver.io.archive``.
        """
        from .io.archive import save
        return save(self, path)

    def copy_steps(self, model=None, system=None):
        """A new ``Solution`` of ``model``/``system`` holding (copies of the lists of) these steps."""
        new = Solution(model, system, self._description if model is None else None)
        for name in ("_times", "_poses", "_reactions", "_sigma", "_strain", "stats", "contacts"):
            setattr(new, name, list(getattr(self, name)))
        new.resume = dict(self.resume)
        new.contact_state = dict(self.contact_state)
        new.converged, new.message = self.converged, self.message
        return new

    def append(self, t, H, reactions, sigma, strain, stats, contact=None):
        self._times.append(float(t))
        self._poses.append(np.array(H))
        self._reactions.append(np.array(reactions))
        self._sigma.append(np.array(sigma))
        self._strain.append(np.array(strain))
        self.stats.append(stats)
        self.contacts.append(contact if contact is not None else {})

    @property
    def times(self):
        return np.array(self._times)

    @property
    def poses(self):
        return np.array(self._poses)

    @property
    def reactions(self):
        return np.array(self._reactions)

    @property
    def section_forces(self):
        return np.array(self._sigma)

    @property
    def strains(self):
        return np.array(self._strain)

    @property
    def n_steps(self):
        return len(self._times) - 1

    def _step(self, step):
        n = len(self._times)
        if not -n <= step < n:
            raise InputError(f"Solution: step {step} out of range (the solution has steps 0..{n - 1})")
        return step

    def _node(self, node):
        nn = self._poses[0].shape[0]
        if int(node) != node or not 0 <= node < nn:
            raise InputError(f"Solution: unknown node id {node!r} (nodes 0..{nn - 1})")
        return int(node)

    def pose(self, node, step=-1):
        return self._poses[self._step(step)][self._node(node)].copy()

    def position(self, node, step=-1):
        """Global position ``(3,)`` of ``node`` at ``step``."""
        return self._poses[self._step(step)][self._node(node), :3, 3].copy()

    def rotation(self, node, step=-1):
        return self._poses[self._step(step)][self._node(node), :3, :3].copy()

    def reaction(self, node, step=-1):
        """Global force and moment ``(6,)`` exerted by the support on ``node`` (moment about the node)."""
        return self._reactions[self._step(step)][self._node(node)].copy()

    def displacement(self, step=-1):
        P = self._poses
        return P[self._step(step)][:, :3, 3] - P[0][:, :3, 3]

    def contact(self, step=-1):
        """Per active contact point: dict of arrays (empty when the scene has no contact)."""
        return self.contacts[self._step(step)]

    def modes(self, step=-1):
        """``(eigenvalues (k,), modes (k, n_nodes, 6))`` recorded at ``step`` by ``solve(modes=k)``:
        the lowest eigenvalues of the scaled tangent and each mode's global displacement and
        rotation vector per node (unit-free size 1, ``bifurcation``); ``k = 0`` where none were."""
        s = self.stats[self._step(step)]
        n = self._poses[0].shape[0]
        lam = np.asarray(s.get("mode_eigenvalues", ()), dtype=float)
        return lam, np.asarray(s.get("modes", np.zeros((0, n, 6))), dtype=float).reshape(len(lam), n, 6)

    @property
    def iterations(self):
        return np.array([s.get("iterations", 0) for s in self.stats])

    def summary(self):
        it = self.iterations[1:]
        wall = sum(s.get("wall_time", 0.0) for s in self.stats)
        return (f"{self.n_steps} steps to t = {self._times[-1]:.6g}, Newton iterations "
                f"total {int(it.sum())}, max {int(it.max(initial=0))}, "
                f"cut-backs {sum(s.get('cutbacks', 0) for s in self.stats)}, wall time {wall:.3f} s")

    def __repr__(self):
        return f"Solution({self.summary()})"
