"""Clamped-free column past its buckling load, selected by a small lateral force (issue 31 item 1).

Timoshenko & Gere, Theory of Elastic Stability (2nd ed., sec. 2.7): a clamped-free column (L = 1,
in-plane ``EI``) under an axial tip load ``P > P_cr = pi^2 EI / 4`` has the elastica with modulus
``k = sin(alpha / 2)``, ``sqrt(P / P_cr) = 2 K(k) / pi``, tip deflection ``2 k / K(k)`` and tip
abscissa ``2 E(k) / K(k) - 1`` (0.5085 and 0.8203 at 1.1 P_cr).  A lateral force of 1 % of P_cr
selects the side.  On 07a7d6e the default solve ended at (0.9957, -0.0829, 0), on the side
opposite the force, unstable, reported converged; with the force removed and P raised to
1.5, 2, 4 P_cr it returned the straight, unstable column at every level.
"""
import warnings

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

import beamsolver as bs
from beamsolver.nonlinear.definiteness import negative_eigenvalues
from scenes import column


def elastica(ratio):
    """Perfect clamped-free column (L = 1): tip ``(x, deflection)`` at ``P / P_cr = ratio > 1``."""
    k = brentq(lambda k: 2.0 * ellipk(k * k) / np.pi - np.sqrt(ratio), 1e-12, 1.0 - 1e-15)
    K, E = ellipk(k * k), ellipe(k * k)
    return np.array([2.0 * E / K - 1.0, 2.0 * k / K])


def _stable(model, sol, k=-1):
    return negative_eigenvalues(bs.linearize(model, sol, k).K)[0] == 0


@pytest.mark.parametrize("line_search", [True, False])
def test_column_with_a_kick_ends_on_the_stable_elastica(line_search):
    m, b, _ = column()
    with warnings.catch_warnings():
        warnings.simplefilter("error", bs.StabilityWarning)      # nothing unstable kept on the way
        sol = bs.solve(m, steps=10, verbose=False, line_search=line_search)
    tip = sol.position(b.last)
    np.testing.assert_allclose(tip, [0.8033, 0.5290, 0.0], atol=2e-4)       # 67217fe: (0.8033, 0.5290, 0)
    assert _stable(m, sol)
    x, f = elastica(1.1)
    # the kick (1 % of P_cr sideways) adds to the perfect column's deflection, within 5 % of it
    assert f < tip[1] < 1.05 * f and 0.97 * x < tip[0] < x


def test_kick_removed_the_column_stays_on_the_elastica_as_the_load_rises():
    """The kick ramps with the load to 1.1 P_cr, is removed there, then P rises to 1.5, 2, 4 P_cr:
    the tip follows the perfect elastica (16 elements: within 2e-3)."""
    T, P, kick = [0, 1, 1.25, 2, 3, 4], [0, 1.1, 1.1, 1.5, 2.0, 4.0], [0, 0.01, 0, 0, 0, 0]
    m, b, P_cr = column(ratio=0.0, kick=0.0)
    m.add_load(b.last, force=(-P_cr, 0, 0), scale=lambda t: float(np.interp(t, T, P)))
    m.add_load(b.last, force=(0, P_cr, 0), scale=lambda t: float(np.interp(t, T, kick)))
    sol = bs.solve(m, steps=16, t_end=4.0, verbose=False)
    for t, ratio in ((2.0, 1.5), (3.0, 2.0), (4.0, 4.0)):
        k = int(np.flatnonzero(sol.times == t)[0])
        np.testing.assert_allclose(sol.position(b.last, k)[:2], elastica(ratio), atol=2e-3)
        assert _stable(m, sol, k)
