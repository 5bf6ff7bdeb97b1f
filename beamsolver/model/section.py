"""Beam cross-sections: a 6x6 constitutive matrix and a contact radius.

Ordering of the matrix matches the strain ``(Gamma_1, Gamma_2, Gamma_3,
kappa_1, kappa_2, kappa_3)``: axial, two shears, torsion, two bendings, so
the diagonal is ``(EA, GA2, GA3, GJ, EI2, EI3)``.  Units are the user's
(consistent) units.

A section may carry a material range, ``yield_stress`` (von Mises, units of
stress) or ``yield_strain`` (equivalent strain, unit-free): the solver warns
when a converged step leaves it (``beamsolver.model.material_range``).  ``E`` and
``G`` are the moduli used there: given by ``circular`` and ``rectangular``,
else those of a solid circle of ``radius`` with the same ``EA`` and ``GJ``.
"""
import numpy as np

from ..errors import InputError
from .validation import real

__all__ = ["Section"]


def _positive(name, value, owner="Section"):
    return real(value, name, owner, above=0.0)


def _stiffness(owner, args, compute):
    """``compute(**args)`` (a dict of stiffnesses) in float64, each checked finite and positive.

    Products of extreme dimensions overflow to inf (or underflow to 0) without an error of their
    own; the ``InputError`` names the arguments that led there and the first bad stiffness.
    """
    with np.errstate(all="ignore"):
        vals = compute(**{k: np.float64(v) for k, v in args.items()})
    bad = [f"{k} = {float(v):g}" for k, v in vals.items() if not (np.isfinite(v) and v > 0.0)]
    if bad:
        given = ", ".join(f"{k}={v:g}" for k, v in args.items())
        raise InputError(f"{owner}: {given} give a stiffness that is not a finite positive number "
                         f"({', '.join(bad)}); check the units")
    return {k: float(v) for k, v in vals.items()}


class Section:
    """Cross-section: stiffness matrix ``C`` (6x6, symmetric positive definite) and ``radius``.

    ``Section(EA=, GA2=, GA3=, GJ=, EI2=, EI3=, radius=)`` builds a diagonal
    ``C``; ``Section.from_matrix(C, radius)`` takes a full one.  ``radius`` is
    the contact (and drawing) radius.  ``yield_stress`` [stress] or
    ``yield_strain`` [-] (at most one; default ``None``: no limit) is the
    material range checked at every converged step.
    """

    def __init__(self, EA, GA2, GA3, GJ, EI2, EI3, radius, name=None, *, yield_stress=None, yield_strain=None):
        vals = dict(EA=EA, GA2=GA2, GA3=GA3, GJ=GJ, EI2=EI2, EI3=EI3)
        owner = f"Section {name!r}" if name else "Section"
        diag = [_positive(k, v, owner) for k, v in vals.items()]
        self.C = np.diag(diag)
        self.radius = _positive("radius", radius, owner)
        self.name = name
        self._set_range(owner, yield_stress, yield_strain)

    def _set_range(self, owner, yield_stress, yield_strain, E=None, G=None):
        """Limits (``None``: none) and the moduli ``E``, ``G`` (default: a solid circle of ``radius``)."""
        if yield_stress is not None and yield_strain is not None:
            raise InputError(f"{owner}: give yield_stress or yield_strain, not both "
                             f"(got {yield_stress!r} and {yield_strain!r})")
        self.yield_stress = None if yield_stress is None else _positive("yield_stress", yield_stress, owner)
        self.yield_strain = None if yield_strain is None else _positive("yield_strain", yield_strain, owner)
        r = self.radius
        self.E = float(self.C[0, 0] / (np.pi * r**2)) if E is None else float(E)
        self.G = float(self.C[3, 3] / (0.5 * np.pi * r**4)) if G is None else float(G)

    @classmethod
    def from_matrix(cls, C, radius, name=None, *, yield_stress=None, yield_strain=None):
        owner = f"Section {name!r}" if name else "Section"
        try:
            C = np.array(C, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"{owner}: C must be a finite 6x6 matrix of numbers, got {C!r}") from None
        if C.shape != (6, 6) or not np.all(np.isfinite(C)):
            raise InputError(f"{owner}: C must be a finite 6x6 matrix, got shape {C.shape}")
        if not np.allclose(C, C.T, rtol=1e-12, atol=0.0):
            raise InputError(f"{owner}: C must be symmetric")
        eig = np.linalg.eigvalsh(C)
        if eig.min() <= 0.0:
            raise InputError(f"{owner}: C must be positive definite, smallest eigenvalue {eig.min():g}")
        obj = cls.__new__(cls)
        obj.C = C
        obj.radius = _positive("radius", radius, owner)
        obj.name = name
        obj._set_range(owner, yield_stress, yield_strain)
        return obj

    @classmethod
    def circular(cls, radius, E, nu=0.3, shear_factor=None, name=None, *, yield_stress=None, yield_strain=None):
        """Solid circular section of ``radius``; Young's modulus ``E``, Poisson's ratio ``nu``.

        Shear factor defaults to Cowper's ``6 (1 + nu) / (7 + 6 nu)``.  ``yield_stress`` or
        ``yield_strain``: the material range (class docstring).
        """
        r = _positive("radius", radius)
        E = _positive("E", E)
        if not (-1.0 < real(nu, "nu", "Section.circular") < 0.5):
            raise InputError(f"Section.circular: nu must lie in (-1, 0.5), got {nu!r}")
        k = 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu) if shear_factor is None else _positive("shear_factor", shear_factor)
        def compute(radius, E):
            G = E / (2.0 * (1.0 + nu))
            A = np.pi * radius**2
            I = np.pi * radius**4 / 4.0
            return dict(EA=E * A, GA2=k * G * A, GA3=k * G * A, GJ=G * 2.0 * I, EI2=E * I, EI3=E * I)
        return cls(**_stiffness("Section.circular", dict(radius=r, E=E), compute), radius=r, name=name,
                   yield_stress=yield_stress, yield_strain=yield_strain)

    @classmethod
    def rectangular(cls, width, height, E, nu=0.3, shear_factor=None, radius=None, name=None, *,
                    yield_stress=None, yield_strain=None):
        """Solid rectangle, ``width`` along ``e2`` and ``height`` along ``e3``.

        Torsion constant from the Saint-Venant series approximation
        ``J = a b^3 (1/3 - 0.21 (b/a) (1 - b^4 / (12 a^4)))`` (a >= b);
        shear factor defaults to Cowper's ``10 (1 + nu) / (12 + 11 nu)``.
        The contact radius defaults to half the smaller side (also the surface distance of the
        material-range check, an estimate for a rectangle).
        """
        b_, h_ = _positive("width", width), _positive("height", height)
        E = _positive("E", E)
        if not (-1.0 < real(nu, "nu", "Section.rectangular") < 0.5):
            raise InputError(f"Section.rectangular: nu must lie in (-1, 0.5), got {nu!r}")
        k = 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu) if shear_factor is None else _positive("shear_factor", shear_factor)
        def compute(width, height, E):
            G = E / (2.0 * (1.0 + nu))
            A = width * height
            a, b = max(width, height), min(width, height)
            J = a * b**3 * (1.0 / 3.0 - 0.21 * (b / a) * (1.0 - b**4 / (12.0 * a**4)))
            return dict(EA=E * A, GA2=k * G * A, GA3=k * G * A, GJ=G * J,
                        EI2=E * width * height**3 / 12.0, EI3=E * height * width**3 / 12.0)
        C = _stiffness("Section.rectangular", dict(width=b_, height=h_, E=E), compute)
        radius = 0.5 * min(b_, h_) if radius is None else radius
        sec = cls(**C, radius=radius, name=name)
        sec._set_range(f"Section {name!r}" if name else "Section.rectangular", yield_stress, yield_strain,
                       E=E, G=E / (2.0 * (1.0 + nu)))
        return sec

    def __repr__(self):
        d = np.diag(self.C)
        return (f"Section(EA={d[0]:.4g}, GA2={d[1]:.4g}, GA3={d[2]:.4g}, GJ={d[3]:.4g}, "
                f"EI2={d[4]:.4g}, EI3={d[5]:.4g}, radius={self.radius:.4g})")
