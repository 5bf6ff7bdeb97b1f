"""The 1+6 strand example against the fibre limit of strand theory (reduced set of angles)."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import seven_wire_strand  # noqa: E402


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
    for beta, kf, kee, mf, kew, kr, kfree, phi, kfree_t in rows:
        assert kr < kf                           # the plate untwists: free ends are softer
        assert phi < 0                           # a right-hand lay untwists under tension
        assert kr > kfree                        # the fibre K_ww omits wire torsion
        assert kr == pytest.approx(kfree_t, rel=0.12)
