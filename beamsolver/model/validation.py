"""Checks of user input: numbers, counts, poses and ``solve``'s arguments (contact options:
``model.contact_options``).

Every check raises ``InputError`` naming where the value came from (``owner``,
e.g. ``"solve"`` or ``"Section 'wire'"``), the argument and the value; none of
them lets a raw ``TypeError``/``ValueError``/``OverflowError`` from numpy out.
Numbers are Python or numpy reals (not ``bool``, not strings); counts are
integers or integral floats.
"""
import math
import numbers
import os

import numpy as np

from ..errors import InputError

__all__ = ["real", "count", "as_array", "vector", "check_pose", "check_poses", "check_node_id",
           "check_solve_arguments", "MAX_REFERENCE_ELEMENT_ROTATION", "ORTHONORMAL_TOL", "MAX_COUNT"]

# a reference element may turn by at most this much; the solver refuses iterates beyond
# solver.MAX_ELEMENT_ROTATION (0.8 pi), so a reference shape keeps some room below it
MAX_REFERENCE_ELEMENT_ROTATION = 0.75 * np.pi
ORTHONORMAL_TOL = 1e-8                # |R^T R - I| and |last row - (0, 0, 0, 1)| of a pose
MAX_COUNT = 10**6                     # elements per generated beam, load steps per solve


def _is_real(value):
    if type(value) is float or type(value) is int:    # the common case, before the ABC check
        return True
    if isinstance(value, (bool, np.bool_)):
        return False
    if isinstance(value, numbers.Real):
        return True
    return isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf"


def real(value, name, owner, *, minimum=None, above=None, maximum=None, none=False):
    """``value`` as a finite float with ``value >= minimum``, ``> above``, ``<= maximum``.

    ``none``: ``None`` is accepted (and returned).
    """
    if value is None and none:
        return None
    if minimum is not None:
        what = "a number >= " + ("0" if minimum == 0 else f"{minimum:g}")
    elif above is not None:
        what = "positive" if above == 0 else f"a number > {above:g}"
    else:
        what = "a finite number"
    if maximum is not None:
        what += f" and <= {maximum:g}"
    ok = _is_real(value) and math.isfinite(float(value))
    if ok:
        v = float(value)
        ok = ((minimum is None or v >= minimum) and (above is None or v > above)
              and (maximum is None or v <= maximum))
    if not ok:
        raise InputError(f"{owner}: {name} must be {what}, got {value!r}")
    return v


def count(value, name, owner, *, minimum=1, maximum=MAX_COUNT):
    """``value`` as an int in ``[minimum, maximum]`` (integral floats accepted)."""
    ok = _is_real(value) and math.isfinite(float(value)) and float(value) == int(value)
    if not ok or int(value) < minimum:
        kind = "a positive integer" if minimum == 1 else f"an integer >= {minimum}"
        raise InputError(f"{owner}: {name} must be {kind}, got {value!r}")
    if int(value) > maximum:
        raise InputError(f"{owner}: {name} must be at most {maximum}, got {value!r}")
    return int(value)


def as_array(value, name, owner):
    """``value`` as a float array (``InputError`` if it is not made of numbers)."""
    try:
        return np.array(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{owner}: {name} must be an array of numbers, got {value!r}") from None


def vector(value, name, owner, size=3):
    """``value`` as a finite float vector of ``size`` numbers."""
    v = as_array(value, name, owner).reshape(-1)
    if v.shape != (size,) or not np.all(np.isfinite(v)):
        raise InputError(f"{owner}: {name} must be {size} finite numbers, got {v.tolist()}")
    return v


def check_poses(P, where, what):
    """Poses ``(k, 4, 4)`` as floats: finite, rotation blocks orthonormal with ``det > 0`` and last
    rows ``(0, 0, 0, 1)`` (to ``ORTHONORMAL_TOL``; set exactly on return).

    ``where`` names the source (``"solve"``), ``what(i)`` the pose (``"initial_poses[3]"``).
    """
    H = np.array(P, dtype=float)
    finite = np.all(np.isfinite(H), axis=(1, 2))
    R = np.where(finite[:, None, None], H[:, :3, :3], np.eye(3))
    err = np.abs(np.swapaxes(R, 1, 2) @ R - np.eye(3)).max(axis=(1, 2), initial=0.0)
    det = np.linalg.det(R) if len(H) else np.zeros(0)
    row = np.abs(H[:, 3] - [0.0, 0.0, 0.0, 1.0]).max(axis=1, initial=0.0)
    bad = np.flatnonzero(~finite | (err > ORTHONORMAL_TOL) | ~(det > 0.0) | (row > ORTHONORMAL_TOL))
    if len(bad):
        i = int(bad[0])
        if not finite[i]:
            raise InputError(f"{where}: {what(i)} must be finite, got {H[i].tolist()}")
        if err[i] > ORTHONORMAL_TOL or not det[i] > 0.0:
            raise InputError(f"{where}: {what(i)} is not a rigid motion: its rotation block has "
                             f"|R^T R - I| = {err[i]:.3g}, det = {det[i]:.6g}")
        raise InputError(f"{where}: {what(i)} is not a rigid motion: its last row is {H[i, 3].tolist()}, "
                         "not (0, 0, 0, 1)")
    H[:, 3] = (0.0, 0.0, 0.0, 1.0)
    return H


def check_pose(G, where, what="pose"):
    """One pose ``G`` (a 4x4 rigid motion) as a float array; see ``check_poses``."""
    try:
        H = np.array(G, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{where}: {what} must be a 4x4 matrix of numbers, got {G!r}") from None
    if H.shape != (4, 4):
        raise InputError(f"{where}: {what} must be a 4x4 matrix, got shape {H.shape}")
    return check_poses(H[None], where, lambda i: what)[0]


def check_node_id(node, n_nodes, what):
    """A node id as an int in ``[0, n_nodes)``; bools, beams and non-integers are refused."""
    if isinstance(node, (bool, np.bool_)) or not _is_real(node) or not np.isfinite(float(node)) \
            or float(node) != int(node):
        raise InputError(f"{what}: node id must be an integer, got {node!r}")
    i = int(node)
    if not 0 <= i < n_nodes:
        raise InputError(f"{what}: unknown node id {node!r} (the model has nodes 0..{n_nodes - 1})")
    return i


class CheckedScalar:
    """``fn(t)`` checked at every call to be a finite number (``scalar_of``): a user's load
    scale or ``fix`` value that returns a string, an array or NaN at some ``t`` is an
    ``InputError`` naming it and ``t``, not a raw error or a NaN state.  ``fn``: the user's."""

    def __init__(self, fn, where):
        self.fn, self.where = fn, where

    def __call__(self, t):
        return scalar_of(self.fn, t, self.where)


def scalar_of(fn, t, where):
    """``fn(t)`` as a finite float; ``where`` names the callable (e.g. ``add_load(4): scale``)."""
    v = fn(t)
    if not _is_real(v) or not math.isfinite(float(v)):
        kind = f"an array of shape {np.shape(v)}" if isinstance(v, np.ndarray) else repr(v)
        raise InputError(f"{where}({t:.6g}) must return a finite number, got {kind}")
    return float(v)


# ------------------------------------------------------------ solve
def check_solve_arguments(model, *, steps, t_end, t_start, rtol, dtol, max_iter, min_step_ratio,
                          checkpoint, initial_poses, restart, callback=None, output=None):
    """Refuse bad ``solve`` arguments before any work (types, ranges, shapes, load scales).

    The load scales and ``fix(..., values=)`` functions are evaluated at ``t_start`` and
    ``t_end`` (they must return finite numbers); ``initial_poses`` must be ``(n_nodes, 4, 4)``
    rigid motions; ``restart``'s last saved time must not lie after ``t_end``.
    """
    # isinstance(model, model.Model) without importing model (which imports this module):
    # imports run one way (tests/test_import_direction.py)
    if not any(c.__module__ == "beamsolver.model.model" and c.__name__ == "Model" for c in type(model).__mro__):
        raise InputError(f"solve: model must be a beamsolver.Model, got {type(model).__name__}")
    count(steps, "steps", "solve")
    t0 = real(t_start, "t_start", "solve")
    t1 = real(t_end, "t_end", "solve")
    real(rtol, "rtol", "solve", above=0.0)
    real(dtol, "dtol", "solve", minimum=0.0)
    count(max_iter, "max_iter", "solve")
    real(min_step_ratio, "min_step_ratio", "solve", above=0.0, maximum=1.0)
    real(checkpoint, "checkpoint", "solve", minimum=0.0, none=True)
    if callback is not None and not callable(callback):
        raise InputError(f"solve: callback must be callable or None, got {callback!r}")
    if output is not None and not isinstance(output, (str, os.PathLike)) and not hasattr(output, "write"):
        raise InputError(f"solve: output must be a folder (str or Path), a writer or None, got {output!r}")
    if isinstance(output, (str, os.PathLike)) and not os.fspath(output).strip():
        raise InputError(f"solve: output {output!r} names no folder (give a folder name, \".\" for the "
                         "current folder, or None for no output)")
    if restart is not None and not isinstance(restart, (str, os.PathLike)) and \
            not (hasattr(restart, "times") and hasattr(restart, "poses")):
        raise InputError(f"solve: restart must be a Solution or the path of a saved one, got {restart!r}")
    if initial_poses is not None:
        _check_initial_poses(initial_poses, model.n_nodes)
    if restart is not None:
        last = _last_saved_time(restart)
        if t1 < last:
            raise InputError(f"solve: t_end = {t_end!r} is before the end of the restart solution "
                             f"(t = {last:.6g}); give t_end >= {last:.6g}")
        t0 = last
    for t in (t0, t1):                 # CheckedScalar: every later evaluation is checked too
        for ld in model.loads + model.line_loads:
            ld.scale(t)
        for fns in model.fix_values.values():
            for fn in fns.values():
                fn(t)
    if restart is not None and initial_poses is not None:
        raise InputError("solve: give either restart or initial_poses, not both")


def _check_initial_poses(P, n_nodes):
    try:
        H = np.array(P, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"solve: initial_poses must be an array of numbers of shape ({n_nodes}, 4, 4)") from None
    if H.shape != (n_nodes, 4, 4):
        raise InputError(f"solve: initial_poses must have shape ({n_nodes}, 4, 4) (one pose per node), "
                         f"got {H.shape}")
    check_poses(H, "solve", lambda i: f"initial_poses[{i}]")


def _last_saved_time(restart):
    """Last time of a restart ``Solution`` or saved file (only ``times`` is read from a file)."""
    if not isinstance(restart, (str, os.PathLike)):
        times = restart.times
        return float(times[-1]) if len(times) else -np.inf
    from ..results.solution_file import saved_times
    times = saved_times(restart)
    return float(times[-1]) if len(times) else -np.inf


def check_stability_options(modes, branch_switching, check_stability=None, stabilize=None, nonconservative=()):
    """``(modes, branch_switching)`` of ``solve`` checked: a count >= 0 and one of ``False``,
    ``True``, ``"auto"``; ``check_stability`` ``None``, ``True`` or ``False``.  Combinations that
    would do nothing are refused: ``modes``/``branch_switching`` with ``check_stability=False``,
    with ``stabilize`` (branch switching), or on a model without a potential (``nonconservative``:
    the names of its parts without one, e.g. friction)."""
    if isinstance(modes, bool) or not isinstance(modes, (int, np.integer)) or modes < 0:
        raise InputError(f"solve: modes must be a whole number >= 0 (eigenpairs per step), got {modes!r}")
    if not any(branch_switching is v or (isinstance(v, str) and branch_switching == v)
               for v in (False, True, "auto")):
        raise InputError(f"solve: branch_switching must be False, True or 'auto', got {branch_switching!r}")
    if check_stability is not None and not isinstance(check_stability, (bool, np.bool_)):
        raise InputError(f"solve: check_stability must be None (default: checked), True or False, "
                         f"got {check_stability!r}")
    asked = [f"{k}={v!r}" for k, v in (("modes", modes), ("branch_switching", branch_switching)) if v]
    if asked and check_stability is not None and not check_stability:
        raise InputError(f"solve: check_stability=False contradicts {' and '.join(asked)}, which need the "
                         "stability check of every step: drop one of them")
    if branch_switching and stabilize is not None and stabilize is not False:
        raise InputError(f"solve: branch_switching={branch_switching!r} with stabilize={stabilize!r}: two ways past "
                         "an instability, and the switch needs the undamped problem: use one of them")
    if asked and nonconservative:
        raise InputError(f"solve: {' and '.join(asked)} need a potential energy (a symmetric tangent), which this "
                         f"model does not have ({', '.join(nonconservative)}): no mode or switch would be computed")
    return int(modes), branch_switching
