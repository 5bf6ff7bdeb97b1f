"""Cable builders: straight multi-layer strands of helical wires along ``e_z``, and ropes of strands.

A strand is a list of ``Layer`` s from the centre out.  A layer of one wire
with pitch radius 0 is a straight core; every other layer is ``n_wires``
helices (``geometry.helix``, exact constant-strain reference poses) at pitch
radius ``r`` with lay angle ``beta``: ``tan(beta) = 2 pi r / lay_length``.
By default a layer touches the layer below (``r_k = r_{k-1} + R_{k-1} + R_k``).

Valid geometry: the wires of a helical layer must not overlap each other.  Two neighbouring
helices (phase apart ``2 pi / n``) come closest at ``d = min_u sqrt(2 r^2 (1 - cos(u + 2 pi / n))
+ (r u / tan beta)^2)`` (exact for the centre lines); their clearance is ``d - 2 R``
(``layer_clearance``).  In the plane normal to the strand axis a wire's section is nearly an
ellipse with semi-axes ``R`` (radial) and ``R / cos beta`` (along the circle), which closes the
layer at ``r = R sqrt(1 + 1 / (tan^2(pi / n) cos^2 beta))`` (``closing_radius``, Costello 1997;
it agrees with the exact root of the clearance within 2e-4 up to 12 deg, 1.4e-3 at 20 deg).  A layer whose wires
would overlap and be declared in contact with each other is refused with an ``InputError`` that
gives the clearance and the core radius (or pitch radius) closing it; ``fit_core=True`` instead
enlarges a single core so that the first layer just closes (wires touching the core and each
other).  The default refuses: a core radius comes from a design or data sheet, and silently
thickening it would change the strand's stiffness.  Overlaps that remain (given pitch radii,
``touch_tol``) are reported by ``solve`` at step 0 as the pre-stress they cause.

Meshing: a helical wire gets ``elements_per_lay`` elements per lay length of its layer; a straight
core as many per shortest lay length of the other layers (at least ``elements_per_lay`` in all).

Contact declarations are made for touching neighbours only: each layer
(slave) against the layer below (master), and neighbouring wires of a layer
when their centre lines come closer than ``(1 + touch_tol) 2 R``.

End conditions: ``Strand.clamp(side)`` clamps every wire end of a side;
``Strand.plate(side)`` makes a node on the axis rigidly linked to every wire
end of that side (a rigid end plate), to be pulled / twisted with
``model.prescribe`` or ``model.fix(..., values=...)``; ``Strand.resultant``
gives the axial force and the torque about the axis from the plate reaction, ``Strand.cut``
the axial force, torque and bending moments across a cross-section at any height
(``resultants.cut_resultant``).

Ropes (``build_rope``; Costello 1997, ch. 4, "wire rope"): ``n_strands`` strands (e.g. 6 x 7,
6 x 19) laid around a straight core along ``e_z``, a wire strand core (``core``: a list of
``Layer``, built by ``build_strand``; an independent wire rope core simplified to a straight
strand) or a fibre core (``core``: a ``Section``).  Strand ``j``'s centre line is a helix of
pitch radius ``R_s``, lay length ``P``, phase ``2 pi j / n_strands``; wire ``i`` of its layer
``k`` is a double helix about it (``geometry.double_helix``: pitch radius ``r_k`` and lay
``p_k`` measured along the strand, phase ``Layer.phase + 2 pi i / n_k``), the strand's centre
wire the helix itself.  Every wire of a strand lies inside the tube of radius ``rho_s = r_last
+ R_last`` (its envelope) about its centre line, so no wires overlap when the centre lines keep
``2 rho_s`` apart and ``rho_s + rho_c`` from the axis (``rho_c``: the core's envelope): the
default ``R_s`` is the larger of ``rho_c + rho_s`` (strands on the core) and the radius closing
``n_strands`` envelopes (``layer_clearance`` = 0); a smaller given ``pitch_radius`` is refused.
A wire gets ``elements_per_lay`` elements per its shortest lay along ``z`` (``P``, or
``p_k cos(alpha)``, ``alpha`` the strands' lay angle); every core wire at least as many per the
shortest lay of all.  Contact: inside each strand as ``build_strand``; the strands' outer layers
on the core's outer layer, and neighbouring strands' outer layers on each other, when their
envelopes are closer than ``touch_tol`` times the outer wire diameter.
"""
from dataclasses import dataclass, replace
from typing import Optional

import numpy as np

from . import geometry
from .bending import BendingFixture, bending_fixture
from ..errors import InputError
from .model import Model
from .section import Section
from . import contact_options as _copts
from .validation import count, real

__all__ = ["Layer", "Strand", "build_strand", "Rope", "build_rope", "bending_fixture", "BendingFixture",
           "fibre_stiffness", "rod_stiffness",
           "layer_clearance", "closing_radius", "steel_yield_stress", "PROOF_FRACTION"]

OVERLAP_TOL = 1e-9       # a clearance above -OVERLAP_TOL R is no overlap (a layer closed to round-off)
PROOF_FRACTION = 0.8     # 0.2 % proof stress / tensile strength of cold-drawn wire (docs/theory_material_range.md)


def steel_yield_stress(grade, E, owner="build_strand"):
    """Yield (0.2 % proof) stress [Pa] of steel wire of ``grade`` (its tensile strength in MPa, e.g.
    ``"1770"``; EN 12385-4 grades 1570, 1770, 1960, 2160): ``PROOF_FRACTION`` times the tensile
    strength.  SI units only: ``E`` [Pa] must be a steel's (between 1e11 and 3e11)."""
    try:
        rm = float(grade)
    except (TypeError, ValueError):
        raise InputError(f"{owner}: grade must be a steel wire's tensile strength in MPa such as '1770', "
                         f"got {grade!r}") from None
    if not 300.0 <= rm <= 3500.0:
        raise InputError(f"{owner}: grade {grade!r} is not a steel wire's tensile strength in MPa (300-3500)")
    if not 1e11 <= float(E) <= 3e11:
        raise InputError(f"{owner}: grade {grade!r} sets a yield stress in Pa, but E = {E!r} is not a steel's "
                         f"Young's modulus in Pa; give yield_stress in your units instead")
    return PROOF_FRACTION * rm * 1e6


@dataclass
class Layer:
    """One layer: ``n_wires`` wires of ``wire_radius``; lay given by ``lay_length`` or ``lay_angle``.

    ``direction``: 'right' (Z lay) or 'left' (S lay); ``phase``: angle of the
    first wire (rad); ``pitch_radius``: default, touching the layer below;
    ``section``: the wires' ``Section`` (default ``Section.circular`` of ``wire_radius``
    with ``build_strand``'s ``E``, ``nu``; its radius must be ``wire_radius``).
    """
    wire_radius: float
    n_wires: int = 1
    lay_length: Optional[float] = None
    lay_angle: Optional[float] = None
    direction: str = "right"
    phase: float = 0.0
    pitch_radius: Optional[float] = None
    section: Optional[Section] = None


@dataclass
class Strand:
    model: Model
    layers: list
    wires: list            # per layer, list of Beam
    pitch_radii: list
    lay_angles: list
    lay_lengths: list
    length: float
    contacts: list
    clearances: list = None     # per layer: the neighbouring wires' clearance (None: no helical neighbours)

    @property
    def all_wires(self):
        return [w for layer in self.wires for w in layer]

    def ends(self, side):
        if side not in ("bottom", "top"):
            raise InputError(f"Strand: side must be 'bottom' or 'top', got {side!r}")
        return [w.first if side == "bottom" else w.last for w in self.all_wires]

    def clamp(self, side):
        for n in self.ends(side):
            self.model.clamp(n)

    def plate(self, side):
        """A node on the axis at the ``side`` end, rigidly linked to every wire end there."""
        z = 0.0 if side == "bottom" else self.length
        node = self.model.add_node((0.0, 0.0, z), name=f"plate {side}")
        for n in self.ends(side):
            self.model.join(node, n, rigid=True)
        return node

    def resultant(self, solution, plate=None, step=-1, z=None):
        """Axial force and torque about ``e_z``: exerted by the support on the strand at ``plate``, or,
        with ``z``, across the strand's cross-section at reference height ``z`` (``cut``: the wires'
        section forces with their lever arms, the part above on the part below)."""
        if z is not None:
            c = self.cut(solution, z, step)
            return float(c.axial), float(c.torque)
        if plate is None:
            raise InputError("Strand.resultant: give the plate node or a height z")
        r = solution.reaction(plate, step)
        return float(r[2]), float(r[5])

    def cut(self, solution, z, step=-1, bending_axis=(0.0, 1.0, 0.0), point=None):
        """Resultants across the strand's material cross-section at height ``z`` (reference), all wires
        with the lever arms of their axial forces: a ``resultants.CutResultant`` (``axial``,
        ``torque``, ``bending[0]`` about ``bending_axis``, ``bending[1]``; ``step=None``: every step)."""
        return solution.cut_resultant(self.all_wires, z, (0.0, 0.0, 1.0), (0.0, 0.0, 0.0), point, bending_axis, step)


def _lay(layer, r):
    if r == 0.0:
        return 0.0, np.inf
    if (layer.lay_length is None) == (layer.lay_angle is None):
        raise InputError(f"Layer {layer}: give exactly one of lay_length, lay_angle")
    if layer.lay_angle is not None:
        beta = real(layer.lay_angle, "lay_angle", "Layer")
        if not 0.0 < beta < np.pi / 2:
            raise InputError(f"Layer: lay_angle must lie in (0, pi/2) rad, got {beta!r}")
        return beta, 2.0 * np.pi * r / np.tan(beta)
    p = real(layer.lay_length, "lay_length", "Layer", above=0.0)
    return float(np.arctan(2.0 * np.pi * r / p)), p


def _layer(layer, k):
    """Layer ``k`` of ``build_strand`` as a ``Layer`` (a ``Layer`` or a dict of its fields), else ``InputError``."""
    if isinstance(layer, Layer):
        return layer
    if not isinstance(layer, dict):
        raise InputError(f"build_strand: layer {k} must be a cables.Layer or a dict of its fields, got {layer!r}")
    known = set(Layer.__dataclass_fields__)
    bad = sorted(set(layer) - known, key=str)
    if bad or "wire_radius" not in layer:
        what = f"unknown keys {bad}" if bad else "no 'wire_radius'"
        raise InputError(f"build_strand: layer {k} {layer!r} has {what}; a layer's fields are {sorted(known)}")
    return Layer(**layer)


def build_strand(layers, length, E, nu=0.3, elements_per_lay=24, min_elements=8, mu=0.0,
                 contact=True, touch_tol=0.05, model=None, contact_options=None, fit_core=False, grade=None,
                 yield_stress=None):
    """Build the wires of a straight strand into ``model`` (a new one by default); returns a ``Strand``.
    ``layers``: ``Layer`` objects or dicts of their fields, from the centre out.

    Wires of a layer that would overlap each other and be declared in contact (``contact`` and
    ``touch_tol``) are refused with an ``InputError`` giving the clearance and the radius that
    closes the layer; ``fit_core=True`` enlarges a single core instead (module docstring).

    Material range of the wires' sections (``Section(yield_stress=)``): ``yield_stress`` in the
    user's units, or ``grade``, a steel wire's tensile strength in MPa (``"1770"``; SI units,
    ``steel_yield_stress``); neither: no limit (a layer's own ``section`` keeps its own).
    """
    if not layers:
        raise InputError("build_strand: need at least one layer")
    length = real(length, "length", "build_strand", above=0.0)
    elements_per_lay = count(elements_per_lay, "elements_per_lay", "build_strand")
    min_elements = count(min_elements, "min_elements", "build_strand")
    touch_tol = real(touch_tol, "touch_tol", "build_strand")
    if grade is not None and yield_stress is not None:
        raise InputError(f"build_strand: give grade or yield_stress, not both (got {grade!r} and {yield_stress!r})")
    if grade is not None:
        yield_stress = steel_yield_stress(grade, E)
    layers = [_layer(layer, k) for k, layer in enumerate(layers)]
    if fit_core:
        layers = _fit_core(layers)
    model = Model() if model is None else model
    geo = _geometry(layers)
    for k, (layer, (r, beta, p, R, n)) in enumerate(zip(layers, geo)):
        c = layer_clearance(r, R, n, beta)
        if c is not None and c < -OVERLAP_TOL * R and contact and c + 2 * R <= 2 * R * (1 + touch_tol):
            raise InputError(_overlap_message(k, layers, geo, c))
    lays = [p for (_, _, p, _, _) in geo]
    helical = [p for p in lays if np.isfinite(p)]
    wires = []
    for k, (layer, (r, beta, p, R, n_wires)) in enumerate(zip(layers, geo)):
        sign = 1.0 if layer.direction == "right" else -1.0
        sec = _section(layer, k, R, E, nu, yield_stress)
        layer_wires = []
        for i in range(n_wires):
            if r == 0.0:
                per_lay = int(np.ceil(elements_per_lay * length / min(helical))) if helical else 0
                P = geometry.straight((0, 0, 0), (0, 0, length), max(min_elements, elements_per_lay, per_lay))
            else:
                n_el = max(min_elements, int(np.ceil(elements_per_lay * length / p)))
                P = geometry.helix(radius=r, pitch=sign * p, length=length, n_elements=n_el,
                                   phase=layer.phase + 2.0 * np.pi * i / n_wires)
            layer_wires.append(model.add_beam(P, sec, name=f"layer {k} wire {i}"))
        wires.append(layer_wires)
    contacts = _strand_contacts(model, wires, geo, mu, dict(contact_options or {}), touch_tol) if contact else []
    return Strand(model, layers, wires, [g[0] for g in geo], [g[1] for g in geo], lays, float(length), contacts,
                  [layer_clearance(r, R, n, beta) for (r, beta, _, R, n) in geo])


def _strand_contacts(model, wires, geo, mu, opts, touch_tol):
    """Contact declarations of one strand's layers ``wires`` (lists of beams, centre out; ``geo``: their
    ``_geometry``): each layer against the one inside it, and neighbours within a layer whose centre
    lines come within ``2 R (1 + touch_tol)``; exact stick's ``c`` from the slave layer's axial stiffness
    (``_axial_c``) unless ``opts`` give ``penalty_t`` or another stick."""
    contacts = []
    for k in range(1, len(wires)):
        contacts.append(model.add_contact(wires[k], wires[k - 1], mu=mu, **_axial_c(model, opts, mu, wires[k][0])))
    for k, lw in enumerate(wires):
        m = len(lw)
        if m >= 2 and _neighbour_distance(model, lw[0], lw[1]) <= 2.0 * geo[k][3] * (1.0 + touch_tol):
            for i in range(m if m > 2 else 1):
                contacts.append(model.add_contact(lw[i], lw[(i + 1) % m], mu=mu,
                                                  **_axial_c(model, opts, mu, lw[i])))
    return contacts


def _axial_c(model, opts, mu, slave):
    """``opts`` with exact stick's ``c`` (``penalty_t``) of a strand's contact whose slave is the wire ``slave``:
    ``EXACT_C_AXIAL EA / (L_e L_s)`` (``contact_options.axial_c``; ``L_e`` its median reference element length).
    Slip between the wires of a strand runs along them, driven by their axial forces' gradients, and the wires resist
    it with their axial stiffness; the library's default ``c`` (``EXACT_C``) takes the slave's bending stiffness,
    1 / 159 of this on the strand of examples/strand_bending.py at a lay ratio of 20, where its slip steps crawled
    (docs/benchmarks.md, "Strand bending, session 10").  ``c`` does not change the solution (exact stick), only
    Newton's path."""
    if mu == 0.0 or "penalty_t" in opts or opts.get("stick", "exact") != "exact" or not _copts.EXACT_C_AXIAL > 0:
        return opts
    x = model.poses0[slave.nodes, :3, 3]
    n = len(slave.elements)
    Le = float(np.median(np.linalg.norm(np.diff(x, axis=0), axis=1))) * ((len(x) - 1) // n)   # nodes per element
    return dict(opts, penalty_t=_copts.axial_c(slave.section.C[0, 0], Le, n))


def _geometry(layers):
    """Per layer ``(pitch radius, lay angle, lay length, wire radius, n_wires)``, checked."""
    out = []
    r_prev, R_prev = None, None
    for k, layer in enumerate(layers):
        R = real(layer.wire_radius, f"layer {k} wire_radius", "build_strand", above=0.0)
        n_wires = count(layer.n_wires, f"layer {k} n_wires", "build_strand")
        if layer.pitch_radius is not None:
            r = real(layer.pitch_radius, f"layer {k} pitch_radius", "build_strand", minimum=0.0)
        elif k == 0 and n_wires == 1:
            r = 0.0
        elif k == 0:                                 # wires touching each other around an empty centre
            r = _closing_pitch_radius(layer, R, n_wires) if n_wires > 1 else 0.0
        else:
            r = r_prev + R_prev + R
        beta, p = _lay(layer, r)
        if layer.direction not in ("right", "left"):
            raise InputError(f"build_strand: layer {k} direction must be 'right' or 'left'")
        out.append((float(r), float(beta), float(p), float(R), int(n_wires)))
        r_prev, R_prev = r, R
    return out


def _section(layer, k, R, E, nu, yield_stress=None):
    if layer.section is None:
        return Section.circular(radius=R, E=E, nu=nu, name=f"layer {k}", yield_stress=yield_stress)
    if not isinstance(layer.section, Section):
        raise InputError(f"build_strand: layer {k} section must be a beamsolver.Section, got {layer.section!r}")
    if abs(layer.section.radius - R) > 1e-12 * R:
        raise InputError(f"build_strand: layer {k} section radius {layer.section.radius!r} differs from its "
                         f"wire_radius {R!r}")
    return layer.section


def layer_clearance(r, R, n, beta):
    """Clearance ``d - 2 R`` between neighbouring wires of a helical layer (``n`` wires of radius ``R`` at
    pitch radius ``r``, lay angle ``beta``), ``d`` the exact least distance of their centre lines;
    ``None`` for fewer than two wires or a straight layer (negative: they overlap)."""
    if n < 2 or r == 0.0 or beta == 0.0:
        return None
    from scipy.optimize import minimize_scalar    # here: 0.1 s of every import otherwise
    delta = 2.0 * np.pi / n
    c = r / np.tan(beta)                   # axial advance per radian of the helix

    def d2(u):
        return 2.0 * r * r * (1.0 - np.cos(u + delta)) + (c * u) ** 2
    res = minimize_scalar(d2, bounds=(-delta, 0.0), method="bounded", options=dict(xatol=1e-15 * delta))
    return float(np.sqrt(min(res.fun, d2(0.0)))) - 2.0 * R


def closing_radius(R, n, beta):
    """Pitch radius at which ``n`` wires of radius ``R`` at lay angle ``beta`` close the layer, from
    the elliptical cut normal to the axis (semi-axes ``R`` and ``R / cos beta``; Costello 1997)."""
    return R * np.sqrt(1.0 + 1.0 / (np.tan(np.pi / n) ** 2 * np.cos(beta) ** 2))


def _closing_pitch_radius(layer, R, n):
    """The exact pitch radius closing a layer (root of ``layer_clearance``; lay angle or lay length kept)."""
    from scipy.optimize import brentq

    def gap(r):
        return layer_clearance(r, R, n, _lay(layer, r)[0])
    if n == 2 or (layer.lay_angle is None and layer.lay_length is None):
        return R / np.sin(np.pi / n)               # straight wires, or two helices: touching on the chord
    beta0 = _lay(layer, 2.0 * R)[0]
    r0 = closing_radius(R, n, beta0)
    lo, hi = R / np.sin(np.pi / n), 2.0 * r0
    return float(brentq(gap, lo, hi, xtol=1e-15 * r0))


def _overlap_message(k, layers, geo, c):
    r, beta, p, R, n = geo[k]
    r_fix = _closing_pitch_radius(layers[k], R, n)
    if k == 1 and geo[0][0] == 0.0 and layers[1].pitch_radius is None:
        fix = (f"a core radius of at least {r_fix - R:.6g} (now {geo[0][3]:.6g}) closes it, or "
               "build_strand(..., fit_core=True) sizes the core so")
    else:
        fix = f"a pitch radius of at least {r_fix:.6g} closes it"
    return (f"build_strand: the {n} wires of layer {k} (radius {R:.6g}, lay angle {np.degrees(beta):.4g} deg, "
            f"pitch radius {r:.6g}) overlap each other: clearance {c:.3g}; {fix}")


def _fit_core(layers):
    """``layers`` with the single core enlarged so that layer 1 just closes (if it would overlap)."""
    if len(layers) < 2 or layers[0].n_wires != 1 or layers[0].pitch_radius not in (None, 0.0) or \
            layers[1].pitch_radius is not None:
        raise InputError("build_strand: fit_core=True needs a single straight core and a first layer "
                         "without a given pitch_radius")
    geo = _geometry(layers[:2])
    r, beta, _, R, n = geo[1]
    c = layer_clearance(r, R, n, beta)
    if c is None or c >= 0.0:
        return layers
    core = replace(layers[0], wire_radius=_closing_pitch_radius(layers[1], R, n) - R, section=None)
    if layers[0].section is not None:
        raise InputError("build_strand: fit_core=True sizes the core's section; give the core no section")
    return [core] + list(layers[1:])


def _neighbour_distance(model, a, b, samples=400):
    """Minimum distance between the reference centre lines of two wires (dense sampling)."""
    P = model.poses0
    xa = P[a.nodes, :3, 3]
    xb = P[b.nodes, :3, 3]
    from scipy.spatial import cKDTree
    sa = _densify(xa, samples)
    sb = _densify(xb, samples)
    d, _ = cKDTree(sb).query(sa)
    return float(d.min())


def _densify(x, samples):
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))])
    t = np.linspace(0.0, s[-1], samples)
    return np.stack([np.interp(t, s, x[:, k]) for k in range(3)], axis=-1)


def fibre_stiffness(core_radius, wire_radius, n_wires, pitch_radius, lay_angle, E, nu=0.3):
    """Thin-wire (fibre) limit of a 1+m strand: ``(K_ee, K_ew, K_ww)``.

    ``K_ee = E A_c + m E A_h cos^3 b``, ``K_ew = m E A_h r sin b cos^2 b``,
    ``K_ww = G J_c + m E A_h r^2 sin^2 b cos b``; fixed ends ``F = K_ee eps``,
    ``M = K_ew eps``; free ends ``F = (K_ee - K_ew^2 / K_ww) eps``.
    """
    G = E / (2.0 * (1.0 + nu))
    Ac, Ah = np.pi * core_radius**2, np.pi * wire_radius**2
    Jc = 0.5 * np.pi * core_radius**4
    b, r, m = lay_angle, pitch_radius, n_wires
    Kee = E * Ac + m * E * Ah * np.cos(b) ** 3
    Kew = m * E * Ah * r * np.sin(b) * np.cos(b) ** 2
    Kww = G * Jc + m * E * Ah * r**2 * np.sin(b) ** 2 * np.cos(b)
    return Kee, Kew, Kww


def rod_stiffness(core_radius, wire_radius, n_wires, pitch_radius, lay_angle, E, nu=0.3, measure="geometric"):
    """Linear strand stiffness with the wires' own bending and torsion: ``(K_ee, K_ew, K_ww)``.

    Thin-rod theory of a straight 1+m strand (the kinematics of Costello's theory,
    linearised, with the helix radius ``r`` held: no Poisson contraction, no contact
    flattening).  A strand strain ``eps`` and twist rate ``theta`` turn each wire into
    another helix of angle ``b + db``, ``db = cos^2 b (r theta - tan b eps)``; its axial
    strain is ``eps cos^2 b + r theta sin b cos b`` (the fibre limit), its curvature
    ``sin^2 b / r`` and torsion ``sin b cos b / r`` change by ``(2 sin b cos b / r) db`` and
    ``(cos 2b / r) db``.  The strain energy per strand length (wire length ``1 / cos b``)
    ``U = G J_c theta^2 / 2 + E A_c eps^2 / 2 + m / (2 cos b) (E A_h e_w^2 + E I_h dk^2 + G J_h dt^2)``
    gives the stiffness; without ``I_h, J_h`` it is :func:`fibre_stiffness`.

    ``measure``: ``"geometric"`` (default) takes ``dk, dt`` as the changes of the helix's
    curvature and torsion (per deformed length, as Costello); ``"material"`` per unit
    reference length, as the SE(3) beam's strains ``h / L``: a wire stretched by ``e_w``
    adds ``e_w (k0, t0)`` with ``k0 = sin^2 b / r``, ``t0 = sin b cos b / r``.  The beam
    model's fixed-end torque follows the latter (``examples/seven_wire_strand.py``).
    """
    if measure not in ("geometric", "material"):
        raise InputError(f"rod_stiffness: measure must be 'geometric' or 'material', got {measure!r}")
    G = E / (2.0 * (1.0 + nu))
    Kee, Kew, Kww = fibre_stiffness(core_radius, wire_radius, n_wires, pitch_radius, lay_angle, E, nu)
    b, r, m = lay_angle, pitch_radius, n_wires
    s, c = np.sin(b), np.cos(b)
    Ih = 0.25 * np.pi * wire_radius**4
    # d(curvature, torsion) / d theta and / d eps
    k_th = np.array([2.0 * s * c**3, c**2 * np.cos(2 * b)])
    k_ep = np.array([-2.0 * s**2 * c**2 / r, -np.cos(2 * b) * s * c / r])
    if measure == "material":       # + e_w (k0, t0), e_w = eps cos^2 b + r theta sin b cos b
        k0 = np.array([s**2 / r, s * c / r])
        k_th = k_th + r * s * c * k0
        k_ep = k_ep + c**2 * k0
    D = np.array([E * Ih, G * 2.0 * Ih])
    w = m / c
    return (Kee + w * np.sum(D * k_ep * k_ep), Kew + w * np.sum(D * k_ep * k_th),
            Kww + w * np.sum(D * k_th * k_th))


@dataclass
class Rope:
    """A rope built by ``build_rope``: ``strands[j][k][i]`` is wire ``i`` of layer ``k`` of outer strand ``j``."""
    model: Model
    core: list                 # per core layer, list of Beam (a fibre core: [[beam]])
    strands: list              # per outer strand, per layer, list of Beam
    core_strand: Optional[Strand]
    pitch_radius: float        # of the strands' centre lines (R_s)
    lay_length: float          # of the strands (P, > 0)
    lay_angle: float
    strand_layers: list        # the outer strands' Layers
    strand_geometry: list      # per strand layer: (pitch radius r_k, lay angle in the strand, lay length p_k, R, n)
    envelope: float            # rho_s, the outer strands' envelope radius
    core_envelope: float       # rho_c
    length: float
    contacts: list             # every declaration: the core strand's, then the outer strands'
    clearance: Optional[float]     # least distance of neighbouring strands' envelopes (negative: overlap)

    @property
    def all_wires(self):
        return [w for layer in self.core for w in layer] + [w for s in self.strands for layer in s for w in layer]

    def ends(self, side):
        if side not in ("bottom", "top"):
            raise InputError(f"Rope: side must be 'bottom' or 'top', got {side!r}")
        return [w.first if side == "bottom" else w.last for w in self.all_wires]

    def clamp(self, side):
        for n in self.ends(side):
            self.model.clamp(n)


def build_rope(strand, length, E, nu=0.3, n_strands=6, lay_length=None, lay_angle=None, direction="right",
               core=None, pitch_radius=None, elements_per_lay=24, min_elements=8, mu=0.0, contact=True,
               touch_tol=0.05, model=None, contact_options=None):
    """Build a rope of ``n_strands`` strands of design ``strand`` around ``core`` into ``model``; a ``Rope``
    (geometry, meshing and contact declarations: the module docstring, "Ropes").

    ``strand``: the outer strands' ``Layer`` s from their centre out (lay lengths measured along
    the strand; pitch radii default to touching layers, as ``build_strand``); ``lay_length`` or
    ``lay_angle`` [m, rad]: the strands' lay in the rope; ``direction``: ``'right'`` (Z) or
    ``'left'`` (S) for the strands (each strand layer has its own, e.g. 'left' for a regular
    lay); ``core``: a list of ``Layer`` (a wire strand core, built straight by ``build_strand``)
    or a ``Section`` (a fibre core); ``pitch_radius``: of the strands' centre lines (default in
    the module docstring).  Other arguments as ``build_strand``.
    """
    length = real(length, "length", "build_rope", above=0.0)
    n_strands = count(n_strands, "n_strands", "build_rope")
    elements_per_lay = count(elements_per_lay, "elements_per_lay", "build_rope")
    min_elements = count(min_elements, "min_elements", "build_rope")
    touch_tol = real(touch_tol, "touch_tol", "build_rope")
    if n_strands < 2:
        raise InputError(f"build_rope: n_strands must be at least 2, got {n_strands}")
    if direction not in ("right", "left"):
        raise InputError(f"build_rope: direction must be 'right' or 'left', got {direction!r}")
    if not strand:
        raise InputError("build_rope: strand needs at least one layer")
    layers = [_layer(layer, k) for k, layer in enumerate(strand)]
    geo = _geometry(layers)
    rho_s = geo[-1][0] + geo[-1][3]
    model = Model() if model is None else model
    rho_c, core_geo = _rope_core_geometry(core)
    # the strands' helix
    envelope = Layer(wire_radius=rho_s, n_wires=n_strands, lay_length=lay_length, lay_angle=lay_angle)
    if (lay_length is None) == (lay_angle is None):
        raise InputError("build_rope: give exactly one of lay_length, lay_angle (the strands' lay in the rope)")
    fit = max(rho_c + rho_s, _closing_pitch_radius(envelope, rho_s, n_strands))
    if pitch_radius is None:
        R_s = fit
    else:
        R_s = real(pitch_radius, "pitch_radius", "build_rope", above=0.0)
        if R_s < fit * (1.0 - 1e-12):
            raise InputError(f"build_rope: pitch_radius {R_s!r} makes the strands (envelope radius {rho_s:.6g}) "
                             f"overlap the core (radius {rho_c:.6g}) or each other; at least {fit:.6g} fits")
    alpha, P = _lay(envelope, R_s)
    clearance = layer_clearance(R_s, rho_s, n_strands, alpha)
    c = (1.0 if direction == "right" else -1.0) * P / (2.0 * np.pi)
    lays = [P] + [p * np.cos(alpha) for (_, _, p, _, _) in geo if np.isfinite(p)]
    core_lays = [] if core_geo is None else [p for (_, _, p, _, _) in core_geo if np.isfinite(p)]
    n_core = max(min_elements, elements_per_lay, int(np.ceil(elements_per_lay * length / min(lays + core_lays))))
    if core_geo is None:
        core_strand = None
        core_wires = [[model.add_beam(geometry.straight((0, 0, 0), (0, 0, length), n_core), core, name="core")]]
    else:
        core_strand = build_strand(core, length, E, nu, elements_per_lay=elements_per_lay, min_elements=n_core,
                                   mu=mu, contact=contact, touch_tol=touch_tol, model=model,
                                   contact_options=contact_options)
        core_wires = core_strand.wires
    strands = [_rope_strand(model, layers, geo, j, n_strands, R_s, c, P, alpha, length, E, nu, elements_per_lay,
                            min_elements) for j in range(n_strands)]
    contacts = list(core_strand.contacts) if core_strand is not None else []
    if contact:
        opts = dict(contact_options or {})
        for sl in strands:
            contacts += _strand_contacts(model, sl, geo, mu, opts, touch_tol)
        gap = 2.0 * geo[-1][3] * touch_tol
        if R_s - rho_s - rho_c <= gap:
            contacts.append(model.add_contact([w for sl in strands for w in sl[-1]], core_wires[-1], mu=mu, **opts))
        if clearance is not None and clearance <= gap:
            for j in range(n_strands if n_strands > 2 else 1):
                contacts.append(model.add_contact(strands[j][-1], strands[(j + 1) % n_strands][-1], mu=mu, **opts))
    return Rope(model, core_wires, strands, core_strand, float(R_s), float(P), float(alpha), layers, geo,
                float(rho_s), float(rho_c), float(length), contacts, clearance)


def _rope_core_geometry(core):
    """``(radius, layer geometry)`` of a rope's core: a ``Section`` (fibre core: geometry ``None``) or a
    list of ``Layer`` (a wire strand core, ``_geometry``)."""
    if isinstance(core, Section):
        return float(core.radius), None
    if not (isinstance(core, (list, tuple)) and core):
        raise InputError(f"build_rope: core must be a list of cables.Layer (a wire strand core) or a Section "
                         f"(a fibre core), got {core!r}")
    cgeo = _geometry([_layer(layer, k) for k, layer in enumerate(core)])
    return cgeo[-1][0] + cgeo[-1][3], cgeo


def _rope_strand(model, layers, geo, j, n_strands, R_s, c, P, alpha, length, E, nu, elements_per_lay, min_elements):
    """The wires of outer strand ``j`` (lists per layer, centre out) on the strands' helix (pitch radius
    ``R_s``, ``c`` = axial advance per radian, lay ``P``, angle ``alpha``)."""
    th0 = 2.0 * np.pi * j / n_strands
    sl = []
    for k, (layer, (r, beta, p, R, n_w)) in enumerate(zip(layers, geo)):
        sec = _section(layer, k, R, E, nu)
        lay_z = min(P, p * np.cos(alpha)) if np.isfinite(p) else P
        n_el = max(min_elements, int(np.ceil(elements_per_lay * length / lay_z)))
        wires = []
        for i in range(n_w):
            name = f"strand {j} layer {k} wire {i}"
            if r == 0.0:
                P_ = geometry.helix(radius=R_s, pitch=2.0 * np.pi * c, length=length, n_elements=n_el, phase=th0)
            else:
                sign = 1.0 if layer.direction == "right" else -1.0
                P_ = geometry.double_helix(R_s, 2.0 * np.pi * c, r, sign * p, length, n_el,
                                           phase=layer.phase + 2.0 * np.pi * i / n_w, strand_phase=th0)
            wires.append(model.add_beam(P_, sec, name=name))
        sl.append(wires)
    return sl
