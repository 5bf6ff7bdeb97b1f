"""The residual line search's watchdog (``Newton.backtrack``, ``LS_CRAWL``, ``LS_WATCHDOG``).

A full Newton step that raises the merit more than ``LS_GROWTH`` is backtracked; after ``LS_CRAWL``
backtracked iterations in a row near the solution (``Newton.near``: the scaled residual ``LS_NEAR`` times
the step's largest) the next full step is kept unless the merit grows more than ``LS_WATCHDOG``
(thousands of contact points crossing the kinks of the contact laws at once: the rope's loaded step,
``test_rope_loaded_step``); far from it (a step's first iterations) the backtracking goes on.  A trial
whose merit is not finite is never kept.  On a stub
Newton whose iterate is a point on a line and whose merit is a given function of it.
"""
import types

import numpy as np
import pytest

from beamsolver.failures import StepFailed
from beamsolver.nonlinear import newton as nw


class _Stub(nw.Newton):
    """``backtrack`` over ``x`` (the 'poses', a float array): merit ``phi(x)``; ``inf`` raises a step failure."""

    def __init__(self, phi):
        self.phi, self.crawl, self.near = phi, 0, True
        self.conv = types.SimpleNamespace(rtol=1e-8)
        self.sys = types.SimpleNamespace(free_dofs=np.arange(1))
        self.problem = types.SimpleNamespace(update=lambda H, dz: H + dz, multiplier_trial=lambda s: None)

    def evaluate(self, H, t, tangent=True):
        if not np.isfinite(self.phi(H[0])):
            raise StepFailed("refused")
        return types.SimpleNamespace(x=H[0], mult=None, kvals=None if not tangent else np.zeros(1))

    def _merit(self, ev, scales):
        return self.phi(ev.x)

    def _measured(self, ev):
        return ev


def _search(newton, growth):
    """One line search from x = 0 (merit 1) along dz = 1, the full step's merit ``growth``; the step kept."""
    def phi(x):
        return growth if x == 1.0 else 1.0 - 0.5 * x
    newton.phi = phi
    H, _ = newton.backtrack(np.zeros(1), np.ones(1), types.SimpleNamespace(x=0.0, mult=None), None, 0.0)
    return H[0]


def test_full_step_kept_after_a_crawl():
    growth = 100.0                                   # between LS_GROWTH and LS_WATCHDOG
    assert nw.LS_GROWTH < growth < nw.LS_WATCHDOG
    newton = _Stub(None)
    steps = [_search(newton, growth) for _ in range(nw.LS_CRAWL)]
    assert all(s < 1.0 for s in steps)               # backtracked LS_CRAWL times in a row
    assert newton.crawl == nw.LS_CRAWL
    assert _search(newton, growth) == 1.0            # the watchdog's full step
    assert newton.crawl == 0
    assert _search(newton, growth) < 1.0             # and the ordinary rule again


def test_no_watchdog_far_from_the_solution():
    newton = _Stub(None)
    newton.crawl, newton.near = nw.LS_CRAWL, False
    assert _search(newton, 100.0) < 1.0


def test_watchdog_still_refuses_a_blow_up():
    newton = _Stub(None)
    newton.crawl = nw.LS_CRAWL
    assert _search(newton, 10.0 * nw.LS_WATCHDOG) < 1.0


def test_a_refused_trial_is_never_kept():
    newton = _Stub(None)
    newton.crawl = nw.LS_CRAWL
    newton.phi = lambda x: np.inf if x > 0.3 else 1.0 - x
    H, ahead = newton.backtrack(np.zeros(1), np.ones(1), types.SimpleNamespace(x=0.0, mult=None), None, 0.0)
    assert 0.0 < H[0] <= 0.3 and ahead is None
