"""Strain-free adjustment of initial overclosures (``add_contact(adjust=)``, ``contact.adjust``;
issue 28 item 10): the table, the radii it changes, a reference state without overlap forces."""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver.contact import adjust
from beamsolver.nonlinear.problem import Problem


def test_offsets_take_only_overlaps_within_the_tolerance():
    key = np.array([7, 3, 5, 9, 3], dtype=np.int64)
    gap = np.array([-1e-4, -2e-4, 1e-9, -5e-3, -1e-6])
    keys, delta, gap0 = adjust.offsets(key, gap, np.full(5, 1e-3))
    assert keys.tolist() == [3, 7] and np.allclose(delta, [2e-4, 1e-4]) and np.allclose(gap0, [-2e-4, -1e-4])
    assert len(adjust.offsets(key, gap, np.zeros(5))[0]) == 0                       # adjust=0: none
    assert adjust.summary((keys, delta, gap0)) == dict(count=2, largest=pytest.approx(2e-4))


def test_apply_reduces_the_radii_in_proportion_and_leaves_the_others():
    table = (np.array([3, 7], dtype=np.int64), np.array([2e-4, 1e-4]), np.array([-2e-4, -1e-4]))
    R1, R2 = np.array([0.02, 0.02, 0.02]), np.array([1.0, 1.0, 1.0])
    a1, a2 = adjust.apply(np.array([7, 4, 3], dtype=np.int64), R1, R2, table)
    np.testing.assert_allclose(a1 + a2, [1.02 - 1e-4, 1.02, 1.02 - 2e-4], rtol=0, atol=1e-15)
    np.testing.assert_allclose(a1 / a2, R1 / R2)                  # the contact point keeps its place


def _crossing(depth, **options):
    """Two crossing beams (radius 0.05) overlapping by ``depth`` at the crossing, the master clamped."""
    sec = bs.Section.circular(radius=0.05, E=1e7, nu=0.3)
    m = bs.Model()
    a = m.add_beam(bs.geometry.straight((-1, 0, 0), (1, 0, 0), 4), sec)
    b = m.add_beam(bs.geometry.straight((0, -1, 0.1 - depth), (0, 1, 0.1 - depth), 4), sec)
    m.clamp(a.first)
    m.clamp(a.last)
    m.clamp(b.first)
    m.add_contact(b, a, **options)
    return m


@pytest.mark.parametrize("depth, adjusted", [(5e-5, True), (5e-4, False)])
def test_an_adjusted_reference_state_carries_no_contact_force(depth, adjusted):
    """Default tolerance 1e-3 (R1 + R2) = 1e-4: an overlap of 5e-5 is adjusted away (no residual at
    the reference poses), one of 5e-4 keeps its penalty force."""
    p = Problem.from_model(_crossing(depth), check_rigid_modes=False)
    assert p.contact.adjusted["count"] == int(adjusted)
    r = p.evaluate(p.system.poses0, 0.0, tangent=False).r
    assert (np.abs(r).max() == 0.0) == adjusted
    if adjusted:
        assert p.contact.adjusted["largest"] == pytest.approx(depth, rel=1e-6)


def test_adjust_zero_and_a_larger_tolerance():
    assert Problem.from_model(_crossing(5e-5, adjust=0.0), check_rigid_modes=False).contact.adjusted["count"] == 0
    assert Problem.from_model(_crossing(5e-4, adjust=1e-3), check_rigid_modes=False).contact.adjusted["count"] == 1


@pytest.mark.parametrize("bad", [-1e-3, float("nan"), "0.1"])
def test_a_bad_adjust_is_refused_by_name(bad):
    with pytest.raises(bs.InputError, match="adjust"):
        _crossing(0.0, adjust=bad)
