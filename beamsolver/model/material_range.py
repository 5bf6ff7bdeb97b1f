"""Material range of the sections: the largest equivalent surface strain and stress per element.

For every element the strain measured from the reference, ``e = Gamma - Gamma_0``
(``(n_el, 6)``: axial, two shears, torsion, two bendings; ``section.py``), gives at the
surface of a solid circular section of radius ``r`` (docs/theory_material_range.md):

- normal strain  ``eps   = |e_1| + r sqrt(e_5^2 + e_6^2)``   (axial plus bending),
- shear strain   ``gamma = r |e_4| + 4/3 sqrt(e_2^2 + e_3^2)``   (torsion plus the peak
  transverse shear of a circle, 4/3 of the mean, with the Timoshenko shear strain taken as
  the mean: an upper bound since the shear factor is below 1),
- von Mises stress ``sigma_eq = sqrt((E eps)^2 + 3 (G gamma)^2)`` and equivalent strain
  ``eps_eq = sigma_eq / E`` (the uniaxial strain of the same von Mises stress).

The maxima of the four parts are added as if they met at one surface point: an upper
bound, exact for each part alone.  ``r`` is the section's radius; for a non-circular section
(``Section(...)``, ``Section.rectangular``) it is the contact radius, an estimate.
``E`` and ``G`` are the section's moduli (``Section.moduli``).

The utilisation of an element is ``sigma_eq / yield_stress`` or ``eps_eq / yield_strain``
for a section given a limit, and ``eps_eq`` itself for a section without one.
"""
import logging
import warnings

import numpy as np

from ..errors import MaterialRangeWarning

log = logging.getLogger("beamsolver")

__all__ = ["surface_strains", "equivalent_strain", "element_properties", "utilisation", "RangeCheck"]


def surface_strains(e, radius):
    """Largest normal and shear strain ``(eps, gamma)``, each ``(...,)``, at the surface of a solid
    circle of ``radius`` (broadcast against ``e[..., 0]``) for strains ``e`` ``(..., 6)`` from the reference."""
    e = np.asarray(e, dtype=float)
    eps = np.abs(e[..., 0]) + radius * np.hypot(e[..., 4], e[..., 5])
    gamma = radius * np.abs(e[..., 3]) + (4.0 / 3.0) * np.hypot(e[..., 1], e[..., 2])
    return eps, gamma


def equivalent_strain(e, radius, E, G):
    """Von Mises equivalent strain ``sigma_eq / E`` ``(...,)`` of strains ``e`` ``(..., 6)``."""
    eps, gamma = surface_strains(e, radius)
    return np.sqrt(eps**2 + 3.0 * (G / E * gamma) ** 2)


def element_properties(description):
    """Per element ``(radius, E, G, yield_stress, yield_strain)``, each ``(n_el,)`` (inf: no limit),
    from a ``Solution.description``; moduli from the radius and stiffnesses when the description
    predates them (``Section.moduli``)."""
    d = description
    beam = np.asarray(d["element_beam"], dtype=np.int64)
    r = np.asarray(d["beam_radius"], dtype=float)
    C = np.asarray(d["beam_C"], dtype=float).reshape(-1, 6, 6)
    n = len(r)
    E = np.asarray(d.get("beam_E", C[:, 0, 0] / (np.pi * r**2)), dtype=float)
    G = np.asarray(d.get("beam_G", C[:, 3, 3] / (0.5 * np.pi * r**4)), dtype=float)
    sy = np.asarray(d.get("beam_yield_stress", np.full(n, np.inf)), dtype=float)
    ey = np.asarray(d.get("beam_yield_strain", np.full(n, np.inf)), dtype=float)
    return r[beam], E[beam], G[beam], sy[beam], ey[beam]


def utilisation(strains, eps0, props):
    """``(eps_eq, utilisation)``, each ``(..., n_el)``, of element strains ``(..., n_el, 6)`` (reference
    included) with ``props`` from ``element_properties``: ``sigma_eq / yield_stress``, else
    ``eps_eq / yield_strain``, else ``eps_eq``."""
    r, E, G, sy, ey = props
    eq = equivalent_strain(np.asarray(strains, dtype=float) - eps0, r, E, G)
    u = np.where(np.isfinite(sy), eq * E / np.where(np.isfinite(sy), sy, 1.0),
                 np.where(np.isfinite(ey), eq / np.where(np.isfinite(ey), ey, 1.0), eq))
    return eq, u


class RangeCheck:
    """Warns once per solve (``MaterialRangeWarning``) at the first converged step where an element
    of a section with a limit is used beyond it (utilisation > 1), naming the beam, element and
    step; records ``stats["utilisation"]`` (the largest over the limited elements) at every step.
    ``RangeCheck.of(description)`` is ``None`` when no section has a limit (no cost)."""

    def __init__(self, props, eps0, limited, element_beam, element_index, beam_names):
        self.props, self.eps0, self.limited = props, eps0, limited
        self.element_beam, self.element_index, self.beam_names = element_beam, element_index, beam_names
        self.warned = False

    @classmethod
    def of(cls, description):
        props = element_properties(description)
        limited = np.isfinite(props[3]) | np.isfinite(props[4])
        if not limited.any():
            return None
        beam = np.asarray(description["element_beam"], dtype=np.int64)
        first = np.r_[0, np.flatnonzero(np.diff(beam)) + 1]
        index = np.arange(len(beam)) - np.repeat(first, np.diff(np.r_[first, len(beam)]))
        return cls(props, np.asarray(description["eps0"], dtype=float), limited, beam, index,
                   [str(s) for s in description["beam_name"]])

    def check(self, strains, stats, step):
        """Record the largest utilisation of step ``step`` in ``stats``; warn if it exceeds 1 (once)."""
        eq, u = utilisation(strains, self.eps0, self.props)
        u = np.where(self.limited, u, 0.0)
        worst = int(np.argmax(u))
        stats["utilisation"] = float(u[worst])
        if u[worst] > 1.0 and not self.warned:
            self.warned = True
            b = int(self.element_beam[worst])
            name = self.beam_names[b] or f"beam {b}"
            text = (f"step {step}: {name!r} (beam {b}) element {int(self.element_index[worst])} leaves its "
                    f"material range: utilisation {u[worst]:.3g} (equivalent surface strain {eq[worst]:.3g}); "
                    f"{int((u > 1.0).sum())} element(s) beyond their limit")
            log.warning(text)
            warnings.warn(text, MaterialRangeWarning, stacklevel=5)
        return stats["utilisation"]
