"""The shallow sinusoidal arch traced by arc length through both limit points against the
shallow-arch (Marguerre) closed form ``q(a) = EI (pi/L)^4 [(e - a) + a (e^2 - a^2) / (4 r^2)]``
(docs/theory.md, "The shallow sinusoidal arch"; ``examples/limit_points.shallow_arch``)."""
import warnings

import numpy as np
import pytest

import beamsolver as bs

from limit_points import (first_peak, heights, limits, shallow_arch, shallow_arch_limits,
                          shallow_arch_load)

RISE = 0.005          # e / L: shallow, so the shallow-arch theory itself is off by about 1e-4


def trace(n_elements, check_stability=False):
    """``(t, a / e, closed-form t at a, closed-form lower limit in t, solution)`` along the path; the
    load is scaled by the closed-form upper limit (so it is at ``t = 1``)."""
    m, mid, r = shallow_arch(n_elements, RISE)
    q_max, _, q_min = shallow_arch_limits(RISE, r)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bs.StabilityWarning)     # the unstable branch is expected
        sol = bs.solve(m, steps=10, t_end=1.5, path="arc-length", verbose=False, check_stability=check_stability)
    a = heights(sol, mid)
    return sol.times, a / RISE, shallow_arch_load(a, RISE, r) / q_max, q_min / q_max, sol


@pytest.fixture(scope="module")
def fine():
    return trace(64, check_stability=True)


def test_shallow_arch_snaps_through_and_back_up(fine):
    """The load goes up to the upper limit, down the unstable branch to the lower limit and up again
    to ``t_end``; the crown goes only down, from ``e`` through the chord to below ``-a*``."""
    t, a, _, _, sol = fine
    assert sol.converged and t[-1] == 1.5
    k = first_peak(t)
    j = k + int(np.argmin(t[k:]))
    assert 0 < k < j < len(t) - 1
    assert np.all(np.diff(t[:k + 1]) > 0) and np.all(np.diff(t[k:j + 1]) < 0) and np.all(np.diff(t[j:]) > 0)
    assert np.all(np.diff(a) < 0) and a[0] == pytest.approx(1.0) and a[-1] < -0.8


def test_shallow_arch_limit_loads_against_the_closed_form(fine):
    """Both limit loads within 1 % of the closed form (measured: upper +1.0e-4, lower +8.7e-4 with
    64 elements, e / L = 0.005), and every converged point on the closed-form curve."""
    t, a, t_closed, t_min, _ = fine
    upper, lower = limits(t, a)
    assert abs(upper - 1.0) < 1e-3
    assert abs(lower / t_min - 1.0) < 2e-3
    np.testing.assert_allclose(t, t_closed, rtol=0, atol=1e-3)      # measured 2.9e-4


def test_shallow_arch_is_unstable_exactly_between_its_limits(fine):
    """One negative eigenvalue from the upper to the lower limit, none outside: for ``e / r = 3.5 < 4``
    the symmetric path has limit points and no bifurcation."""
    t, a, _, _, sol = fine
    neg = np.array([s["negative_eigenvalues"] for s in sol.stats[1:]])
    a_star = np.sqrt((1.0 - 4.0 / 3.5**2) / 3.0)          # a* / e
    inside = np.abs(a[1:]) < a_star
    clear = np.abs(np.abs(a[1:]) - a_star) > 0.05            # away from the limits themselves
    assert np.all(neg[inside & clear] == 1) and np.all(neg[~inside & clear] == 0)
    assert neg.max() == 1


def test_shallow_arch_converges_under_mesh_refinement(fine):
    """Halving the elements (64 -> 32) multiplies the distance to the closed form by more than 3
    (measured 6.7 pointwise, 8.7 at the upper limit): second order, not a floor."""
    t, a, t_closed, _, _ = fine
    t32, a32, t_closed32, _, _ = trace(32)
    fine_err, coarse_err = np.abs(t - t_closed).max(), np.abs(t32 - t_closed32).max()
    assert coarse_err > 3.0 * fine_err
    assert abs(limits(t32, a32)[0] - 1.0) > 3.0 * abs(limits(t, a)[0] - 1.0)
