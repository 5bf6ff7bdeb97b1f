"""Contact options of one ``Model.add_contact`` declaration as one validated, typed object.

``ContactOptions.from_dict`` takes the keyword options (checked by
``validation.check_contact_options``, which refuses unknown names and bad values
with an ``InputError`` naming them) and fills the defaults, which live here
only.  Lengths are in model units; ``None`` means "derived per pair" where
stated.
"""
from dataclasses import asdict, dataclass
from typing import Any, Optional

import numpy as np

from ..model.validation import check_contact_options

__all__ = ["ContactOptions", "SMOOTHING", "SLIP_TOLERANCE", "STICK_TOLERANCE", "LINE_ANGLE", "ADJUST"]

SMOOTHING = 1e-6          # default smoothing gap of the normal law / (R1 + R2) (benchmarks/touching_defaults.py)
SLIP_TOLERANCE = 0.005    # elastic slip at the onset of sliding / slave element length (Abaqus' default)
STICK_TOLERANCE = 1e-8    # weighted slip of a sticking node / (R1 + R2) with stick="exact"
LINE_ANGLE = float(np.deg2rad(20.0))   # below this crossing angle: line contact (search.py, rule 1)
ADJUST = 1e-3             # default overclosure adjusted away at the reference poses / (R1 + R2)
                          # (chords of a polyline on a post: 1.1e-4 at R1 + R2 = 1.02; docs/theory_adjust.md)


@dataclass(frozen=True)
class ContactOptions:
    """``smoothing``: gap over which the normal law is made C1 (None: ``SMOOTHING (R1 + R2)`` for
    line contact, 0 for point and orthogonal pairs);
    ``gauss_points`` per slave element; ``penalty_t``: tangential penalty, force / length^3
    (None: from ``slip_tolerance``); ``slip_tolerance``: elastic slip at the onset of sliding /
    slave element length; ``tolerance``: penetration enabling augmented-Lagrangian updates
    (None: pure penalty); ``line_angle`` [rad], ``point_ratio``: the search's kind rules;
    ``margin``: search margin (None: twice the largest radius); ``law``: the contact law of the
    compiled kernel, a ``law.ContactLaw`` (None: ``law.PENALTY_COULOMB``, the penalty /
    augmented-Lagrangian / smoothed normal law with Coulomb friction); ``adjust``: largest
    overclosure at the reference poses taken as touching, strain-free (None: ``ADJUST (R1 + R2)``
    per pair; 0: none; ``contact.adjust``);
    ``stick``: ``"penalty"`` (a tangential penalty per Gauss point, the elastic slip set by
    ``slip_tolerance`` or ``penalty_t``) or ``"exact"`` (mortar nodal multipliers on the slave
    beam, ``contact/mortar.py``, iterated by augmented-Lagrangian updates until every sticking
    node's weighted slip is below ``stick_tolerance``; ``penalty_t`` is then only the
    augmentation penalty, force / length^2, default the normal penalty);
    ``stick_tolerance``: that slip, a length (None: ``STICK_TOLERANCE (R1 + R2)`` of the largest
    radii of the declaration)."""
    smoothing: Optional[float] = None
    gauss_points: int = 5
    penalty_t: Optional[float] = None
    slip_tolerance: float = SLIP_TOLERANCE
    tolerance: Optional[float] = None
    line_angle: float = LINE_ANGLE
    point_ratio: float = 0.5
    margin: Optional[float] = None
    law: Optional[Any] = None
    adjust: Optional[float] = None
    stick: str = "penalty"
    stick_tolerance: Optional[float] = None

    @classmethod
    def from_dict(cls, options, owner="add_contact"):
        """Validated options from ``add_contact``'s keyword arguments (defaults filled)."""
        return cls(**check_contact_options(dict(options), owner))

    def as_dict(self):
        out = asdict(self)
        out["law"] = self.law                 # the law itself, not a dict of its fields
        return out
