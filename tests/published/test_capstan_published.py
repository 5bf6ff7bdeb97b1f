"""Capstan (Euler-Eytelwein) on a post from starts that touch (issue 31 items 3, 4; issue 28 item 10).

A rope pulled round a post slides when ``T_pull / T_hold = exp(mu theta)`` (Euler 1762,
Eytelwein 1808), ``exp(mu theta R / (R + r))`` for a rope of radius ``r`` whose friction acts on
its surface.  Both scenes have no load at t = 0 (the held end's force ramps from 0).

1. A thin rope (r = 5e-5 m, EA = 1e5 N, EI = 1e-5 N m^2) on a helix touching a clamped post
   (R = 0.05 m) over a full wrap: on 07a7d6e step 0 met a mechanism (the rope can slide round
   the post) and stopped at t = 0; 67217fe gave T_pull / T_hold within 0.35 % of exp(mu theta).
2. A rope (R = 1, r = 0.02) through points on the radius 1.02 by ``geometry.polyline``: where the
   arc meets the straight ends its elements cut up to 2.2e-4 into the post.  On 07a7d6e: "no
   equilibrium at t_start = 0, where contact forces already act"; now the overlaps are adjusted
   away (``add_contact(adjust=)``, default 1e-3 (R + r)) and reported in ``stats[0]``.
"""
import numpy as np
import pytest

import beamsolver as bs
from scenes import capstan

HELIX = dict(mu=0.1, theta=2.0 * np.pi, R=0.05, r=5e-5, n_arc=48, pitch=4e-3)
CHORDS = dict(mu=0.25, theta=np.pi, R=1.0, r=0.02, n_arc=36, polyline=True, EI=1e-3, T_hold=10.0, pull=0.02,
              straight=0.15, post_length=1.0)


def _ratio(sol, rope, t_out, T_hold):
    return abs(float(np.dot(sol.reaction(rope.last)[:3], t_out))) / T_hold


def test_full_wrap_on_a_helix_touching_the_post():
    m, rope, t_out = capstan(**HELIX)
    sol = bs.solve(m, steps=8, verbose=False)
    assert sol.stats[0]["iterations"] == 0 and np.array_equal(sol.poses[0], m.poses0)   # started as given
    assert _ratio(sol, rope, t_out, 1.0) == pytest.approx(np.exp(0.1 * 2.0 * np.pi), rel=3.5e-3)   # 0.17 %


@pytest.mark.slow
def test_polyline_cutting_into_the_post_is_adjusted_and_slides_at_the_capstan_ratio():
    m, rope, t_out = capstan(**CHORDS)
    sol = bs.solve(m, steps=8, verbose=False)
    adjusted = sol.stats[0]["adjusted"]
    assert adjusted["count"] > 0 and 1e-4 < adjusted["largest"] < 1e-3 * 1.02
    exact = np.exp(0.25 * np.pi * 1.0 / 1.02)                                  # 2.160
    assert _ratio(sol, rope, t_out, 10.0) == pytest.approx(exact, rel=2e-3)   # 2.158


@pytest.mark.slow
def test_an_overlap_deeper_than_adjust_keeps_the_clear_error():
    m, rope, t_out = capstan(**CHORDS, adjust=1e-5)
    with pytest.raises(bs.ConvergenceError, match=r"no equilibrium at t_start = 0, where contact forces already "
                                                  r"act .*adjust="):
        bs.solve(m, steps=8, verbose=False, max_iter=5)
