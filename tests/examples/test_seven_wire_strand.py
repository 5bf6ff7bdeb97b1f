"""The 1+6 strand example against the fibre limit of strand theory (reduced set of angles)."""

import numpy as np
import pytest


import seven_wire_strand


@pytest.fixture(scope="module")
def rows():
    return seven_wire_strand.main(angles=(5.0, 15.0))


def test_fixed_end_stiffness_and_torque_near_fibre_limit(rows):
    for beta, kf, kee, mf, kew, *_ in rows:
        assert kf == pytest.approx(kee, rel=0.03), beta
        assert kf <= kee * 1.0001, beta          # the fibre limit is an upper bound here
        assert mf == pytest.approx(kew, rel=0.10), beta


def test_trends_with_lay_angle_and_free_ends(rows):
    (b5, k5, _, m5, *_), (b15, k15, _, m15, *_) = rows
    assert k15 < k5 and m15 > m5                 # stiffness falls, torque coupling grows with the angle
    for beta, kf, kee, mf, kew, kr, kfree, phi, kfree_rod, kee_rod, kew_rod in rows:
        assert kr < kf                           # the plate untwists: free ends are softer
        assert phi < 0                           # a right-hand lay untwists under tension
        assert kr > 1.4 * kfree                  # the fibre K_ww omits wire torsion
        assert kr == pytest.approx(kfree_rod, rel=0.02), beta    # the rod theory has it
        assert kf == pytest.approx(kee_rod, rel=0.01), beta


def test_rod_theory_tends_to_the_fibre_limit_for_thin_wires():
    """The wires' bending and torsion terms scale as ``R_w^4`` against the fibre terms'
    ``R_w^2``: at a fixed pitch radius, ten times thinner wires make the relative
    correction of ``K_ew`` (no core term) exactly 100 times smaller."""
    from beamsolver import cables
    b = np.deg2rad(12.0)
    rel = []
    for Rw in (1e-3, 1e-4):
        f = np.array(cables.fibre_stiffness(1e-3, Rw, 6, 2e-3, b, 2e11))
        r = np.array(cables.rod_stiffness(1e-3, Rw, 6, 2e-3, b, 2e11))
        rel.append(np.abs(r - f) / np.abs(f))
        # a stiffness matrix: symmetric positive definite, stiffer than the fibre limit
        K = np.array([[r[0], r[1]], [r[1], r[2]]])
        assert np.all(np.linalg.eigvalsh(K) > 0)
        assert r[0] >= f[0] and r[2] > f[2]
    assert rel[0][1] == pytest.approx(100.0 * rel[1][1], rel=1e-9)
    assert rel[0][1] > 0.01                    # and not negligible for the example's wires
