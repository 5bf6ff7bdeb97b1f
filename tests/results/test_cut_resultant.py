"""Resultants across a cut through a bundle (resultants.cut_resultant, Solution.cut_resultant,
Strand.cut): equilibrium with known end loads, a strand in pure tension, a bent beam."""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver import cables

SEC = bs.Section.circular(radius=0.01, E=1e9, nu=0.3)


def _cantilever(n=7, L=1.0):
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (0, 0, L), n), SEC)
    m.clamp(b.first)
    return m, b


@pytest.mark.parametrize("z", [0.0, 0.3, 3 / 7, 0.95])
def test_straight_beam_under_end_loads_carries_them_across_any_cut(z):
    m, b = _cantilever()
    F, M0 = np.array([30.0, -20.0, 500.0]), np.array([1.0, 2.0, -3.0])
    m.add_load(b.last, force=F, moment=M0)
    sol = bs.solve(m, steps=3)
    r = sol.cut_resultant(b, z, point=(0.0, 0.0, z))
    tip = sol.position(b.last)
    np.testing.assert_allclose(r.force, F, rtol=1e-10)
    np.testing.assert_allclose(r.moment, M0 + np.cross(tip - (0, 0, z), F), rtol=1e-9, atol=1e-9)
    assert r.axial == pytest.approx(F @ r.axis, rel=1e-12)
    assert r.axis @ (0, 0, 1) > 0.99


def test_uniform_line_load_is_carried_by_the_part_beyond_the_cut():
    m, b = _cantilever(n=10)
    q = np.array([2.0, 0.0, 0.0])
    m.add_line_load(b, force_per_length=q)
    sol = bs.solve(m, steps=2, rtol=1e-12)       # equilibrium to 1e-12: the cut force to round-off
    for z in (0.3, 0.35):                 # at a node and inside an element: F = q (L - z) exactly
        r = sol.cut_resultant(b, z, bending_axis=(0, 1, 0))
        np.testing.assert_allclose(r.force, q * (1.0 - z), rtol=1e-9, atol=1e-9)
        # small deflection: M_y = -q (L - z)^2 / 2 about the cut point
        assert r.bending[0] == pytest.approx(q[0] * (1 - z) ** 2 / 2, rel=2e-3)


def test_bent_beam_carries_the_end_moment_whatever_the_rotation():
    m, b = _cantilever(n=12)
    EI = SEC.C[4, 4]
    M0 = 1.5 * EI                       # curvature 1.5 / L: the tip turns by 1.5 rad
    m.add_load(b.last, moment=(0.0, M0, 0.0))
    sol = bs.solve(m, steps=4)
    res = sol.cut_resultant(b, 0.5, step=None)
    assert res.bending.shape == (5, 2)
    np.testing.assert_allclose(res.bending[:, 0], M0 * sol.times, rtol=1e-9, atol=1e-9 * M0)
    np.testing.assert_allclose(res.axial, 0.0, atol=1e-9 * M0)
    # the deformed axis at mid-length has turned by half the tip rotation
    assert np.degrees(np.arccos(res.axis[-1] @ (0, 0, 1))) == pytest.approx(np.degrees(0.75), rel=1e-6)


def test_strand_in_pure_tension_has_no_bending_moment_and_carries_the_pull():
    beta = np.deg2rad(12.0)
    L = 0.5 * 2 * np.pi * 2.1e-3 / np.tan(beta)
    st = cables.build_strand([cables.Layer(1.1e-3, 1), cables.Layer(1.0e-3, 6, lay_angle=beta)], L, 200e9,
                             elements_per_lay=16)
    st.clamp("bottom")
    plate = st.plate("top")
    st.model.prescribe(plate, bs.motion.translation((0.0, 0.0, 2e-4 * L)))
    sol = bs.solve(st.model, steps=1)
    F, T = st.resultant(sol, plate)
    for z in (0.25 * L, 0.5 * L):
        cut = st.cut(sol, z)
        assert F > 0 and cut.axial == pytest.approx(F, rel=1e-6)     # the plate pulls the upper part
        assert cut.torque == pytest.approx(T, rel=1e-4)
        assert np.abs(cut.bending).max() < 1e-6 * abs(F) * 2.1e-3
        assert st.resultant(sol, z=z) == (cut.axial, cut.torque)
    with pytest.raises(bs.InputError, match="crosses"):
        st.cut(sol, 2 * L)
