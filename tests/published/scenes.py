"""Scenes of the published cases (tests/published/test_*.py): built here once, solved by the tests."""

import numpy as np

import beamsolver as bs

from limit_points import argyris_frame  # noqa: F401  (Argyris' frame, the example's scene)


def column(n=16, ratio=1.1, kick=0.01, EI3=1.0, EI2=4.0, EA=1e7):
    """Clamped-free column along +x (L = 1), dead tip force ``(-ratio, kick, 0) P_cr`` with
    ``P_cr = pi^2 EI3 / 4`` (in plane), ``EI2`` out of plane.  Returns ``(model, beam, P_cr)``."""
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n),
                   bs.Section(EA=EA, GA2=EA, GA3=EA, GJ=1.0, EI2=EI2, EI3=EI3, radius=0.01))
    m.clamp(b.first)
    P_cr = np.pi**2 * EI3 / 4.0
    m.add_load(b.last, force=(-ratio * P_cr, kick * P_cr, 0.0))
    return m, b, P_cr


def twisted_wire(n=8, turns=2.25, radius=0.5e-3, length=0.02, E=200e9, nu=0.3):
    """A straight wire clamped at one end, the other end turned about the wire's axis by
    ``turns`` over ``0 <= t <= 1`` (all its motions prescribed).  Returns ``(model, beam, section)``."""
    sec = bs.Section.circular(radius=radius, E=E, nu=nu)
    m = bs.Model()
    w = m.add_beam(bs.geometry.straight((0, 0, 0), (0, 0, length), n), sec)
    m.clamp(w.first)
    m.prescribe(w.last, bs.motion.rotation((0, 0, 1), 2.0 * np.pi * turns))
    return m, w, sec


def _rope(m, x, t, r, EA, EI, polyline):
    GA = EA / 2.6
    sec = bs.Section(EA=EA, GA2=GA, GA3=GA, GJ=EI, EI2=EI, EI3=EI, radius=r)
    P = bs.geometry.polyline(x) if polyline else bs.geometry.frames_from_tangents(x, t, e2=(0, 0, 1))
    return m.add_beam(P, sec)


def capstan(mu, theta, R, r, n_arc, pitch=0.0, polyline=False, EA=1e5, EI=1e-5, T_hold=1.0, pull=2e-3,
            straight=0.01, post_length=0.1, t_hold=0.25, **contact):
    """A rope wrapped by ``theta`` round a clamped post (radius ``R``, axis e_z) on the helix of
    radius ``R + r`` and ``pitch`` (its centre line touching the post), straight tangent ends of
    length ``straight``: the held end carries a dead force ``T_hold`` ramped from 0 over
    ``t <= t_hold``, the pulled end is fixed, then moved by ``pull`` along its tangent.
    ``polyline``: the rope through the same points by ``geometry.polyline`` (its elements cut
    slightly into the post where the arc meets the straight ends).  Returns ``(model, rope,
    outward tangent of the pulled end)``."""
    m = bs.Model()
    post = m.add_beam(bs.geometry.straight((0, 0, -0.5 * post_length), (0, 0, 0.5 * post_length), 8),
                      bs.Section.circular(radius=R, E=1e9))
    m.clamp(post.first)
    m.clamp(post.last)
    rc, c = R + r, pitch / (2.0 * np.pi)
    phi = np.linspace(-0.5 * theta, 0.5 * theta, n_arc + 1)
    xa = np.stack([rc * np.cos(phi), rc * np.sin(phi), c * phi], axis=1)
    ta = np.stack([-rc * np.sin(phi), rc * np.cos(phi), c + 0.0 * phi], axis=1)
    ta /= np.linalg.norm(ta, axis=1)[:, None]
    ns = max(2, int(np.ceil(straight / np.linalg.norm(xa[1] - xa[0]))))
    s = np.linspace(straight, 0.0, ns + 1)[:-1]
    x = np.concatenate([xa[0] - s[:, None] * ta[0], xa, xa[-1] + s[::-1, None] * ta[-1]])
    t = np.concatenate([np.repeat(ta[:1], ns, 0), ta, np.repeat(ta[-1:], ns, 0)])
    rope = _rope(m, x, t, r, EA, EI, polyline)
    m.add_load(rope.first, force=-T_hold * ta[0], scale=lambda s: min(s / t_hold, 1.0))
    m.prescribe(rope.last, bs.motion.translation(lambda s: pull * max(s - t_hold, 0.0) / (1.0 - t_hold) * ta[-1]))
    m.add_contact(rope, post, mu=mu, **contact)
    return m, rope, ta[-1]


