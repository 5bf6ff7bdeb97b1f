"""Kinks of the loading path: where the prescribed motions, ``fix`` values or load factors turn back or start or
stop (the reversals of a cyclic history, a bending that starts after a pull).

The step after a kink meets a new regime (contact points that slid stick again, friction that starts) and the
size the steps before it grew to may not carry it: on the strand bending cycle the user's step failed twice at
each reversal (8-9 s of CPU each) before a quarter of it converged.  ``stepping.steps.Run`` starts the step after
a kink at the size that converged after the last kink (``kink_size``), the first at ``FIRST`` times the step."""
import numpy as np

__all__ = ["drive", "kink", "ZERO"]

ZERO = 1e-12            # a part's increment below this times its size (at least 1) counts as none
FIRST = 1.0             # the first kink of a run (no size known yet) where a motion starts: this share of the step


def drive(system, t):
    """What drives the model at ``t``: ``(poses of the prescribed nodes, fix values, load factors)``, flat arrays."""
    poses = system.prescribed_poses(t).ravel() if len(system.prescribed_nodes) else np.zeros(0)
    fixed = np.array([float(f(t)) for _, _, f in system.fix_values]) if system.fix_values else np.zeros(0)
    loads = system.load_factors(t) if len(system.load_scales) else np.zeros(0)
    return poses, fixed, loads


def kink(system, t0, t1, t2, before=None):
    """Whether the loading path kinks at ``t1`` between the steps ``t0 -> t1`` and ``t1 -> t2``: for some part
    of ``drive`` the increment turns back (``a . b <= 0`` with both non-zero) or starts or stops.
    ``before``: ``drive(system, t0)`` and ``drive(system, t1)`` if known.  Returns ``"start"`` where a prescribed
    motion or ``fix`` value starts to move (from rest), ``"kink"`` for any other kink, ``None`` for none."""
    d0, d1 = before if before is not None else (drive(system, t0), drive(system, t1))
    d2 = drive(system, t2)
    found = None
    for part, (x0, x1, x2) in enumerate(zip(d0, d1, d2)):
        if not len(x1):
            continue
        a, b = x1 - x0, x2 - x1
        tol = ZERO * max(1.0, float(np.abs(x1).max()))
        on_a, on_b = np.abs(a).max() > tol, np.abs(b).max() > tol
        if on_b and not on_a and part < 2:
            return "start"
        if on_a != on_b or (on_a and float(a @ b) <= 0.0):
            found = "kink"
    return found
