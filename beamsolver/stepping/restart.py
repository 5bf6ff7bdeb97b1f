"""Continuing a run: the saved solution to start from and the contact history to carry over.

``solve(model, ..., restart=solution_or_path)`` continues from the last step of a
``Solution`` of the same model.  What makes the continued run identical to an
uninterrupted one: the poses of the last step (exact copies), the stepping
state (``Solution.resume``) and, for contact, the committed friction history,
augmented-Lagrangian multipliers and point set (``Solution.contact_state``).
"""
import numpy as np

from ..errors import InputError
from ..results.solution import Solution, load

__all__ = ["restart_from", "contact_snapshot", "contact_restore"]


def contact_snapshot(contact):
    """Committed history (flat dict of arrays) for saving and restart: ``contact.get_state()``
    (a contact system or a ``problem.Problem``)."""
    return dict(contact.get_state())


def contact_restore(contact, state):
    """Give ``contact`` (a contact system or a ``problem.Problem``) the state
    ``contact_snapshot`` took: ``contact.set_state(state)``."""
    contact.set_state(dict(state))


def restart_from(restart, model, problem):
    """The ``Solution`` to continue (a copy bound to ``model``) from a Solution or a saved file;
    ``problem`` (``problem.Problem``) takes the committed history of its last step."""
    system = problem.system
    if not isinstance(restart, Solution):
        restart = load(restart)
    if not len(restart.times):
        raise InputError("solve: the restart solution has no steps")
    H = restart.poses[-1]
    P0 = restart.description["poses0"]
    if H.shape[0] != model.n_nodes or P0.shape != system.poses0.shape or \
            np.abs(P0 - system.poses0).max() > 1e-9 * system.length_scale:
        raise InputError(f"solve: the restart solution ({H.shape[0]} nodes) does not belong to this model "
                         f"({model.n_nodes} nodes, or other reference poses)")
    sol = restart.copy_steps(model, system)
    sol.converged, sol.message, sol.off_equilibrium = True, "", False
    if sol.contact_state:
        contact_restore(problem, sol.contact_state)
    return sol
