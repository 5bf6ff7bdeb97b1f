"""Contact laws, batched over contact points (docs/theory.md section 7).

Complex inputs are allowed (complex-step tangents): every branch is decided on
the real part, arithmetic stays analytic.
"""
import numpy as np

__all__ = ["normal_force", "coulomb_return_mapping", "default_penalty"]


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
