"""Sweep of the singular coefficients of ``se3.coefficient`` against 200-digit arithmetic."""
import mpmath as mp
import numpy as np
import pytest

from beamsolver import se3

mp.mp.dps = 200


def _reference(name, t):
    """Closed form of coefficient ``name`` at the double ``t`` in 200-digit arithmetic."""
    t = mp.mpf(float(t))
    s, c = mp.sin(t), mp.cos(t)
    forms = {
        "a": lambda: s / t,
        "b": lambda: (1 - c) / t**2,
        "c": lambda: (t - s) / t**3,
        "d": lambda: (1 - (t / 2) * mp.cot(t / 2)) / t**2,
        "q2": lambda: (t * t + 2 * c - 2) / (2 * t**4),
        "q3": lambda: (2 * t - 3 * s + t * c) / (2 * t**5),
        "cp": lambda: (3 * s - t * c - 2 * t) / t**5,
        "dp": lambda: (t * t / mp.sin(t / 2) ** 2 + 2 * t * mp.cot(t / 2) - 8) / (4 * t**4),
        "q2p": lambda: (-t * t - t * s - 4 * c + 4) / t**6,
        "q3p": lambda: (-8 * t + 15 * s - 7 * t * c - t * t * s) / (2 * t**7),
    }
    return forms[name]()


# Bounds stated in se3.py's comment above SWITCH (worst relative error over
# t in [1e-12, 5]), tightened where the sweep does better.
DOCUMENTED = {"a": 2e-15, "b": 2e-15, "c": 2e-15, "q2": 2e-15, "d": 3e-15, "q3": 5e-15,
              "cp": 5e-15, "dp": 2.5e-13, "q2p": 8e-15, "q3p": 1.5e-14}
TIGHTENED = {"a": 5e-16, "b": 5e-16, "c": 5e-16, "q2": 1e-15, "q3": 2e-15, "cp": 3e-15,
             "q2p": 6e-15}
# Measured (dense sampling, 3000 points near each worst spot): d 2.2e-15
# (t = 0.77), dp 1.8e-13 (t = 1.06, closed form just above its switch 1.0),
# q3p 1.13e-14 (t = 2.02).  With nine series terms the series and closed-form
# errors of dp cross near 1e-13 (series 5.6e-14, closed form 1.6e-13 at t = 1),
# so no switch point does better; the documented bounds state these levels.
MEASURED_CAP = {"d": 3e-15, "dp": 2.5e-13, "q3p": 1.5e-14}


def _sweep_points(name):
    sw = se3.SWITCH[name]
    around = [np.nextafter(sw, 0.0), sw, np.nextafter(sw, 10.0), sw * (1 - 1e-9), sw * (1 + 1e-9),
              sw * (1 - 1e-4), sw * (1 + 1e-4), sw * 0.99, sw * 1.01]
    return np.concatenate([np.logspace(-12, 0.7, 400), around])


def _errors(name, t):
    got = se3.coefficient(name, t)
    assert got.shape == t.shape and np.all(np.isfinite(got))
    return np.array([float(abs((mp.mpf(float(g)) - r) / r))
                     for g, r in ((g, _reference(name, x)) for g, x in zip(got, t))])


@pytest.mark.parametrize("name", sorted(se3.SERIES))
def test_coefficient_sweep(name):
    assert name in se3.SWITCH and name in se3._CLOSED
    t = _sweep_points(name)
    err = _errors(name, t)
    worst = err.max()
    where = t[err.argmax()]
    cap = MEASURED_CAP.get(name, TIGHTENED.get(name, DOCUMENTED[name]))
    assert worst <= cap, f"{name}: relative error {worst:.3g} at t = {where:.6g} (cap {cap:g})"


@pytest.mark.parametrize("name", sorted(se3.SERIES))
def test_coefficient_at_zero_is_series_constant(name):
    v = se3.coefficient(name, 0.0)
    assert np.isfinite(v)
    exact = _reference(name, 1e-20)  # the limit (next term ~ 1e-40), to 200 digits
    assert abs(float(v) - float(exact)) <= 1e-16 * abs(float(exact))
    assert float(v) == se3.SERIES[name][0]
    # batched, including zeros among non-zeros, no warnings leak out as NaN
    t = np.array([[0.0, 1e-3], [1.0, 0.0]])
    out = se3.coefficient(name, t)
    assert out.shape == (2, 2) and np.all(np.isfinite(out))


def test_coefficient_continuous_across_switch():
    """Both branches agree at every switch point to the bound of the sweep."""
    for name, sw in se3.SWITCH.items():
        lo, hi = se3.coefficient(name, np.nextafter(sw, 0.0)), se3.coefficient(name, sw)
        cap = MEASURED_CAP.get(name, DOCUMENTED[name])
        assert abs(hi - lo) <= 2 * cap * abs(lo), name


def test_naive_t_minus_sin_trap():
    """docs/theory.md eq. 2.9: ``(t - sin t)/t^3`` evaluated directly at 1e-5 is wrong in the 6th digit."""
    t = 1e-5
    exact = float(_reference("c", t))
    naive = (t - np.sin(t)) / t**3
    assert abs(naive - exact) / exact > 1e-7          # the trap is real
    assert abs(se3.coefficient("c", t) - exact) / exact < 2e-16
    # the same for the other cancelling forms at a small angle
    for name in ("q2", "q3", "cp", "q2p", "q3p", "dp", "d"):
        assert abs(se3.coefficient(name, t) - float(_reference(name, t))) <= 2e-16 * abs(float(_reference(name, t)))
