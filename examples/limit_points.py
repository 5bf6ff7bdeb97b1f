"""Limit points traced by arc length (``solve(..., path="arc-length")``): three classic scenes.

Material: none, dimensionless benchmarks in consistent units (no yield limit); their largest
equivalent surface strains (printed) are below 0.005 (the truss) and 0.02.

- ``truss``: the shallow von Mises (two-bar) truss, its symmetric half, with the closed-form
  load-deflection curve ``truss_load`` and limit ``truss_limit``; snaps through and back up.
- ``deep_arch``: DaDeppo & Schmidt's clamped-hinged 215-degree arch under a crown load, limit
  load ``P_CR_DADEPPO = 8.97 EI / R^2`` (DaDeppo, D.A. and Schmidt, R., 1975, "Instability of
  clamped-hinged circular arches subjected to a point load", J. Appl. Mech. 42, 894-896).
- ``lee_frame``: Lee's right-angle frame, a snap-back (the deflection turns back as well).
- ``shallow_arch``: a pinned-pinned shallow sinusoidal arch under a sinusoidal dead load, whose
  shallow-arch (Marguerre) closed form ``shallow_arch_load`` has an upper and a lower limit point
  ``shallow_arch_limits`` (docs/theory.md, "The shallow sinusoidal arch"); snaps through and back up.

``first_peak`` and ``peak`` find the limit point on a traced path.  Run
``python examples/limit_points.py`` to print the limit loads; ``beamsolver run`` solves the truss.
"""
import numpy as np

import beamsolver as bs

A_HALF, RISE, EA = 1.0, 0.1, 1e4               # truss: half span, rise, axial stiffness of a bar
R_ARCH, EI_ARCH = 100.0, 1e6                   # deep arch: radius, bending stiffness
P_CR_DADEPPO = 8.97 * EI_ARCH / R_ARCH**2      # 897
LEE_L, LEE_E, LEE_A, LEE_I = 120.0, 720.0, 6.0, 2.0    # Lee's frame: member length, E, A, I

ARCH_SPAN, ARCH_EI = 1.0, 1.0                   # shallow arch: span, in-plane bending stiffness

solve_options = dict(steps=10, t_end=1.5, path="arc-length")   # for `beamsolver run`: the truss


def truss_load(y):
    """Apex load carried by one bar with the apex at height ``y`` (a pinned straight bar,
    ``N = EA (L / L0 - 1)``): ``P = EA y (1 / L - 1 / L0)`` (docs/theory.md eq. 16.9)."""
    L0, L = np.hypot(A_HALF, RISE), np.hypot(A_HALF, y)
    return EA * y * (1.0 / L - 1.0 / L0)


def truss_limit():
    """Closed-form limit ``(load, apex height)``: ``dP/dy = 0`` where ``L^3 = L0 a^2``."""
    L0 = np.hypot(A_HALF, RISE)
    y = np.sqrt((L0 * A_HALF**2) ** (2.0 / 3.0) - A_HALF**2)
    return truss_load(y), y


def truss(load=None):
    """Half of the symmetric von Mises truss: one bar pinned at ``(-a, 0)`` (only ``rz`` free), the
    apex on the symmetry line (``ux`` fixed, ``rz`` free: no end moments, the bar stays straight; it is
    stiff in bending, so it does not buckle itself);
    apex load ``(0, -load t, 0)`` (default: the limit load, so the limit is at ``t = 1``).
    Returns ``(model, apex node)``."""
    load = truss_limit()[0] if load is None else load
    # bars stiff in bending: Euler load pi^2 EI / L^2 about 200 times the largest compression
    sec = bs.Section(EA=EA, GA2=EA, GA3=EA, GJ=1e3, EI2=1e3, EI3=1e3, radius=0.01)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight(start=(-A_HALF, 0, 0), end=(0, RISE, 0), n_elements=2), sec)
    m.fix(b.first, dofs=("ux", "uy", "uz", "rx", "ry"))
    m.fix(b.last, dofs=("ux", "uz", "rx", "ry"))
    m.add_load(b.last, force=(0, -load, 0))
    return m, b.last


def build():
    return truss()


def deep_arch(n_elements=40, element=None):
    """Clamped-hinged circular arch (radius 100, 215 degrees), crown load ``(0, -1000 t, 0)``.

    ``EI = 1e6``, ``EA = GA = 100 EI`` (as in Kadapa 2021, Eng. Struct. 234, 111755), square-like
    section (``EI2 = EI3 = GJ``): the path stays in the plane.  Hinge at the first node (``rz``
    free), clamp at the last.  ``n_elements`` segments between nodes; ``element``: the element type
    (``Model.add_beam``; ``"se3-3"``: ``n_elements / 2`` three-node elements).  Returns
    ``(model, crown node)``.
    """
    sec = bs.Section(EA=100 * EI_ARCH, GA2=100 * EI_ARCH, GA3=100 * EI_ARCH, GJ=EI_ARCH, EI2=EI_ARCH,
                     EI3=EI_ARCH, radius=1.0)
    P = bs.geometry.arc(radius=R_ARCH, angle=np.radians(215.0), n_elements=n_elements)
    c, a = np.array([0.0, R_ARCH, 0.0]), np.radians(72.5)       # turn about the centre: crown on top
    G = np.eye(4)
    G[:3, :3] = [[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]]
    G[:3, 3] = c - G[:3, :3] @ c
    m = bs.Model()
    b = m.add_beam(G @ P, sec, element=element)
    m.fix(b.first, dofs=("ux", "uy", "uz", "rx", "ry"))
    m.clamp(b.last)
    crown = int(b.nodes[len(b.nodes) // 2])
    m.add_load(crown, force=(0, -1000.0, 0))
    return m, crown


def lee_frame(n_per_member=10):
    """Lee's frame: a column ``(0, 0) -> (0, L)`` and a beam ``(0, L) -> (L, L)`` rigidly joined, both
    far ends pinned (``rz`` free), a downward load ``20 t`` at ``L / 5`` from the corner; ``E = 720``,
    ``A = 6``, ``I = 2``, ``L = 120`` (load in units of ``EI / L^2`` is ``P L^2 / EI``).
    Returns ``(model, loaded node)``."""
    G = LEE_E / 2.6 * LEE_A * 5.0 / 6.0
    sec = bs.Section(EA=LEE_E * LEE_A, GA2=G, GA3=G, GJ=LEE_E * LEE_I, EI2=LEE_E * LEE_I, EI3=LEE_E * LEE_I,
                     radius=1.0)
    m = bs.Model()
    col = m.add_beam(bs.geometry.straight((0, 0, 0), (0, LEE_L, 0), n_per_member), sec)
    beam = m.add_beam(bs.geometry.straight((0, LEE_L, 0), (LEE_L, LEE_L, 0), n_per_member), sec)
    m.join(col.last, beam.first)
    m.fix(col.first, dofs=("ux", "uy", "uz", "rx", "ry"))
    m.fix(beam.last, dofs=("ux", "uy", "uz", "rx", "ry"))
    node = int(beam.nodes[n_per_member // 5])
    m.add_load(node, force=(0, -20.0, 0))
    return m, node


def argyris_frame(F, imperfection=1e-4, n=10):
    """Argyris' right-angle frame: legs of 240 mm, section 30 x 0.6 mm, ``E = 71240`` N/mm^2,
    ``nu = 0.31``, clamped at one end; at the tip an in-plane force ``F`` (N) along the clamped leg
    with an out-of-plane ``imperfection * F``; lateral buckling near ``F = 1.09`` N.  ``n``
    elements per leg.  Returns ``(model, tip beam)``."""
    m = bs.Model()
    sec = bs.Section.rectangular(width=0.6, height=30.0, E=71240.0, nu=0.31)
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (0, 240, 0), n, e2=(0, 0, 1)), sec)
    b = m.add_beam(bs.geometry.straight((0, 240, 0), (240, 240, 0), n, e2=(0, 0, 1)), sec)
    m.join(a.last, b.first)
    m.clamp(a.first)
    m.add_load(b.last, force=(0, F, imperfection * F))
    return m, b


def shallow_arch_load(a, rise, r, span=ARCH_SPAN, EI=ARCH_EI):
    """Amplitude ``q`` of the load ``q sin(pi x / L)`` holding the shallow pinned arch
    ``e sin(pi x / L)`` (``e = rise``, radius of gyration ``r``) at midspan height ``a``:
    ``q = EI (pi / L)^4 [(e - a) + a (e^2 - a^2) / (4 r^2)]`` (docs/theory.md, shallow arch)."""
    return EI * (np.pi / span) ** 4 * ((rise - a) + a * (rise**2 - a**2) / (4.0 * r**2))


def shallow_arch_limits(rise, r, span=ARCH_SPAN, EI=ARCH_EI):
    """``(q_max, a_star, q_min)``: the upper limit at ``a = a_star = sqrt((e^2 - 4 r^2) / 3)``, the
    lower at ``a = -a_star``; there are limit points only for ``e > 2 r``."""
    if rise <= 2.0 * r:
        raise bs.InputError(f"shallow_arch_limits: rise {rise!r} <= 2 r = {2.0 * r!r}: no limit point")
    a = np.sqrt((rise**2 - 4.0 * r**2) / 3.0)
    return shallow_arch_load(a, rise, r, span, EI), a, shallow_arch_load(-a, rise, r, span, EI)


def shallow_arch(n_elements=32, rise=0.01, rise_over_r=3.5, load=None):
    """Pinned-pinned shallow arch ``y = e sin(pi x / L)``, ``0 <= x <= L = 1`` (``e = rise * L``),
    in the x-y plane, under the dead load ``q sin(pi x / L) t`` downwards as consistent nodal forces
    (``load``: ``q``, default the closed-form upper limit, so it is at ``t = 1``).

    ``EI = 1`` in plane (``EI3``), ``EA = EI / r^2`` with ``r = e / rise_over_r`` (below 4: limit points,
    no bifurcation), ``GA = EA``; out of plane 100 times stiffer (``EI2``, ``GJ``) so the arch stays in
    its plane.  Supports fixed in ``ux, uy, uz, rx, ry`` (``rz`` free).  ``n_elements`` even.
    Returns ``(model, midspan node, r)``."""
    if n_elements % 2:
        raise bs.InputError(f"shallow_arch: n_elements must be even (a node at midspan), got {n_elements!r}")
    L, e = ARCH_SPAN, rise * ARCH_SPAN
    r = e / rise_over_r
    q = shallow_arch_limits(e, r)[0] if load is None else load
    EA = ARCH_EI / r**2
    sec = bs.Section(EA=EA, GA2=EA, GA3=EA, GJ=100 * ARCH_EI, EI2=100 * ARCH_EI, EI3=ARCH_EI, radius=r)
    x = np.linspace(0.0, L, n_elements + 1)
    k = np.pi / L
    points = np.stack([x, e * np.sin(k * x), 0 * x], axis=-1)
    tangents = np.stack([np.ones_like(x), e * k * np.cos(k * x), 0 * x], axis=-1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.frames_from_tangents(points, tangents, e2=(0, 1, 0)), sec)
    for end in (b.first, b.last):
        m.fix(end, dofs=("ux", "uy", "uz", "rx", "ry"))
    for node, f in zip(b.nodes, _sine_nodal_forces(x, q * L / np.pi)):
        m.add_load(int(node), force=(0.0, -f, 0.0))
    return m, int(b.nodes[n_elements // 2]), r


def _sine_nodal_forces(x, scale):
    """Consistent nodal forces ``int q(x) N_i(x) dx`` of ``q sin(pi x / L)`` on the hat functions of the
    nodes ``x`` (``0 .. L``), exactly: ``scale = q L / pi``, element by element."""
    k = np.pi / x[-1]
    a, b = k * x[:-1], k * x[1:]
    h = b - a
    # int_a^b sin(s) (b - s) / h ds  and  int_a^b sin(s) (s - a) / h ds
    left = (np.cos(a) * h - np.sin(b) + np.sin(a)) / h
    right = (-np.cos(b) * h + np.sin(b) - np.sin(a)) / h
    f = np.zeros_like(x)
    f[:-1] += left
    f[1:] += right
    return scale * f


def first_peak(t):
    """Index of the first local maximum of ``t`` along a path (the limit point)."""
    down = np.flatnonzero(np.diff(t) < 0)
    return int(down[0]) if len(down) else len(t) - 1


def peak(t, y):
    """``t`` at the limit point: the parabola in ``y`` through the first local maximum of the path
    and its two neighbours, at its vertex."""
    k = first_peak(t)
    if 0 < k < len(t) - 1:
        c = np.polyfit(y[k - 1:k + 2], t[k - 1:k + 2], 2)
        if c[0] < 0:
            return float(np.polyval(c, -c[1] / (2 * c[0])))
    return float(t[k])


def turning_point(t, y, k):
    """``t`` at the turning point of the path near step ``k`` (a local maximum or minimum of ``t``):
    the extremum of the cubic in ``y`` fitted to the steps ``k - 2 .. k + 2`` nearest ``y[k]`` (the
    shallow arch's ``q(a)`` is a cubic, so the fit adds no error of its own there)."""
    s = slice(max(k - 2, 0), min(k + 3, len(t)))
    c = np.polyfit(y[s], t[s], 3)
    roots = np.roots(np.polyder(c))
    roots = roots[np.isreal(roots)].real
    if not len(roots):
        return float(t[k])
    return float(np.polyval(c, roots[np.argmin(np.abs(roots - y[k]))]))


def limits(t, y):
    """``(upper, lower)``: ``t`` at the first local maximum of the path and at the lowest point after
    it, each refined by ``turning_point``."""
    k = first_peak(t)
    j = k + int(np.argmin(t[k:]))
    return turning_point(t, y, k), turning_point(t, y, j)


def heights(sol, node):
    """Vertical position of ``node`` at every step."""
    return np.array([sol.position(node, k)[1] for k in range(sol.n_steps + 1)])


if __name__ == "__main__":
    import warnings
    m, apex = truss()
    sol = bs.solve(m, path="arc-length", **{k: v for k, v in solve_options.items() if k != "path"})
    print(f"truss: limit t = {peak(sol.times, heights(sol, apex)):.5f} (closed form 1), "
          f"{sol.n_steps} steps, lowest t {sol.times.min():.3f}")
    print(f"  {sol.material_summary()}")
    import logging
    m, crown = deep_arch()
    quiet = logging.getLogger("beamsolver")
    level, quiet.level = quiet.level, logging.ERROR
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)    # the solver's "t_end not reached": see below
            sol = bs.solve(m, steps=40, path="arc-length", arc_length=dict(max_steps=230))
    finally:
        quiet.level = level
    print(f"deep arch: limit load {1000 * peak(sol.times, heights(sol, crown)):.1f} "
          f"(DaDeppo & Schmidt {P_CR_DADEPPO:.0f}); traced {sol.n_steps} arc-length steps (max_steps) to "
          f"t = {sol.times[-1]:.3g}, past the limit point, as intended (the path does not return to t = 1)")
    print(f"  {sol.material_summary()}")
