"""Continuing a run: the saved solution to start from and the contact history to carry over.

``solve(model, ..., restart=solution_or_path)`` continues from the last step of a
``Solution`` of the same model.  What makes the continued run identical to an
uninterrupted one: the poses of the last step (exact copies), the stepping
state (``Solution.resume``) and, for contact, the committed friction history,
augmented-Lagrangian multipliers and point set (``Solution.contact_state``).
"""
import numpy as np

from .errors import InputError

__all__ = ["restart_from", "contact_snapshot", "contact_restore"]


def contact_snapshot(contact):
    """Committed contact history (flat dict of arrays) for saving and restart.

    Uses ``contact.get_state()`` when the contact system offers it, else its
    committed history, multipliers and last point set (whatever of them exists).
    """
    if hasattr(contact, "get_state"):
        return dict(contact.get_state())
    out = {}
    hist = getattr(contact, "_history", None)
    if isinstance(hist, dict):
        out.update({f"history.{k}": v for k, v in hist.items()})
    mult = getattr(contact, "_mult_committed", None)
    if isinstance(mult, tuple) and len(mult) == 2:
        out["mult_keys"], out["mult_values"] = mult
    if getattr(contact, "_prev_points", None) is not None:
        out["prev_points"] = contact._prev_points
    return out


def contact_restore(contact, state):
    if hasattr(contact, "set_state"):
        contact.set_state(dict(state))
        return
    hist = {k[8:]: np.asarray(v) for k, v in state.items() if k.startswith("history.")}
    if hist:
        contact._history = hist
    if "mult_keys" in state:
        contact._mult_committed = (np.asarray(state["mult_keys"]), np.asarray(state["mult_values"]))
        contact._mult = contact._mult_committed
    if "prev_points" in state:
        contact._prev_points = np.asarray(state["prev_points"])


def restart_from(restart, model, system):
    """The ``Solution`` to continue (a copy bound to ``model``) from a Solution or a saved file."""
    if not hasattr(restart, "_poses"):
        from .results import load
        restart = load(restart)
    if not restart._times:
        raise InputError("solve: the restart solution has no steps")
    H = restart._poses[-1]
    P0 = restart.description["poses0"]
    if H.shape[0] != model.n_nodes or P0.shape != system.poses0.shape or \
            np.abs(P0 - system.poses0).max() > 1e-9 * system.length_scale:
        raise InputError(f"solve: the restart solution ({H.shape[0]} nodes) does not belong to this model "
                         f"({model.n_nodes} nodes, or other reference poses)")
    sol = restart.copy_steps(model, system)
    sol.converged, sol.message = True, ""
    if system.contact is not None and sol.contact_state:
        contact_restore(system.contact, sol.contact_state)
    return sol
