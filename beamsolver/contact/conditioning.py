"""How far a contact penalty is from the stiffness of the beams it couples (docs/theory_contact_tolerances.md).

A penalty ``eps_N`` (force / length^2) gives a slave element of length ``L_e`` in contact a
normal stiffness of about ``eps_N L_e``; the element's own axial stiffness is ``EA / L_e``.
Their ratio ``rho = eps_N L_e^2 / EA`` (largest over the declaration's elements) measures how
many digits the penalty takes from the tangent: above ``ILL_CONDITIONED_PENALTY`` the linear
solves lose them and Newton stalls at the round-off floor; the default penalty (the softer
section's Young's modulus, ``law.default_penalty``) gives ``rho = L_e^2 / (pi r^2)``, of order 1-100.
A penalty ``STIFF_PENALTY`` times its default or more also makes the contact forces jump with
penetrations of round-off size (slow Newton, cut-backs) at any ``rho``: a failed solve names it.
"""
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import ConditioningWarning
from .law import default_penalty

__all__ = ["PenaltyRatio", "penalty_ratios", "stiff_penalty_hint", "warn_ill_conditioned",
           "ILL_CONDITIONED_PENALTY", "STIFF_PENALTY"]

ILL_CONDITIONED_PENALTY = 1e6    # eps_N L_e^2 / EA above which solve warns (ConditioningWarning)
STIFF_PENALTY = 100.0            # penalty / its default from which a failed solve names the penalty


@dataclass(frozen=True)
class PenaltyRatio:
    """One ``add_contact`` declaration: its index, penalty, default penalty and
    ``rho = max eps_N L_e^2 / EA`` over its slave and master elements, reached on ``beam``."""
    index: int
    penalty: float
    default: float
    rho: float
    beam: object

    def text(self):
        return (f"add_contact no. {self.index} has penalty {self.penalty:.3g} ({self.penalty / self.default:.3g} "
                f"times its default {self.default:.3g}); penalty x L_e against EA / L_e of {self.beam!r}: "
                f"{self.rho:.3g}")


def penalty_ratios(model, system):
    """``PenaltyRatio`` of every contact declaration of ``model`` (``system``: its ``assembly.System``,
    element lengths ``L`` and sections ``C``)."""
    out = []
    for k, d in enumerate(model.contacts):
        beams = d.slave + d.master
        default = min(default_penalty(a.section, b.section) for a in beams for b in beams)
        penalty = default if d.penalty is None else float(d.penalty)
        rho = [penalty * np.max(system.L[b.elements] ** 2 / system.C[b.elements, 0, 0]) for b in beams]
        j = int(np.argmax(rho))
        out.append(PenaltyRatio(k, penalty, default, float(rho[j]), beams[j]))
    return out


def stiff_penalty_hint(ratios):
    """The tail of a ``ConvergenceError`` naming the stiffest penalty of ``ratios`` when it is
    ``STIFF_PENALTY`` times its default or ``rho`` passes ``ILL_CONDITIONED_PENALTY``; else ``""``."""
    stiff = [r for r in ratios if r.rho > ILL_CONDITIONED_PENALTY or r.penalty >= STIFF_PENALTY * r.default]
    if not stiff:
        return ""
    r = max(stiff, key=lambda r: (r.rho, r.penalty / r.default))
    more = f" (and {len(stiff) - 1} more declarations)" if len(stiff) > 1 else ""
    why = "makes the contact forces jump with penetrations of round-off size"
    if r.rho > ILL_CONDITIONED_PENALTY:
        why += f" and leaves the tangent ill-conditioned (above {ILL_CONDITIONED_PENALTY:.0e})"
    return f"; {r.text()}{more}: a penalty this stiff {why}: lower it towards its default"


def warn_ill_conditioned(ratios):
    """Warn (``ConditioningWarning``) once if a penalty of ``ratios`` has ``rho > ILL_CONDITIONED_PENALTY``."""
    bad = [r for r in ratios if r.rho > ILL_CONDITIONED_PENALTY]
    if not bad:
        return
    r = max(bad, key=lambda r: r.rho)
    more = f" (and {len(bad) - 1} more declarations)" if len(bad) > 1 else ""
    warnings.warn(f"solve: {r.text()}{more}, above {ILL_CONDITIONED_PENALTY:.0e}: the tangent is ill-conditioned "
                  "and Newton may stall at its round-off floor; lower the penalty", ConditioningWarning,
                  stacklevel=3)
