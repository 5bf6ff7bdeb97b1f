"""The ``Solution`` of a solve: poses, reactions, section forces and statistics per converged step."""
import numpy as np

from .errors import InputError

__all__ = ["Solution"]


class Solution:
    """Results at every converged pseudo-time step (the initial state is step 0).

    Attributes: ``times`` ``(n_steps + 1,)``; ``poses`` ``(n_steps + 1, n_nodes, 4, 4)``;
    ``reactions`` ``(n_steps + 1, n_nodes, 6)`` global force and moment on every
    node (non-zero on constrained nodes); ``section_forces`` and ``strains``
    ``(n_steps + 1, n_elements, 6)`` in the section frame; ``stats`` a list of
    dicts per step (``iterations``, ``residuals``, ``wall_time``, ``dt``,
    ``cutbacks``); ``contacts`` a list per step of contact point tables.
    """

    def __init__(self, model, system=None):
        self.model = model
        self.system = system
        self._times, self._poses, self._reactions = [], [], []
        self._sigma, self._strain, self.stats, self.contacts = [], [], [], []
        self.converged = True
        self.message = ""

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
