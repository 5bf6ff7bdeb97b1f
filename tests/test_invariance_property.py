"""Property tests (issue 12): a rigid motion of a whole scene, a change of length unit with the
scene moved far from the origin, the number of load steps of a path-independent problem and the
slave/master order of a frictionless contact all give the correspondingly transformed answer.

Scenes: a cantilever under a dead end force and moment (conservative: path independent), and
two crossing beams clamped at both ends, pushed together by a dead force (frictionless).
Units: a length unit ``lam`` times the reference one scales positions and radii by ``lam``,
stiffnesses ``EA, GA`` by 1, ``GJ, EI`` by ``lam^2``, Young's modulus by ``lam^-2``, moments by
``lam`` (forces unchanged).
"""
import functools

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

import beamsolver as bs
from beamsolver import se3
from helpers import placed_crossing as crossing

RTOL = 1e-7          # solver rtol 1e-8 (residual), so answers agree to about this


def _motion(rotvec, direction, distance):
    """A rigid motion: rotation ``rotvec``, translation ``distance`` along ``direction``."""
    G = np.eye(4)
    G[:3, :3] = se3.exp_so3(np.asarray(rotvec, dtype=float))
    d = np.asarray(direction, dtype=float)
    G[:3, 3] = distance * d / max(np.linalg.norm(d), 1e-12)
    return G


def cantilever(G=np.eye(4), lam=1.0, steps=4):
    """A 10-unit cantilever along ``x`` (in units ``lam``) moved by ``G``; returns the solution,
    its tip and root nodes."""
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2 * lam**2, EI2=1e2 * lam**2, EI3=1.5e2 * lam**2,
                     radius=0.05 * lam)
    m = bs.Model()
    b = m.add_beam(G @ bs.geometry.straight((0, 0, 0), (10.0 * lam, 0, 0), 6), sec)
    m.clamp(b.first)
    R = G[:3, :3]
    m.add_load(b.last, force=R @ np.array([0.0, 3.0, 2.0]), moment=R @ np.array([0.0, 0.0, 5.0 * lam]))
    return bs.solve(m, steps=steps, verbose=False), b.last, b.first


@functools.lru_cache(maxsize=None)
def reference(scene):
    return {"cantilever": cantilever, "crossing": crossing}[scene]()


def assert_transformed(scene, got, G, lam):
    """``got`` (solution, node, support) is the reference answer moved by ``G`` in units ``lam``."""
    (s0, n0, c0), (s, n, c) = reference(scene), got
    R, p = G[:3, :3], G[:3, 3]
    size = (10.0 if scene == "cantilever" else 1.0) * lam
    np.testing.assert_allclose(s.position(n), R @ (lam * s0.position(n0)) + p, rtol=0,
                               atol=RTOL * (size + np.linalg.norm(p)) + 1e-9 * size)
    np.testing.assert_allclose(s.poses[-1][n, :3, :3], R @ s0.poses[-1][n0, :3, :3], rtol=0, atol=RTOL)
    f0, f = s0.reaction(c0), s.reaction(c)
    F = np.abs(f0[:3]).max()
    np.testing.assert_allclose(f[:3], R @ f0[:3], rtol=0, atol=RTOL * F * 10)
    np.testing.assert_allclose(f[3:], lam * (R @ f0[3:]), rtol=0, atol=RTOL * F * size * 10)


rotations = st.lists(st.floats(-np.pi, np.pi), min_size=3, max_size=3)
directions = st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3)


@settings(max_examples=60, deadline=None)
@example(rotvec=[0.3, -0.2, 0.1], direction=[1.0, 0.2, 0.0], log_distance=3.0, log_lam=3.0, steps=3)  # km in mm
@given(rotvec=rotations, direction=directions, log_distance=st.floats(0.0, 3.0),
       log_lam=st.floats(-3.0, 3.0), steps=st.integers(1, 6))
def test_cantilever_rigid_motion_units_far_away_and_step_count(rotvec, direction, log_distance, log_lam, steps):
    lam = 10.0**log_lam
    G = _motion(rotvec, direction, 10.0**log_distance * 10.0 * lam)    # up to 1000 lengths away
    assert_transformed("cantilever", cantilever(G, lam, steps), G, lam)


@settings(max_examples=20, deadline=None)
@given(rotvec=rotations, direction=directions, log_distance=st.floats(-1.0, 2.0),
       log_lam=st.floats(-2.0, 2.0), steps=st.integers(1, 3), swap=st.booleans())
def test_crossing_beams_rigid_motion_units_steps_and_slave_master_order(rotvec, direction, log_distance,
                                                                        log_lam, steps, swap):
    lam = 10.0**log_lam
    G = _motion(rotvec, direction, 10.0**log_distance * lam)
    got = crossing(G, lam, steps, swap)
    assert got[0].contact()["normal_force"].sum() > 1.0          # the beams do touch
    assert_transformed("crossing", got, G, lam)
