"""Touching wires with no load at ``t_start`` (issue 14): the state there is solved.

Two straight steel wires (R = 0.5 mm) touching along 0.1 m, clamped at both ends, no load: the
smoothed normal law pushes them apart at zero gap (docs/theory.md 17.1), so the given poses
are no equilibrium.  Step 0 was solved only when loads or motions act at ``t_start``; here it
recorded the reference poses and the first step had to find the pushed-apart state within
``max_iter`` (41 iterations needed), at any step size: the solve stopped at t = 0 with "the
tangent at t = 0 is already indefinite ...: the path has passed a limit point or bifurcation"
(it had not).  Round-off contact forces on a load-free given state (the capstan's rope on its
post) ask for a Newton correction at round-off and leave step 0 as given
(tests/contact/test_contact_scenes.py runs those scenes).
"""
import numpy as np
import pytest

import beamsolver as bs

R, L = 0.5e-3, 0.1


def _pair(n=24, clamp_both=True, load=None):
    from touching_start import touching_pair        # benchmarks/touching_start.py (on pytest's pythonpath)
    return touching_pair(R, L, n, clamp_both=clamp_both, load=load)


def test_touching_wires_without_load_find_their_first_equilibrium():
    m, a, b = _pair()
    sol = bs.solve(m, steps=2)
    assert sol.converged and sol.iterations[0] > 0            # step 0 solved, not the given poses
    c = sol.contact(0)
    on = c["normal_force"] > 0
    assert on.any()
    # an equilibrium without load: the supports carry nothing in total, the wires bow apart
    total = sum(sol.reaction(n, 0)[:3] for w in (a, b) for n in (w.first, w.last))
    assert np.abs(total).max() < 1e-8 * c["normal_force"].sum()
    gap = np.linalg.norm(sol.poses[0][b.nodes, :3, 3] - sol.poses[0][a.nodes, :3, 3], axis=1) - 2 * R
    assert gap[len(gap) // 2] > 0
    # nothing changes after it (the later steps start at rtol's edge: one iteration at most)
    assert np.all(sol.iterations[1:] <= 1)
    np.testing.assert_allclose(sol.poses[-1], sol.poses[0], rtol=0, atol=1e-12 * L)


def test_a_zero_load_at_t_start_finds_the_same_equilibrium():
    """A load ramped from zero (zero at ``t_start``) and then a small one: the same first state."""
    m, a, b = _pair(load=(1e-3, 0.0, 0.0))
    sol = bs.solve(m, steps=2)
    ref = bs.solve(_pair()[0], steps=1)
    assert sol.converged and sol.iterations[0] > 0
    np.testing.assert_allclose(sol.poses[0], ref.poses[0], rtol=0, atol=1e-15)


def test_an_unreachable_first_state_names_the_contact_that_pushes():
    """Step 0 takes 10 iterations (44 before the normal law's active set and secant acted at t_start,
    ``newton.START_SWITCHES``, ``START_SECANT``; 18 with the active set alone): a budget of 8 does not reach it."""
    m, a, b = _pair()
    with pytest.raises(bs.ConvergenceError, match=r"no equilibrium at t_start = 0, where contact forces already "
                                                  r"act .*add_contact no\. 0: Beam 1 'b' element \d+ against "
                                                  r"Beam 0 'a' element \d+") as err:
        bs.solve(m, steps=1, max_iter=2)
    assert "indefinite" not in str(err.value)
