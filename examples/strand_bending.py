"""Bending hysteresis of a tensioned 1+6 strand with Coulomb friction, against the closed-form theory.

The strand: a straight core (radius 1.97 mm) and six helical wires (1.865 mm), the wires of the 1+6 strands
tested by Utting & Jones (1987), the common test case of strand theories (Costello 1997), on a lay of 229.2 mm:
a lay ratio of 20 (lay over the layer's diameter, lay angle 6.0 deg), as in the six-wire steel cores of overhead
conductors.  Utting & Jones' own lay, 114.6 mm (11.9 deg), is ``--lay 114.6`` (``LAY_UJ``; below why it is not the
default).  Steel, E = 200 GPa, nu = 0.3, mu = 0.3.  With these radii the outer wires do not touch each other
(clearance ``cables.layer_clearance``).

History (pseudo-time ``t``): ``[0, 1]`` the pull ``T`` (wire strain about 1e-3) is applied
frictionless (``friction_from=1``: friction starts from zero traction at the tensioned state);
``[1, 2]`` the curvature goes ``0 -> +k``, ``[2, 4]`` ``+k -> -k``, ``[4, 6]`` ``-k -> +k``, with
``k = amplitude * kappa_b``.  ``cables.bending_fixture`` turns the end plates by ``-+kappa L / 2``,
leaves the top plate free axially under the dead pull and cancels the P-delta with the line load
``w = T kappa``.  The moment is measured across the cross-section at mid-length
(``Strand.cut``, the wires' axial forces with their lever arms), the stick/slip state from the
contact points of the middle half (``status``).

Theory (docs/theory_strand_bending.md; Papailiou 1997, Foti & Martinelli 2016, Cardou 2013):
``EI_min = E I_c + n c E I_w``, ``c = cos b (1 + cos^2 b + sin^2 b / (1 + nu)) / 2`` (full slip);
``EI_max = EI_min + S``, ``S = (n / 2) E A_w r^2 cos^3 b`` (full stick, plane sections);
first slip ``kappa_b = mu F sin b / (E A_w cos^2 b r)``; slipping share ``2 psi / pi`` with
``sin(psi) / psi = kappa_b / kappa`` up to ``kappa_t = (pi / 2) kappa_b``; saturated friction moment
``M_f = (2 n / pi) mu F r sin b cos b``; reversals by Masing's rule; loop energy from it.

Stick: the library's default, exact (``stick="exact"``: the mortar nodal multipliers as Newton unknowns,
docs/theory_mortar.md), whose stick state does not depend on a penalty; ``cables.build_strand`` gives its
contacts exact stick's ``c`` from the wires' axial stiffness (slip in a strand runs along the wires).  The issue's
size (``--lays 4 --elements 48 --onset``): the cycle in 221 Newton iterations, no cut-back, 31 s; ``EI_min`` -0.8 %,
``M_f`` -1.3 % (friction part -0.7 %), first slip 1.04 ``kappa_b`` on the fine ramp (24 el/lay: 1.03), the Masing
branch within 0.02 % of ``M_f`` of Masing's rule on the model's own virgin curve, the loop energy -3.5 %, the wires tied to the core
``EI_max`` -0.07 % (docs/benchmarks.md, "Strand bending, session 10").

The stick branch of a beam model is softer than plane sections: the wires stick at their surface, a lever arm
``R_w`` from their axes, and shear and twist under the friction's couple (initial stiffness 6 % below ``EI_max`` here;
tying the axes rigidly to the core gives ``EI_max``).  That compliance falls like ``sin^2(beta)``: at Utting & Jones'
lay (11.9 deg) the stick branch is 13-14 % of the Steiner term below plane sections and the first slip comes at
1.14 ``kappa_b``, where the model's own stick stiffness puts it (within 2.7 %), and ``M_f`` is 3.2 % low (4 lays, 48
el/lay: 198 iterations, 36 s CPU); from 6 deg down plane sections hold within 5 % (docs/theory_strand_bending.md,
section 5).  The ends, where the wires are tied to the plates, carry more friction moment (+5 to +20 % of ``M_f`` at
0.05 ``L``); 1.3 lays or more from a plate the moment settles on the long strand's value (2 lays have no plateau,
their middle is lifted by the ends).
The row ``M_f, friction part`` subtracts the model's own frictionless moment (the stiffness checks) instead of
``EI_min kappa``; the rows ``M - EI_min kappa at z`` give the moment along the strand (section 5).
Exact stick wants a dozen elements per lay or more: with fewer the linear nodal tractions smear the friction's
reversal at the neutral axis over an element (``M_f`` 6 % low at 8 el/lay).
``--stick penalty`` uses the Gauss-point penalty with ``slip_tolerance`` 5e-6 element lengths (with the
library's default 0.005 the strand does not stick at all).
``tied=True`` ties the wires rigidly to the core (no contact) to measure the beam model's own
full-stick stiffness (shear and torsion of the wires included) against ``EI_max``; ``--onset`` adds the first slip on
a ramp in steps of 0.01 ``kappa_b`` (``first_slip``; on by default, ``--no-onset`` skips it).

    python examples/strand_bending.py [--lays 4] [--elements 24] [--amplitude 3] [--steps 8] [--lay 229.2] [--no-onset]
"""
import argparse
import time

import numpy as np

import beamsolver as bs
from beamsolver import cables
from beamsolver.contact import SLIP

E, NU, MU = 200e9, 0.3, 0.3
RC, RW, N = 1.97e-3, 1.865e-3, 6
LAY_UJ = 114.6e-3                 # Utting & Jones' lay (11.9 deg)
LAY = 229.2e-3                    # the example's: their wires on a lay ratio of 20 (6.0 deg), as a conductor's steel core
STRAIN = 1e-3                     # axial strain of the strand under the pull

LAYS, ELEMENTS, AMPLITUDE, STEPS = 4, 24, 5.0, 4   # default size: the 4 lays (the cut at mid-length 2 lays from
#                                                   the plates, on the long strand's plateau; 2 lays have none: their
#                                                   full-slip slope read -4.8 % of EI_min), about 40 s of CPU
solve_options = dict(steps=6 * STEPS, t_end=6.0)   # for `beamsolver run examples/strand_bending.py`


# ---------------------------------------------------------------- theory
def theory(F, mu=MU, lay=LAY):
    """Closed-form quantities for a wire force ``F`` and a lay length ``lay`` (docs/theory_strand_bending.md): dict."""
    r = RC + RW
    b = np.arctan(2 * np.pi * r / lay)
    Aw, Iw, Ic = np.pi * RW**2, np.pi * RW**4 / 4, np.pi * RC**4 / 4
    c = np.cos(b) * (1 + np.cos(b) ** 2 + np.sin(b) ** 2 / (1 + NU)) / 2
    EI_min = E * Ic + N * c * E * Iw
    S = 0.5 * N * E * Aw * r**2 * np.cos(b) ** 3
    kb = mu * F * np.sin(b) / (E * Aw * np.cos(b) ** 2 * r)
    Mf = 2 * N / np.pi * mu * F * r * np.sin(b) * np.cos(b)
    return dict(beta=b, r=r, c=c, EI_min=EI_min, S=S, EI_max=EI_min + S, kappa_b=kb, kappa_t=0.5 * np.pi * kb,
                M_f=Mf, F=F)


def slip_angle(kappa, th):
    """``psi`` with ``sin(psi) / psi = kappa_b / kappa`` (0 below kappa_b, pi / 2 from kappa_t on)."""
    kappa = np.abs(np.atleast_1d(np.asarray(kappa, dtype=float)))
    out = np.zeros_like(kappa)
    x = np.linspace(1e-9, 0.5 * np.pi, 20001)
    ratio = np.sin(x) / x                                   # decreasing from 1 to 2 / pi
    mid = (kappa > th["kappa_b"]) & (kappa < th["kappa_t"])
    out[mid] = np.interp(-th["kappa_b"] / kappa[mid], -ratio, x)
    out[kappa >= th["kappa_t"]] = 0.5 * np.pi
    return out


def friction_moment(kappa, th):
    """Virgin friction part ``M - EI_min kappa`` (odd in ``kappa``): ``S kappa`` in stick,
    ``S kappa (4 / pi) g(psi)`` while slip spreads, ``M_f`` in full slip."""
    kappa = np.atleast_1d(np.asarray(kappa, dtype=float))
    k, psi = np.abs(kappa), slip_angle(kappa, th)
    with np.errstate(invalid="ignore", divide="ignore"):
        g = np.pi / 4 - psi / 2 + np.sin(psi) ** 2 / np.where(psi > 0, psi, 1) - np.sin(psi) * np.cos(psi) / 2
    m = np.where(k <= th["kappa_b"], th["S"] * k, np.where(k >= th["kappa_t"], th["M_f"],
                                                                 th["S"] * k * 4 / np.pi * g))
    return np.sign(kappa) * m


def moment(kappa, th, reversal=None):
    """Virgin ``M(kappa)``; after a reversal at ``(kappa_r, M_fr_r)`` (friction part) Masing's branch
    ``M_fr = M_fr_r - 2 f((kappa_r - kappa) / 2)``."""
    kappa = np.asarray(kappa, dtype=float)
    if reversal is None:
        return th["EI_min"] * kappa + friction_moment(kappa, th)
    kr, mr = reversal
    return th["EI_min"] * kappa + mr - 2 * friction_moment((kr - kappa) / 2, th)


def loop_energy(kappa_a, th):
    """Energy dissipated per cycle between ``-+kappa_a`` (Masing): ``8 int_0^k f - 4 k f(k)``."""
    x = np.linspace(0.0, kappa_a, 4001)
    f = friction_moment(x, th)
    return 8 * np.trapezoid(f, x) - 4 * kappa_a * f[-1]


# ---------------------------------------------------------------- model
STICK = "exact"                  # mortar nodal multipliers (docs/theory_mortar.md); "penalty": the Gauss-point penalty
SLIP_TOLERANCE = 5e-6            # with stick="penalty": its elastic slip / element length (default 0.005: see above)


def _contact_options(stick, slip_tolerance):
    """Friction from the tensioned state; the library's default stick (exact), or the penalty stick with
    ``slip_tolerance``."""
    stick = STICK if stick is None else stick
    return dict(friction_from=1.0) | (dict(stick=stick, slip_tolerance=slip_tolerance) if stick == "penalty" else {})


def build(lays=LAYS, elements_per_lay=ELEMENTS, mu=MU, amplitude=AMPLITUDE, tied=False, kappa_b=None, slip_tolerance=SLIP_TOLERANCE,
          stick=None, lay=LAY, curvature=None, sections=None):
    """The strand in its bending fixture: ``(model, strand, fixture, T, k)``; ``kappa_b`` sets the
    curvature unit (default: the theory's with the fibre-limit wire force); ``lay``: the lay length;
    ``curvature(t, k)``: the history for ``t`` in ``[1, 6]`` (default: the cycle of the module docstring);
    ``sections``: ``(core, wire)`` ``Section`` objects (default: steel circles of ``RC``, ``RW``)."""
    b = np.arctan(2 * np.pi * (RC + RW) / lay)
    core, wire = (None, None) if sections is None else sections
    layers = [cables.Layer(RC, 1, section=core), cables.Layer(RW, N, lay_length=lay, section=wire)]
    st = cables.build_strand(layers, lays * lay, E, nu=NU, elements_per_lay=elements_per_lay, mu=mu,
                             contact=not tied, touch_tol=0.0, contact_options=_contact_options(stick, slip_tolerance))
    if tied:                                   # every wire node rigidly on the core node at its height
        core = st.wires[0][0]
        for w in st.wires[1]:
            for a, c in zip(w.nodes, core.nodes):
                st.model.join(c, a, rigid=True)
    Kee = E * np.pi * RC**2 + N * E * np.pi * RW**2 * np.cos(b) ** 3
    T = Kee * STRAIN
    kb = theory(E * np.pi * RW**2 * np.cos(b) ** 2 * STRAIN, mu if mu > 0 else MU, lay)["kappa_b"] \
        if kappa_b is None else kappa_b
    k = amplitude * kb

    def cycle(t):
        if curvature is not None:
            return 0.0 if t <= 1.0 else curvature(t, k)
        if t <= 1.0:
            return 0.0
        if t <= 2.0:
            return k * (t - 1.0)
        if t <= 4.0:
            return k * (3.0 - t)
        return k * (t - 5.0)
    fx = cables.bending_fixture(st, curvature=cycle, pull=lambda t: T * min(t, 1.0))
    return st.model, st, fx, T, k


def run(lays=LAYS, elements_per_lay=ELEMENTS, mu=MU, amplitude=AMPLITUDE, steps=STEPS, tied=False, t_end=6.0, verbose=False,
        slip_tolerance=SLIP_TOLERANCE, stick=None, lay=LAY, curvature=None, sections=None, check_stability=None):
    """Solve with ``steps`` steps per unit pseudo-time; returns a dict of the measured curves (``build`` for the
    keywords; ``check_stability``: ``solve``'s)."""
    model, st, fx, T, k = build(lays, elements_per_lay, mu, amplitude, tied, slip_tolerance=slip_tolerance, stick=stick,
                                lay=lay, curvature=curvature, sections=sections)
    t0, c0 = time.perf_counter(), time.process_time()
    sol = bs.solve(model, steps=int(round(steps * t_end)), t_end=t_end, verbose=verbose,
                   check_stability=check_stability)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    kappa = np.array([fx.curvature(t) for t in sol.times])
    M = fx.moment(sol)
    outer = np.concatenate([w.elements for w in st.wires[1]])
    F = float(np.mean(sol.section_forces[int(np.argmin(np.abs(sol.times - 1.0))), outer, 0]))
    share = np.full(len(sol.times), np.nan)
    for i, c in enumerate(sol.contacts):
        if not len(c.get("status", ())):
            continue
        z = c["position"][:, 2]
        mid = (c["normal_force"] > 0) & (np.abs(z - 0.5 * fx.length) < 0.25 * fx.length)
        share[i] = np.mean(c["status"][mid] == SLIP) if mid.any() else np.nan
    return dict(sol=sol, fixture=fx, strand=st, lay=lay, times=sol.times, kappa=kappa, M=M, F=F, T=T, k=k, share=share,
                wall=wall, cpu=cpu, iterations=int(sol.iterations.sum()), cutbacks=sum(s.get("cutbacks", 0) for s in sol.stats))


def compare(res, EI_frictionless=None):
    """Theory against the model's measurements: list of ``(name, theory, model, relative error)``.
    ``EI_frictionless``: the model's own full-slip stiffness (``stiffness_checks``); given, the row
    ``M_f, friction part`` subtracts it instead of the theory's ``EI_min`` (docs/theory_strand_bending.md,
    section 5: the friction part of the moment is the moment less the frictionless one)."""
    th = theory(res["F"], lay=res.get("lay", LAY))
    t, kap, M = res["times"], res["kappa"], res["M"]
    up = (t > 1.0) & (t <= 2.0 + 1e-9)
    down = (t > 2.0) & (t <= 4.0 + 1e-9)
    rows = []
    first = np.flatnonzero(up)[0]
    rows.append(("EI initial (stick) [N m^2]", th["EI_max"], M[first] / kap[first]))
    slip = up & (kap >= max(th["kappa_t"] * 1.05, 0.6 * res["k"]))     # the last part of the virgin branch
    ks, Ms = kap[slip], M[slip]
    EI_slip = np.polyfit(ks, Ms, 1)[0] if len(ks) >= 2 else np.nan
    rows.append(("EI full slip, slope of the virgin branch [N m^2]", th["EI_min"], EI_slip))
    Mf = float(np.mean(Ms - th["EI_min"] * ks)) if len(ks) else np.nan
    rows.append(("M_f [N m]", th["M_f"], Mf))
    beyond = np.flatnonzero(up & (kap >= 2.0 * th["kappa_b"] * (1 - 1e-9)))   # issue 26: M beyond 2 kappa_b
    for j in sorted({beyond[0], beyond[-1]}) if len(beyond) else ():
        rows.append((f"M at {kap[j] / th['kappa_b']:.3g} kappa_b, virgin branch [N m]",
                     float(np.ravel(moment(kap[j], th))[0]), M[j]))
    if EI_frictionless is not None:
        rows.append(("M_f, friction part M - EI_frictionless kappa [N m]", th["M_f"],
                     float(np.mean(Ms - EI_frictionless * ks)) if len(ks) else np.nan))
    onset = np.flatnonzero(up & (res["share"] > 0))
    rows.append((f"kappa first slip, on the cycle's steps of {kap[first] / th['kappa_b']:.3g} kappa_b [1/m]",
                 th["kappa_b"], kap[onset[0]] if len(onset) else np.nan))
    mid = up & (kap > th["kappa_b"]) & (kap < th["kappa_t"])
    if mid.any():
        j = np.flatnonzero(mid)[-1]
        rows.append((f"slipping share at {kap[j] / th['kappa_b']:.2f} kappa_b", 2 * slip_angle(kap[j], th)[0] / np.pi,
                     res["share"][j]))
    kr = kap[np.flatnonzero(up)[-1]]
    rev = (kr, friction_moment(kr, th)[0])
    masing = moment(kap[down], th, rev)
    err = np.abs(M[down] - masing) / th["M_f"]
    rows.append(("Masing branch: max |M - M_Masing| / M_f", 0.0, err.max()))
    rows.append(("Masing branch at -k: |M - M_Masing| / M_f", 0.0, err[-1]))
    # Masing's rule on the model's own virgin curve and reversal point: the two rows above measure the theory's
    # reversal point, so they repeat the model's M_f error; these measure the rule itself, at the points of the
    # branch whose half-distance to the reversal is a computed state of the virgin branch (interpolating the virgin
    # curve between steps of 1.25 kappa_b instead errs by 6 % of M_f on the theory's own curves)
    xs = np.concatenate([[0.0], kap[up]])
    fs = np.concatenate([[0.0], M[up] - th["EI_min"] * kap[up]])
    half = (kr - kap[down]) / 2
    near = np.abs(xs[None, :] - half[:, None]).argmin(axis=1)
    hit = np.abs(xs[near] - half) <= 1e-9 * abs(kr)
    own = th["EI_min"] * kap[down][hit] + fs[-1] - 2 * fs[near[hit]]
    err_own = np.abs(M[down][hit] - own) / th["M_f"]
    rows.append(("Masing on the model's virgin curve: max |M - M_Masing| / M_f", 0.0, err_own.max()))
    rows.append(("Masing on the model's virgin curve at -k: |M - M_Masing| / M_f", 0.0, err_own[-1]))
    last = t >= 2.0 - 1e-9
    W = np.trapezoid(M[last], kap[last])                         # one full cycle +k -> -k -> +k
    rows.append(("loop energy [J/m]", loop_energy(res["k"], th), W))
    return th, [(n, a, b, (b - a) / a if a else b) for n, a, b in rows]


ONSET = (0.9, 0.01, 1.3)          # first-slip ramp: one step to 0.9 kappa_b, then steps of 0.01 kappa_b up to 1.3


def first_slip(lays=LAYS, elements_per_lay=ELEMENTS, lay=LAY, ramp=ONSET, stick=None, sections=None):
    """First slip on the virgin branch, read from the stick flags of the contact points of the middle half:
    dict with ``kappa`` (the first step with a slipping point), ``kappa_b`` (the theory's, with the model's wire
    force), ``EI0`` (the stick branch's slope ``M / kappa`` at the first step), ``own`` (``kappa_b`` scaled by
    the model's stick part ``(EI_max - EI_min) / (EI0 - EI_min)``: where the model's own stick stiffness puts the
    onset, docs/theory_strand_bending.md section 5) and the run's ``res``.  ``ramp = (start, step, end)`` in
    units of ``kappa_b``: the stick branch is elastic, so one step reaches ``start``; then steps of ``step``
    (the flags resolve it)."""
    start, step, end = ramp
    n = int(round((end - start) / step))

    def curvature(t, k):                       # k = 1 kappa_b; t in [1, 2] in n + 1 equal steps
        x = (t - 1.0) * (n + 1)
        return k * (start * min(x, 1.0) + step * max(x - 1.0, 0.0))
    res = run(lays, elements_per_lay, amplitude=1.0, steps=n + 1, t_end=2.0, stick=stick, lay=lay,
              curvature=curvature, sections=sections)
    th = theory(res["F"], lay=lay)
    up = np.flatnonzero(res["times"] > 1.0)
    hit = up[res["share"][up] > 0]
    EI0 = res["M"][up[0]] / res["kappa"][up[0]]
    own = th["kappa_b"] * (th["EI_max"] - th["EI_min"]) / (EI0 - th["EI_min"])
    return dict(kappa=res["kappa"][hit[0]] if len(hit) else np.nan, kappa_b=th["kappa_b"], EI0=EI0, own=own,
                EI_max=th["EI_max"], res=res)


CHECK_STEPS = 1                  # steps per unit t of the stiffness checks: elastic, so path-independent


def stiffness_checks(lays=LAYS, elements_per_lay=ELEMENTS, steps=CHECK_STEPS, lay=LAY):
    """``(EI frictionless, EI tied)``: the initial slopes ``M / kappa`` of the strand with frictionless
    contact (full slip: against ``EI_min``) and with the wires tied rigidly to the core (against
    ``EI_max``), each on the virgin branch ``t`` in ``[1, 2]``, with their wire forces.  Both are elastic (no
    friction), so one step per unit ``t`` gives the slopes of four (4 lays, 48 el/lay: 13.31322 and 103.3276
    N m^2 either way) for 3.7 s of CPU instead of 7.5.  Their stability is not judged (``check_stability=False``): the
    frictionless long-lay strand (``--lay 229.2``, 4 lays) has torsion-bending modes of its outer wires that the
    frictionless contact barely holds, whose lowest eigenvalues (scaled -6e-7 .. -2e-6, the tangent's own, a finite
    difference of the residual gives the same) cross zero under the pull (t = 0.418); the stable-branch rule cut the
    check's steps back to 1/128 and warned, for the same slope (docs/benchmarks.md, session 9)."""
    out = []
    for kw in (dict(mu=0.0), dict(tied=True)):
        res = run(lays, elements_per_lay, amplitude=AMPLITUDE, steps=steps, t_end=2.0, lay=lay, check_stability=False,
                  **kw)
        j = np.flatnonzero(res["times"] > 1.0)[-1]
        out.append((res["M"][j] / res["kappa"][j], res["F"]))
    return out


ALONG = (0.05, 0.25, 0.5)         # cuts z / L of the printed moment along the strand


def moment_along(res, fractions=ALONG, step=None):
    """``(M - EI_min kappa) / M_f - 1`` across the cuts at ``z = fractions L`` at ``step`` (default: the
    end of the virgin branch): the friction moment along the strand (the tied ends carry more)."""
    sol, fx, th = res["sol"], res["fixture"], theory(res["F"], lay=res.get("lay", LAY))
    j = int(np.flatnonzero(res["times"] <= 2.0 + 1e-9)[-1]) if step is None else step
    k = res["kappa"][j]
    return np.array([(fx.moment(sol, fx.z0 + f * fx.length, step=j) - th["EI_min"] * k) / th["M_f"] - 1
                     for f in fractions])


def main(lays=LAYS, elements_per_lay=ELEMENTS, amplitude=AMPLITUDE, steps=STEPS, mu=MU, checks=True, lay=LAY,
         onset=False):
    res = run(lays, elements_per_lay, mu, amplitude, steps, lay=lay)
    (EI0, F0), (EIt, Ft) = stiffness_checks(lays, elements_per_lay, lay=lay) if checks else ((None, None), (None, None))
    th, rows = compare(res, EI0)
    if onset:
        fs = first_slip(lays, elements_per_lay, lay=lay)
        rows += [(name, ref, fs["kappa"], fs["kappa"] / ref - 1) for name, ref in
                 ((f"first slip on a ramp in steps of {ONSET[1]:g} kappa_b [1/m]", fs["kappa_b"]),
                  ("first slip against the model's own stick stiffness [1/m]", fs["own"]))]
    rows += [(f"M - EI_min kappa at z = {f:g} L, +k of the virgin branch, / M_f - 1", 0.0, e, e)
             for f, e in zip(ALONG, moment_along(res))]
    if checks:
        rows += [("EI frictionless contact (full slip) [N m^2]", theory(F0, lay=lay)["EI_min"], EI0,
                  EI0 / theory(F0, lay=lay)["EI_min"] - 1),
                 ("EI wires tied to the core (full stick) [N m^2]", theory(Ft, lay=lay)["EI_max"], EIt,
                  EIt / theory(Ft, lay=lay)["EI_max"] - 1)]
    print(f"1+6 strand (wires of Utting & Jones 1987): Rc = {RC * 1e3} mm, Rw = {RW * 1e3} mm, lay {lay * 1e3:.4g} mm, "
          f"beta = {np.degrees(th['beta']):.2f} deg, mu = {mu}, T = {res['T']:.4g} N, wire force F = {res['F']:.4g} N;"
          f" {lays} lays, {elements_per_lay} elements per lay, +-{amplitude} kappa_b, {steps} steps per unit t, "
          f"stick {STICK}" + (f", slip_tolerance {SLIP_TOLERANCE}" if STICK == "penalty" else ""))
    print("| quantity | theory | model | model / theory - 1 |")
    print("|---|---:|---:|---:|")
    for name, a, b, e in rows:
        print(f"| {name} | {a:.5g} | {b:.5g} | {e:+.3g} |")
    print(f"| Newton iterations / cut-backs / CPU time (wall time) of the cyclic run | | {res['iterations']} / "
          f"{res['cutbacks']} / {res['cpu']:.1f} s ({res['wall']:.1f} s) | |")
    return res, th, rows


def plot_loop(res, th, path):
    """PNG ``path`` of the moment-curvature loop of ``run``'s result ``res`` against the theory ``th`` (``compare``):
    the model's moment at the mid-length cut, the theory's virgin curve and Masing branches, ``EI_max`` and
    ``EI_min`` (matplotlib, the ``viz`` extra)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    t, kap, M = res["times"], res["kappa"], res["M"]
    kb = th["kappa_b"]
    x = np.linspace(0.0, res["k"], 200)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(kap[t >= 1] / kb, M[t >= 1], "o-", ms=3, label="beamsolver (cut at mid-length)")
    ax.plot(x / kb, moment(x, th), "k-", lw=1, label="theory, virgin")
    xr = np.linspace(res["k"], -res["k"], 400)
    rev = (res["k"], friction_moment(res["k"], th)[0])
    ax.plot(xr / kb, moment(xr, th, rev), "k--", lw=1, label="theory, Masing")
    ax.plot(-xr / kb, -moment(xr, th, rev), "k--", lw=1)
    ax.plot(x / kb, th["EI_max"] * x, ":", c="gray", label="EI_max (full stick)")
    ax.plot(x / kb, th["EI_min"] * x, "-.", c="gray", label="EI_min (full slip)")
    ax.set_xlabel("curvature / kappa_b")
    ax.set_ylabel("bending moment [N m]")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


MAP_SQUEEZE = 6.0                 # the stick/slip map's axial squeeze (a lay is 20 strand diameters long)


def stick_slip_map(res, th, path):
    """PNG at ``path`` of the contact points (stick blue, slip red) on the wires of the middle lay at the first step
    of the virgin branch where slip has spread part way (needs pyvista, the ``viz`` extra)."""
    import os
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista as pv
    sol, t = res["sol"], res["times"]
    k = int(np.flatnonzero((t > 1.0) & (res["share"] > 0) & (res["share"] < 1))[0])
    H = sol.poses[k]
    st = res["strand"]
    z_mid, half = 0.5 * st.length, 0.5 * res["lay"]
    pl = pv.Plotter(off_screen=True, window_size=(1200, 420))
    squeeze = MAP_SQUEEZE

    def squeezed(x):
        return np.column_stack([x[:, :2], z_mid + (x[:, 2] - z_mid) / squeeze])
    for w in st.all_wires:
        x = H[w.nodes, :3, 3]
        x = squeezed(x[np.abs(x[:, 2] - z_mid) <= half + 2 * (x[1, 2] - x[0, 2])])
        pl.add_mesh(pv.Spline(x, 8 * len(x)).tube(radius=0.9 * w.section.radius), color="lightgray", opacity=0.35)
    c = sol.contacts[k]
    on = (c["normal_force"] > 0) & (np.abs(c["position"][:, 2] - z_mid) <= half)
    for code, colour in ((bs.contact.STICK, "royalblue"), (bs.contact.SLIP, "crimson")):
        pts = squeezed(c["position"][on & (c["status"] == code)])
        if len(pts):
            pl.add_points(pv.PolyData(pts), color=colour, point_size=9, render_points_as_spheres=True,
                          label=bs.contact.STATUS_NAMES[code])
    pl.add_legend()
    pl.view_vector((0.0, -1.0, 0.0), viewup=(1.0, 0.0, 0.0))     # the strand axis e_z across the picture
    pl.enable_parallel_projection()
    pl.reset_camera()
    pl.camera.zoom(2.0)
    pl.add_text(f"middle lay (length squeezed {squeeze:g} times), kappa = {res['kappa'][k] / th['kappa_b']:.2f} kappa_b: slipping share "
                f"{res['share'][k]:.2f} (theory {2 * slip_angle(res['kappa'][k], th)[0] / np.pi:.2f}, middle half)",
                font_size=10)
    pl.screenshot(path)
    pl.close()


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lays", type=float, default=LAYS)
    ap.add_argument("--elements", type=int, default=ELEMENTS)
    ap.add_argument("--amplitude", type=float, default=AMPLITUDE)
    ap.add_argument("--steps", type=int, default=STEPS)
    ap.add_argument("--mu", type=float, default=MU)
    ap.add_argument("--stick", default=STICK, choices=("exact", "penalty"))
    ap.add_argument("--lay", type=float, default=LAY * 1e3,
                    help="lay length [mm] (default 229.2: lay ratio 20; Utting & Jones' own lay: 114.6)")
    ap.add_argument("--onset", action=argparse.BooleanOptionalAction, default=True,
                    help="also the first slip on a fine ramp (steps of 0.01 kappa_b from 0.9 kappa_b; the cycle's "
                         "steps are amplitude / steps kappa_b apart); --no-onset skips it")
    ap.add_argument("--plot", default=None, help="PNG of the loop against the theory (needs matplotlib)")
    ap.add_argument("--map", default=None, help="PNG of the stick/slip map where slip spreads (needs pyvista)")
    a = ap.parse_args()
    STICK = a.stick
    res, th, rows = main(a.lays, a.elements, a.amplitude, a.steps, a.mu, lay=a.lay * 1e-3, onset=a.onset)
    if a.plot:
        plot_loop(res, th, a.plot)
        print(f"written: {a.plot}")
    if a.map:
        stick_slip_map(res, th, a.map)
        print(f"written: {a.map}")
