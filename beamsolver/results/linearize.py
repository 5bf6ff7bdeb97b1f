"""The linearised system at a converged step: tangent stiffness, residual and DOF map.

``linearize(model, solution, step)`` re-assembles, at the poses and
pseudo-time of ``step``, exactly the matrix the Newton loop factorises
(``problem.Problem``): element tangents, follower/dead load terms and, for
scenes with contact, the contact tangent.  Unknowns are those of
``assembly``: six per representative node, body increments
``H <- H exp(hat(z))`` (translation first) for free and prescribed nodes,
global increments for nodes with a partial ``fix``.  At an equilibrium of a
conservative problem the free block ``K`` is symmetric; its eigenvalues give
the stability of the state (a zero eigenvalue at a buckling load).

Contact history (friction, augmented-Lagrangian multipliers) is the
committed one of the solution's last step when ``step`` is the last step;
for earlier steps contact points start without tangential history.
"""
from dataclasses import dataclass

import numpy as np

from ..assembly.system import GLOBAL
from ..model.model import DOF_NAMES
from ..nonlinear.problem import Problem

__all__ = ["linearize", "Linearization", "DofMap"]


@dataclass
class DofMap:
    """Where each unknown of the reduced system lives.

    ``node``, ``component`` (0..5: ``ux uy uz rx ry rz``), ``beam`` (-1 for
    nodes without elements) per free unknown; ``index`` its position
    ``6 node + component`` in the full vector; ``global_frame`` True where the
    unknown is a global-direction increment (partially fixed nodes), False
    for body-frame increments.  ``free_of(node)`` returns the reduced indices
    of a node's free unknowns.
    """
    node: np.ndarray
    component: np.ndarray
    beam: np.ndarray
    index: np.ndarray
    global_frame: np.ndarray
    n_nodes: int

    def free_of(self, node):
        return np.flatnonzero(self.node == int(node))

    def names(self):
        return [f"{DOF_NAMES[c]}@{n}" for n, c in zip(self.node, self.component)]


@dataclass
class Linearization:
    """``K`` (free x free CSR), ``r`` (free residual), ``dofs`` (``DofMap``); unpacks as ``K, r, dofs``.

    ``K_full`` and ``r_full`` cover all ``6 n`` unknowns (constrained and
    joined ones included, rows/columns of non-representative nodes empty).
    """
    K: object
    r: np.ndarray
    dofs: DofMap
    K_full: object
    r_full: np.ndarray
    t: float
    step: int

    def __iter__(self):
        return iter((self.K, self.r, self.dofs))


def linearize(model, solution, step=-1):
    """Tangent stiffness and residual of ``model`` at ``step`` of ``solution`` (a fresh or loaded one)."""
    n = len(solution)
    if isinstance(step, (bool, np.bool_)) or not isinstance(step, (int, np.integer)) or not -n <= step < n:
        from ..errors import InputError
        raise InputError(f"linearize: step {step!r} is not a step number of the solution (steps 0..{n - 1}, "
                         "or negative from the end)")
    k = int(step) % n
    problem = Problem.from_model(model, check_rigid_modes=False)
    system = problem.system
    H = np.array(solution.poses[k], dtype=float)
    if H.shape[0] != system.n_nodes:
        from ..errors import InputError
        raise InputError(f"linearize: the solution has {H.shape[0]} nodes, the model {system.n_nodes}")
    t = float(solution.times[k])
    if k == n - 1 and solution.contact_state:
        problem.set_state(solution.contact_state)
    problem.begin_step(H, t)
    ev = problem.evaluate(H, t, tangent=True)
    r = ev.r
    K = problem.tangent(ev).tocsr()
    K_full = problem.full_tangent(ev)
    free = system.free_dofs
    node, comp = free // 6, free % 6
    node_beam = solution.description["node_beam"]
    dofs = DofMap(node=node, component=comp, beam=np.asarray(node_beam)[node], index=free.copy(),
                  global_frame=system.kind[node] == GLOBAL, n_nodes=system.n_nodes)
    return Linearization(K, r[free].copy(), dofs, K_full, r, float(t), k)
