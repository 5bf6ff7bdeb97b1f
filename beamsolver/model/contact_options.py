"""Contact options of one ``Model.add_contact`` declaration: one validated, typed object, written once.

Each field of ``ContactOptions`` carries its default, its check and its meaning (``option``);
``add_contact``'s docstring, the validation of its keywords (``check_contact_options``) and the
contact kernel's per-declaration table (``contact.options.declaration_table``: ``None`` encoded
as the field's ``kernel_none``) are all made from them.  Lengths are in model units; ``None``
means "derived per pair" where stated.  (In ``model``: ``add_contact`` checks its options
before any contact code runs; ``contact.options`` is the same object's public path.)
"""
import re
from dataclasses import asdict, dataclass, field, fields
from typing import Any, Optional

import numpy as np

from ..errors import InputError
from .validation import count, real

__all__ = ["ContactOptions", "check_contact_options", "describe", "SMOOTHING", "SLIP_TOLERANCE", "GAUSS_POINTS",
           "SEGMENT_POINTS",
           "STICK_TOLERANCE", "LINE_ANGLE", "ADJUST", "EXACT_C", "EXACT_N",
           "EXACT_C_AXIAL", "axial_c"]

SMOOTHING = 1e-6          # default smoothing gap of the normal law / (R1 + R2) (benchmarks/touching_defaults.py)
SLIP_TOLERANCE = 0.005    # elastic slip at the onset of sliding / slave element length (Abaqus' default)
EXACT_C = 24.0            # stick="exact": default c of the complementarity function / (EI / (L_e L_s^3)) of the slave,
EXACT_N = 16              # ... L_s = its length / EXACT_N (n L_e / EXACT_N; docs/theory_mortar.md 3b, "c under mesh
                          # refinement": c grows like 1 / L_e, and equals 24 EI / L_e^4 at 16 elements)
EXACT_C_AXIAL = 1.0       # ... a strand's contacts (``cables.build_strand``): c = this times EA / (L_e L_s) of the slave
STICK_TOLERANCE = 1e-8    # weighted slip of a sticking node / (R1 + R2) with stick="exact"
LINE_ANGLE = float(np.deg2rad(20.0))   # below this crossing angle: line contact (search.py, rule 1)
GAUSS_POINTS = 5          # integration="points": Gauss points per slave element
SEGMENT_POINTS = 3        # integration="segments": Gauss points per segment (2 integrate the patch test exactly;
                          # 3 keep the contact examples' iterations: docs/benchmarks.md, segment-to-segment)
ADJUST = 1e-3             # default overclosure adjusted away at the reference poses / (R1 + R2)
                          # (chords of a polyline on a post: 1.1e-4 at R1 + R2 = 1.02; docs/theory_adjust.md)


def axial_c(EA, Le, n):
    """Exact stick's ``c`` (force / length^2) from a slave's axial stiffness ``EA``: ``EXACT_C_AXIAL EA / (L_e L_s)``
    with ``L_s = n L_e / EXACT_N`` (``L_e`` its element length, ``n`` its elements), the axial counterpart of the
    default ``EXACT_C EI / (L_e L_s^3)`` (``contact.system.exact_c``): the wire's stiffness against a nodal
    displacement along it, per unit length of the node."""
    return float(EXACT_C_AXIAL * EA / Le ** 2 * (EXACT_N / n))


def _gauss_points(v, owner):
    return None if v is None else count(v, "gauss_points", owner, maximum=64)


def _line_angle(v, owner):
    a = real(v, "line_angle", owner)
    if not 0.0 <= a <= 0.5 * np.pi:
        raise InputError(f"{owner}: line_angle must lie in [0, pi/2] rad, got {v!r}")
    return a


def _stick(v, owner):
    if v in ("penalty", "exact"):
        return v
    raise InputError(f"{owner}: stick must be 'penalty' or 'exact', got {v!r}")


def _compiled(f):
    """Whether ``f`` is a numba dispatcher (anything callable when numba's JIT is disabled)."""
    from numba.core import config
    from numba.core.dispatcher import Dispatcher
    return isinstance(f, Dispatcher) or bool(config.DISABLE_JIT)


def _integration(v, owner):
    if v in ("points", "segments"):
        return v
    raise InputError(f"{owner}: integration must be 'points' or 'segments', got {v!r}")


def _contact_law(v, owner):
    """A ``contact.law.ContactLaw`` (checked by its fields: ``name``, compiled ``normal`` and
    ``tangential``) or None."""
    if v is None:
        return v
    if isinstance(getattr(v, "name", None), str) and callable(getattr(v, "normal", None)) \
            and callable(getattr(v, "tangential", None)):
        plain = [k for k in ("normal", "tangential") if not _compiled(getattr(v, k))]
        if plain:
            raise InputError(f"{owner}: law {v.name!r}: {' and '.join(plain)} must be numba-compiled functions "
                             "(decorate them with beamsolver._jit.jit, i.e. numba.njit): the compiled contact "
                             f"kernel cannot call the plain Python function(s) {plain}")
        return v
    raise InputError(f"{owner}: law must be a beamsolver.contact.law.ContactLaw (name, normal, tangential) "
                     f"or None, got {type(v).__name__} {v!r}")


def _real(name, **limits):
    return lambda v, owner: real(v, name, owner, **limits)


def option(default, check, doc, kernel_none=None):
    """A field of ``ContactOptions``: its ``default``, ``check(value, owner)`` returning the stored
    value, its meaning ``doc`` (reST, for ``add_contact``) and, for fields the kernel's
    per-declaration table reads, the number that stands for ``None`` there (``kernel_none``)."""
    return field(default=default, metadata=dict(check=check, doc=doc, kernel_none=kernel_none))


@dataclass(frozen=True)
class ContactOptions:
    """The keyword options of ``Model.add_contact`` (their meanings: ``describe()``, also in
    ``add_contact``'s docstring).  ``from_dict`` validates and fills the defaults."""
    smoothing: Optional[float] = option(
        None, _real("smoothing", minimum=0.0, none=True),
        "gap over which the normal law is made C1 (default None: ``1e-6 (R1 + R2)`` "
        "(``SMOOTHING``) for line contact, so touching, lightly loaded wires converge, and sharp "
        "for point and orthogonal pairs; 0: sharp everywhere)", kernel_none=np.nan)
    gauss_points: Optional[int] = option(
        None, _gauss_points, "integration points of line contact per segment (``integration=\"segments\"``, "
        "default 3, ``SEGMENT_POINTS``) or per slave element (``\"points\"`` and orthogonal pairs, default 5, "
        "``GAUSS_POINTS``)")
    integration: str = option(
        "points", _integration,
        "line contact's integration: ``\"points\"`` (default: ``gauss_points`` fixed per slave element, each "
        "projected on one master element: the master's shape functions, kinked inside the slave element, "
        "are integrated inexactly) or ``\"segments\"`` (each slave element cut where its section planes "
        "pass through the master's nodes, ``gauss_points`` on every piece: the products of slave and master "
        "shape functions exact on straight beams, the contact patch test passes to round-off; "
        "docs/theory_mortar.md section 7)")
    penalty_t: Optional[float] = option(
        None, _real("penalty_t", above=0.0, none=True),
        "with ``stick=\"penalty\"``: a fixed tangential penalty, force / length^3, instead of one from "
        "``slip_tolerance`` (default None); with ``stick=\"exact\"``: the parameter ``c`` of the "
        "complementarity function ``C = lam - P(lam + c u)`` the semi-smooth Newton solves, force / "
        "length^2 (default ``24 EI / (L_e L_s^3)`` (``EXACT_C``), the slave's bending stiffness against a "
        "nodal displacement at the reference element length ``L_s`` = its length / 16 (``EXACT_N``), per unit "
        "length of the node: ``EI`` its smaller bending stiffness, ``L_e`` its median element length; it grows "
        "like ``1 / L_e`` under refinement and is ``24 EI / L_e^4`` at 16 elements): it changes the path of the "
        "iterations, not the answer", kernel_none=np.nan)
    slip_tolerance: float = option(
        SLIP_TOLERANCE, _real("slip_tolerance", above=0.0),
        "with ``stick=\"penalty\"`` (and point pairs): elastic slip at the onset of sliding, in slave element "
        "lengths (default 0.005, Abaqus' default); the tangential stiffness of a point is then "
        "``mu lam_N / (slip_tolerance L_e)``")
    tolerance: Optional[float] = option(
        None, _real("tolerance", above=0.0, none=True),
        "penetration below which augmented-Lagrangian updates stop (default None: pure penalty, "
        "no updates)", kernel_none=np.inf)
    line_angle: float = option(
        LINE_ANGLE, _line_angle, "crossing angle (rad) below which a pair is line contact (default "
        "``radians(20)``)")
    point_ratio: float = option(
        0.5, _real("point_ratio", minimum=0.0, maximum=1.0),
        "from this ``sin^2`` of the crossing angle up a pair is one point contact, below it "
        "orthogonal projection (0.5)")
    margin: Optional[float] = option(
        None, _real("margin", minimum=0.0), "search margin around every element (default twice the "
        "largest radius)")
    law: Optional[Any] = option(
        None, _contact_law, "the contact law, a ``contact.law.ContactLaw`` of compiled functions "
        "(default None: the penalty / augmented-Lagrangian / smoothed normal law with Coulomb "
        "friction; docs/theory.md section 15)")
    adjust: Optional[float] = option(
        None, _real("adjust", minimum=0.0, none=True),
        "strain-free adjustment of initial overclosures (Abaqus' contact ``ADJUST``): a contact "
        "point whose gap at the reference poses lies between ``-adjust`` and 0 starts touching (its "
        "gap offset by the overlap for the whole run: the overlap puts no force on the reference "
        "state); deeper overlaps are left as they are (default None: ``1e-3 (R1 + R2)`` "
        "(``ADJUST``); 0: no adjustment; the count and the largest overlap adjusted are in "
        "``Solution.stats[0][\"adjusted\"]``; docs/theory_adjust.md)", kernel_none=np.nan)
    stick: str = option(
        "exact", _stick,
        "``\"exact\"`` (default: line contact's tangential traction is a field of nodal multipliers on the "
        "slave beam, Newton unknowns with their Coulomb complementarity functions: a sticking node's weighted "
        "slip is below ``stick_tolerance``, whatever ``penalty_t``; the nodal forces are in ``Solution.extra"
        "[\"mortar_*\"]``; point and orthogonal pairs keep the point law; docs/theory_mortar.md) or "
        "``\"penalty\"`` (the tangential penalty above, per Gauss point: cheaper per Newton iteration, 1.5-7x "
        "fewer iterations on the contact examples, but sticking points slip elastically by ``lam_T / penalty_t``, "
        "up to ``slip_tolerance`` element lengths, an error in the answer: a tensioned strand bent with the "
        "default ``slip_tolerance`` never sticks, its bending stiffness 4x low; docs/benchmarks.md)")
    stick_tolerance: Optional[float] = option(
        None, _real("stick_tolerance", above=0.0, none=True),
        "that slip, a length (default ``1e-8 (R1 + R2)`` (``STICK_TOLERANCE``) of the largest radii "
        "of the declaration)")

    @classmethod
    def from_dict(cls, options, owner="add_contact"):
        """Validated options from ``add_contact``'s keyword arguments (defaults filled)."""
        return cls(**check_contact_options(dict(options), owner))

    def as_dict(self):
        out = asdict(self)
        out["law"] = self.law                 # the law itself, not a dict of its fields
        return out


def check_contact_options(options, owner="add_contact"):
    """Validated copy of ``Model.add_contact``'s keyword options (unknown names refused)."""
    known = {f.name: f for f in fields(ContactOptions)}
    bad = sorted(set(options) - set(known))
    if bad:
        raise InputError(f"{owner}: unknown options {bad}; known: {sorted(known)}")
    return {k: known[k].metadata["check"](v, owner) for k, v in options.items()}


def describe(indent=""):
    """The options and their meanings as a reST bullet list (``add_contact``'s docstring)."""
    lines = []
    for f in fields(ContactOptions):
        # inline literals (``...``) are never broken across lines
        text = re.sub(r"``.*?``", lambda m: m.group(0).replace(" ", "\0"), f"- ``{f.name}``: {f.metadata['doc']};")
        words = [w.replace("\0", " ") for w in text.split()]
        line = indent
        for w in words:
            if len(line) + len(w) + 1 > 100 and line.strip():
                lines.append(line.rstrip())
                line = indent + "  "
            line += w + " "
        lines.append(line.rstrip())
    return "\n".join(lines)
