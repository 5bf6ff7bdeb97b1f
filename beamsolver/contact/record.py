"""The typed record of contact pairs passed between the stages of the contact pipeline.

One row per pair: a slave point (a Gauss point of a slave element for line and
orthogonal projections, the closest point for a point pair) against one master
element.  The search fills it (broad phase -> pair rules -> projection); the
kernel parameters, the history look-up and the results read it.
"""
from dataclasses import dataclass, fields
from typing import NamedTuple

import numpy as np

__all__ = ["PairSet", "Candidates", "OPEN", "STICK", "SLIP", "STATUS_NAMES"]

# ``status`` of a point in the contact table (``ContactSystem.results``): open (no normal force),
# stick (friction holds it), slip (sliding: Coulomb friction at mu lam_N, or frictionless)
OPEN, STICK, SLIP = 0, 1, 2
STATUS_NAMES = ("open", "stick", "slip")


class Candidates(NamedTuple):
    """Element pairs from the broad phase and pair rules, arrays over ``n`` element pairs:
    slave and master elements ``e``, ``m``, their ``kind``, closest points ``xi1``, ``xi2`` (non-line
    pairs), master bounding-sphere centres ``c2`` ``(n, 3)`` and their radii plus the slave's section
    radius ``reach`` (``projection.gauss_projections``' filter of the Gauss points); ``swept``: the pairs
    are in the order of ``search.sweep_phase``, not of the distance matrix (``ContactSystem._candidates``)."""
    e: np.ndarray
    m: np.ndarray
    kind: np.ndarray
    xi1: np.ndarray
    xi2: np.ndarray
    c2: np.ndarray
    reach: np.ndarray
    swept: bool


@dataclass
class PairSet:
    """Arrays over ``P`` pairs.

    ``kind`` (frames.LINE / ORTHOGONAL / POINT), slave and master element ids ``e``, ``m``;
    ``xi1``, ``xi2``: projection parameters on them (0..1, a little past an inner node);
    ``weight``: integration weight (length); ``key``: material point identity (int64, for
    the friction history); ``gp``: Gauss point index (0 for point pairs); ``decl``: index of
    the ``add_contact`` declaration; ``nodes`` ``(P, 4)``: node ids A1, B1, A2, B2; ``R1``, ``R2``:
    radii.
    """
    kind: np.ndarray
    e: np.ndarray
    m: np.ndarray
    xi1: np.ndarray
    xi2: np.ndarray
    weight: np.ndarray
    key: np.ndarray
    gp: np.ndarray
    decl: np.ndarray
    nodes: np.ndarray
    R1: np.ndarray
    R2: np.ndarray

    def __len__(self):
        return len(self.e)

    def take(self, idx):
        """The pairs ``idx`` (index array or mask) as a new record."""
        return PairSet(**{f.name: getattr(self, f.name)[idx] for f in fields(self)})

    @staticmethod
    def concatenate(parts):
        return PairSet(**{f.name: np.concatenate([getattr(p, f.name) for p in parts]) for f in fields(PairSet)})
