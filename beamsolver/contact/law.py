"""Contact laws (docs/theory.md section 7): batched numpy forms and the compiled law interface.

``normal_force`` and ``coulomb_return_mapping`` are batched over contact points and
accept complex inputs (the complex-step oracle, ``reference.py``): every branch is decided
on the real part, arithmetic stays analytic.  ``ContactLaw`` bundles the scalar
compiled forms with their derivatives (``penalty_normal``, ``coulomb``, tested equal to
the numpy forms) that the compiled kernel calls; a new law is a new ``ContactLaw``,
no kernel edit (``kernel_jit.make_kernel``).
"""
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .._jit import jit

__all__ = ["normal_force", "coulomb_return_mapping", "default_penalty", "ContactLaw", "penalty_normal",
           "coulomb", "PENALTY_COULOMB", "PENALTY_T_MIN"]

PENALTY_T_MIN = 1e-3     # floor of lam_N in the slip-tolerance stick stiffness, / (normal penalty x elastic slip)


def normal_force(gap, penalty, multiplier=0.0, smoothing=0.0):
    """Penalty / augmented-Lagrangian normal traction, smoothed near first touch.

    The trial traction ``x = multiplier - penalty g`` gives ``lam = <x>`` for a sharp
    law (``smoothing = 0``).  With a smoothing gap ``w > 0`` the ramp is replaced on
    ``|x| < W = penalty w`` by the C1 parabola ``(x + W)^2 / (4 W)``: the traction
    and its derivative are continuous, contact starts at a gap ``w`` with zero force
    and zero stiffness, and traction above ``W`` is untouched.  This keeps Newton
    from cycling on points whose gap hovers at zero (two touching, lightly loaded
    beams), as the quadratic regularisation of Meier, Popp & Wall (2016).
    Returns ``(lam, active)``, ``active`` where ``lam`` (or its stiffness) is non-zero.
    """
    trial = multiplier - penalty * gap
    W = penalty * smoothing
    xr, Wr = np.real(trial), np.real(W)
    active = xr > -Wr if np.any(Wr > 0) else xr >= 0.0   # sharp: touching counts (it carries stiffness)
    safe = np.where(Wr > 0, W, 1.0)
    parab = (trial + W) ** 2 / (4.0 * safe)
    lam = np.where(xr >= Wr, trial, np.where(active, parab, 0.0 * trial))
    return lam, active


def coulomb_return_mapping(lam_trial, mu, lam_n):
    """Return mapping onto the Coulomb disk of radius ``mu lam_n``.

    ``lam_trial``: ``(..., 2)`` trial tangential traction.  Returns
    ``(lam_t, stick)``; in slip ``lam_t = mu lam_n lam_trial / |lam_trial|``.
    """
    norm = np.sqrt(np.sum(lam_trial * lam_trial, axis=-1))
    limit = mu * lam_n
    stick = np.real(norm) <= np.real(limit)
    safe = np.where(stick, 1.0, norm)
    slip = (limit / safe)[..., None] * lam_trial
    return np.where(stick[..., None], lam_trial, slip), stick


def default_penalty(section_a, section_b):
    """Default normal penalty per unit length (force / length^2).

    The effective Young's modulus ``EA / (pi r^2)`` of the softer section: the
    order of the Hertzian line-contact stiffness, so the penetration under a
    line load ``q`` is about ``q / E``, independent of the mesh.
    """
    e = [s.C[0, 0] / (np.pi * s.radius**2) for s in (section_a, section_b)]
    return float(min(e))


# ---------------------------------------------------------------- the law interface of the compiled kernel
@dataclass(frozen=True)
class ContactLaw:
    """A contact law for the compiled kernel (``kernel_jit.make_kernel`` builds a kernel from it).

    ``normal(gap, penalty, multiplier, smoothing) -> (lam, dlam_dgap, active)``: normal traction per
    unit weight, its derivative with respect to the gap and whether the point carries force or
    stiffness (a gap within round-off above zero arrives as 0: ``reference.touching_gap``); ``tangential(trial0, trial1, Dtrial, mu, lam, Dlam) -> (lt0, lt1, D, stick)``:
    tangential traction from the trial ``(trial0, trial1)`` (in ``t1, t2``) in forward mode, ``D``
    ``(2, k)`` its gradient from the gradients ``Dtrial`` ``(2, k)`` of the trial and ``Dlam`` ``(k,)``
    of the normal traction.  Both are numba-jitted (``_jit.jit``).  ``name`` names the compiled kernel (and its numba cache entry).
    """
    name: str
    normal: Callable
    tangential: Callable


@jit
def penalty_normal(gap, penalty, multiplier, smoothing):
    """``normal_force`` for one point: penalty ``<multiplier - penalty gap>`` (augmented Lagrangian
    with a multiplier), C1 parabola on ``|x| < penalty smoothing``; ``(lam, dlam/dgap, active)``."""
    x = multiplier - penalty * gap
    W = penalty * smoothing
    if W > 0.0:
        if x >= W:
            return x, -penalty, True
        if x > -W:
            return (x + W) ** 2 / (4.0 * W), -penalty * (x + W) / (2.0 * W), True
        return 0.0, 0.0, False
    if x >= 0.0:
        return x, -penalty, True
    return 0.0, 0.0, False


@jit
def coulomb(trial0, trial1, Dtrial, mu, lam, Dlam):
    """``coulomb_return_mapping`` for one point in forward mode (``ContactLaw.tangential``): stick
    inside the disk ``|trial| <= mu lam``, else ``mu lam trial / |trial|``.  ``Dtrial`` ``(2, k)``,
    ``Dlam`` ``(k,)``: gradients of the trial traction and of ``lam``; returns ``(lt0, lt1, D, stick)``
    with ``D`` ``(2, k)`` the gradient of the traction.  In slip
    ``D = tt (mu Dlam)^T + (limit / norm) (Dtrial - tt proj^T)``, ``tt = trial / norm``,
    ``proj = tt^T Dtrial``: written column by column into ``D``, its only allocation (the
    operations and their order those of the array form, so the same bits)."""
    norm = np.sqrt(trial0 * trial0 + trial1 * trial1)
    limit = mu * lam
    if norm <= limit:
        return trial0, trial1, Dtrial, True
    t0, t1 = trial0 / norm, trial1 / norm
    s = limit / norm
    k = Dtrial.shape[1]
    D = np.empty((2, k))
    for j in range(k):
        proj = t0 * Dtrial[0, j] + t1 * Dtrial[1, j]
        dl = mu * Dlam[j]
        D[0, j] = t0 * dl + s * (Dtrial[0, j] - t0 * proj)
        D[1, j] = t1 * dl + s * (Dtrial[1, j] - t1 * proj)
    return limit * t0, limit * t1, D, False


PENALTY_COULOMB = ContactLaw("penalty_coulomb", penalty_normal, coulomb)
