"""Greenhill's twisted rod by bisection over short solve intervals (issue 31 item 2).

A straight wire clamped at one end and turned about its axis at the other (all motions of that
end prescribed) buckles at Greenhill's clamped-clamped torque ``M L / B = 8.99`` (``B = E I``,
no axial force; Greenhill 1883, as in Timoshenko & Gere sec. 2.19).  The critical twist is
bracketed by a load-stepped solve and bisected with ``solve(steps=1, t_start=t_lo, t_end=t,
initial_poses=H_lo, check_stability=True)`` down to an interval of 1e-10: on 07a7d6e the last
calls were refused ("the smallest step 1.01e-13 (min_step_ratio 0.000244 of the step 4.14e-10)
vanishes in round-off ... raise min_step_ratio").
"""
import warnings

import numpy as np
import pytest

import beamsolver as bs
from scenes import twisted_wire

TURNS = 2.25


def test_bisection_to_a_short_interval_finds_greenhills_torque():
    m, w, sec = twisted_wire(turns=TURNS)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bs.StabilityWarning)
        sol = bs.solve(m, steps=18, verbose=False, check_stability=True)
        k = next(k for k, s in enumerate(sol.stats[1:], 1) if not s["stable"])
        t_lo, t_hi, H_lo = sol.times[k - 1], sol.times[k], sol.poses[k - 1]
        while t_hi - t_lo > 1e-10:
            t = 0.5 * (t_lo + t_hi)
            s = bs.solve(m, steps=1, t_start=t_lo, t_end=t, initial_poses=H_lo, check_stability=True, verbose=False)
            assert s.converged and s.times[-1] == t
            if s.stats[-1]["stable"]:
                t_lo, H_lo = t, s.poses[-1]
            else:
                t_hi = t
    twist_rate = 2.0 * np.pi * TURNS * t_lo / 0.02
    M = sec.C[3, 3] * twist_rate                    # the straight wire's torque GJ x twist rate
    assert M * 0.02 / sec.C[4, 4] == pytest.approx(8.99, rel=0.02)    # 8 elements: 9.12
