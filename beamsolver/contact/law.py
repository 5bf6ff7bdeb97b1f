"""Contact laws, batched over contact points (THEORY.md section 6).

Complex inputs are allowed (complex-step tangents): every branch is decided on
the real part, arithmetic stays analytic.
"""
import numpy as np

__all__ = ["normal_force", "coulomb_return_mapping", "default_penalty"]


def normal_force(gap, penalty, multiplier=0.0):
    """Penalty / augmented-Lagrangian normal traction ``<multiplier - penalty g>`` (>= 0)."""
    trial = multiplier - penalty * gap
    active = np.real(trial) >= 0.0   # touching (g = 0) counts: it carries stiffness
    return np.where(active, trial, 0.0 * trial), active


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
