"""A touching start's crawl to the smoothed normal law's double root (docs/theory/contact_laws.md 17.2, issue 26 / 30
session 9): at t_start the points whose traction the full Newton step cuts to ``newton.SECANT_SHARE`` or less are
linearised once on the smoothing parabola's secant to ``SECANT_REACH`` of the way to its zero-force end
(``ContactSystem.force_secant``), where the parabola's tangent only halves their distance per iteration.

The contact patch (``examples/contact_patch.py``) has no load at t_start: its slave, held by contact alone, floats up to
the law's zero-force end, a double root, in 11 halving iterations before; the answer must not change.
"""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver.contact.law import penalty_normal
from beamsolver.contact.system import ContactSystem
from beamsolver.nonlinear import newton

import contact_patch


def _patch(monkeypatch, secant):
    monkeypatch.setattr(newton, "START_SECANT", secant)
    model, slave, master = contact_patch.build(stick="exact")
    gaps = []

    def record(info):
        if info["t"] == 0.0:
            H = info["poses"]
            gaps.append(H[slave.nodes[3], 2, 3] - H[master.nodes[5], 2, 3] - 2 * slave.section.radius)

    sol = bs.solve(model, callback=record, **contact_patch.solve_options)
    return sol, np.array(gaps)


def test_the_secant_law_has_the_point_s_traction_and_reaches_its_share_of_the_way_to_the_double_root():
    """``_secant_law``'s parameters: at the point's gap the same traction as the parabola, the slope of the line
    through it and the gap ``reach`` of the way to the zero-force end (``w`` for ``m = 0``), on both sides of
    ``x = 0``, with a normal multiplier too."""
    pen, w = 3e7, 2e-6
    W = pen * w
    for m in (0.0, 0.3 * W):
        for g0 in (-0.5 * w, 0.0, 0.3 * w, 0.9 * w):
            x0 = m - pen * g0
            assert -W < x0 < W
            lam0, d0, _ = penalty_normal(g0, pen, m, w)
            for reach in (1.0, 1.0 - 2.0 ** -10, 0.75):
                cs = ContactSystem.__new__(ContactSystem)
                cs._secant = (np.array([4, 7]), np.array([g0, g0]), reach)
                p = dict(penalty=np.full(3, pen), smoothing=np.full(3, w), multiplier=np.full(3, m))
                cs._secant_law(np.array([2, 4, 7]), p)
                assert p["smoothing"][0] == w and p["multiplier"][0] == m        # key 2 is not on the secant
                lam, d, active = penalty_normal(g0, pen, p["multiplier"][1], p["smoothing"][1])
                assert active and lam == pytest.approx(lam0, rel=1e-12)
                g_end = (m + W) / pen                                            # the zero-force end
                target = g0 + reach * (g_end - g0)
                assert d == pytest.approx(-lam0 / (target - g0), rel=1e-12)     # the secant to the target
                assert d == pytest.approx(d0 / (2.0 * reach), rel=1e-12)


def test_the_contact_patch_s_touching_start_reaches_the_double_root_in_two_iterations_with_the_same_answer(
        monkeypatch):
    """Step 0 of the contact patch: 11 iterations halving the distance to the zero-force end before (the tangent's
    linear rate at a double root), 2 with the secant; the first covers ``SECANT_REACH`` of the way, where ten
    tangent steps end; then the step stops on its increment where the crawl stopped.  Every step's poses agree to
    round-off and the loaded steps take the same iterations."""
    before, g_before = _patch(monkeypatch, False)
    after, g_after = _patch(monkeypatch, True)
    its_before = [s["iterations"] for s in before.stats]
    its_after = [s["iterations"] for s in after.stats]
    assert its_before[0] == 11 and its_after[0] <= 2
    assert its_after[1:] == its_before[1:]
    # the crawl: linear, its distances to the end gap w halve
    w = g_before[-1] + (g_before[-1] - g_before[-2])
    ratios = np.diff(g_before[1:]) / np.diff(g_before[:-1])
    np.testing.assert_allclose(ratios, 0.5, rtol=1e-3)
    # the secant: the first iterate 2^-10 of the way short of it, where the crawl's tenth was
    d_after = w - g_after
    assert d_after[1] == pytest.approx(2.0 ** -10 * d_after[0], rel=1e-3)
    assert abs(g_after[-1] - g_before[-1]) <= 1e-11           # dtol L (L = 1)
    for k in range(len(before.times)):
        np.testing.assert_allclose(after.poses[k][:, :3, 3], before.poses[k][:, :3, 3], rtol=0, atol=1e-13)


def test_the_start_solves_one_direction_again_per_iteration(monkeypatch):
    """``START_SWITCH_LIMIT`` = 1: at t_start the normal law's active set solves at most one more direction per Newton
    iteration (each is an evaluation and a factorisation: with ``NORMAL_SWITCHES`` = 4 there the 19-wire strand twin's
    loaded step took 21 s against 12.7 s). The unloaded touching pair (benchmarks/touching_start.py) then takes 26
    iterations at step 0 and 49 directions (with 4: 10 and 30, 3 a iteration; without the start's switches 44)."""
    from touching_start import touching_pair
    count = [0]
    direction = newton.Newton.direction

    def counted(self, *a, **k):
        count[0] += self.start
        return direction(self, *a, **k)
    monkeypatch.setattr(newton.Newton, "direction", counted)
    sol = bs.solve(touching_pair()[0], steps=2, verbose=False)
    its = sol.stats[0]["iterations"]
    assert sol.converged and its < 44
    assert count[0] <= 2 * its
