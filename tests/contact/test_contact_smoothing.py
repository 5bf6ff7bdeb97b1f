"""The smoothed normal law: C1, untouched above the smoothing zone, sharp when w = 0."""
import numpy as np
import pytest

from beamsolver.contact.law import normal_force

PEN, W = 2e11, 1e-6


def test_sharp_law_when_smoothing_is_zero():
    g = np.array([-2e-6, -1e-9, 0.0, 1e-9])
    lam, active = normal_force(g, PEN, 0.0, 0.0)
    np.testing.assert_allclose(lam, np.maximum(-PEN * g, 0.0))
    assert list(active) == [True, True, True, False]


def test_smoothed_law_is_c1_and_exact_outside_the_zone():
    g = np.linspace(-3 * W, 3 * W, 6001)
    lam, active = normal_force(g, PEN, 0.0, W)
    far = g <= -W
    np.testing.assert_allclose(lam[far], -PEN * g[far], rtol=1e-12)
    assert np.all(lam[g >= W] == 0.0) and not active[g >= W].any()
    assert np.all(np.diff(lam) <= 0)          # monotone
    # derivative by complex step, continuous across both ends of the zone
    d = np.imag(normal_force(g + 1e-30j, PEN, 0.0, W)[0]) / 1e-30
    jumps = np.abs(np.diff(d)) / PEN
    assert jumps.max() < 2 * (g[1] - g[0]) / W  # no jump larger than the parabola's slope change
    assert d[np.argmin(np.abs(g - W))] == pytest.approx(0.0, abs=PEN * 2e-3)
    assert d[np.argmin(np.abs(g + W))] == pytest.approx(-PEN, rel=2e-3)


def test_smoothed_law_with_multiplier_shifts_the_trial():
    lam0, _ = normal_force(np.array([-5e-6]), PEN, 0.0, W)
    lam1, _ = normal_force(np.array([0.0]), PEN, PEN * 5e-6, W)
    np.testing.assert_allclose(lam0, lam1)
