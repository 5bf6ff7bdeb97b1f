"""Prescribed motions as continuous paths: how far a step may go before a rotation is ambiguous.

The solver reaches a prescribed pose through the logarithm of the rotation
from the current pose to the target, which only sees angles in ``[0, pi]``: a
motion turning by ``2 pi`` in one step looks like no motion, by ``1.5 pi``
like ``0.5 pi`` the other way round.  So each step is sampled at
``SAMPLES`` irregularly spaced pseudo-times (irregular, so that no steady
rotation can turn by whole turns between every pair of samples) and the
rotation along the sampled path is kept below ``MAX_MOTION_ROTATION``: then
the end-to-end rotation of the step is below it too, and equal to the path
the user described.  ``fix(..., values=)`` rotations are angles about a fixed
axis and are summed as such (no wrapping).
"""
import numpy as np

__all__ = ["MAX_MOTION_ROTATION", "SAMPLES", "path_rotation", "limit_step"]

MAX_MOTION_ROTATION = 0.6 * np.pi     # largest prescribed rotation followed within one step
SAMPLES = np.array([0.0, 0.11, 0.26, 0.37, 0.53, 0.64, 0.79, 0.91, 1.0])
MAX_SPLITS = 60                       # bound of the step-shortening loop


def _angle(R):
    return np.arccos(np.clip(0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0), -1.0, 1.0))


def path_rotation(system, t0, t1):
    """Largest rotation ``(rad)`` of any prescribed node along its motion from ``t0`` to ``t1``.

    ``prescribe`` motions: the sum of the angles between the rotations sampled at
    ``SAMPLES``; ``fix(values=)`` rotations: the sum of the angle changes.
    """
    ts = t0 + (t1 - t0) * SAMPLES
    worst = 0.0
    for node in system.prescribed_nodes:
        motion = system.motions[node]
        R = np.array([np.asarray(motion(t), dtype=float)[:3, :3] for t in ts])
        if not np.all(np.isfinite(R)):
            return np.inf
        steps = _angle(np.swapaxes(R[:-1], 1, 2) @ R[1:])
        worst = max(worst, float(steps.sum()))
    for _, comp, f in system.fix_values:
        if comp >= 3:
            a = np.array([float(f(t)) for t in ts])
            worst = max(worst, float(np.abs(np.diff(a)).sum()))
    return worst


def limit_step(system, t, t_next):
    """The end ``t_next' <= t_next`` of a step from ``t`` over which prescribed rotations stay
    below ``MAX_MOTION_ROTATION`` along their path; ``(t_next', rotation over the step)``."""
    if not (len(system.prescribed_nodes) or any(c >= 3 for _, c, _ in system.fix_values)):
        return t_next, 0.0
    for _ in range(MAX_SPLITS):
        rot = path_rotation(system, t, t_next)
        if rot <= MAX_MOTION_ROTATION:
            return t_next, rot
        t_next = t + (t_next - t) * (0.9 * MAX_MOTION_ROTATION / rot if np.isfinite(rot) else 0.5)
    return t_next, path_rotation(system, t, t_next)
