"""Exactly touching wires with the default contact options (issue 14 robustness item 1): the
state at ``t_start`` converges for long wires.

Two straight steel wires (R = 0.5 mm) touching along 0.1 m, clamped below and rigidly joined to
a plate under a constant 5 N pull (``examples/twisted_pair.build``), solved to a negligible
twist.  The smoothed normal law (docs/theory.md 7.2) pushes touching points apart with
``eps_N w / 4`` per unit length, so the first state is not the reference one: the wires bow
apart between the clamped ends, and Newton approaches it only linearly (the law's zero-force end
is a double root; docs/theory.md section 17).  Before the step-zero budget
(``stepping.STEP_ZERO_ITERATIONS``) the solve stopped at t_start after ``max_iter`` = 30
iterations (41 are needed at 0.1 m).
"""

import numpy as np
import pytest

import beamsolver as bs


import three_wires
import twisted_pair_extreme as twisted_pair

L, PULL = 0.1, 5.0


@pytest.mark.parametrize("mu", [0.0, 0.3])
def test_touching_long_pair_finds_its_first_equilibrium(mu):
    model, plate, (a, b) = twisted_pair.build(length=L, n_elements=24, turns=0.5, mu=mu, pull=PULL)
    sol = bs.solve(model, steps=1, t_end=1e-9)           # the state at t_start and a negligible twist
    assert sol.converged and sol.times[-1] == pytest.approx(1e-9)
    # an equilibrium: the clamps carry the pull, the contact forces on the two wires cancel
    axial = -sum(sol.reaction(c, 0)[2] for c in (a.first, b.first))
    assert axial == pytest.approx(PULL, rel=1e-6)
    c = sol.contact(0)
    on = c["normal_force"] > 0
    assert on.any() and np.all(c["gap"][on] < 1e-3 * 2 * 0.5e-3)   # inside the smoothing gap


@pytest.mark.slow
def test_three_touching_wires_with_default_options_find_their_first_equilibrium():
    """``examples/three_wires.py`` (default contact options) at 0.1 m (step 0 needed 50 iterations when written)."""
    model, plate, wires = three_wires.build(length=L, n_elements=24, turns=0.5, mu=0.3, pull=PULL)
    sol = bs.solve(model, steps=1, t_end=1e-9)
    assert sol.converged
    axial = -sum(sol.reaction(w.first, 0)[2] for w in wires)
    assert axial == pytest.approx(PULL, rel=1e-6)


def test_step_zero_budget_is_bounded_by_the_options():
    """The step-zero budget is ``STEP_ZERO_ITERATIONS`` times ``max_iter``: with ``max_iter=2``
    the same state stops at t_start, naming the budget it used (it takes 10 iterations since the normal law's
    active set and secant act at t_start, ``newton.START_SWITCHES``, ``START_SECANT``; 18 with the active set alone,
    41 before either: ``max_iter=5`` stopped it)."""
    from beamsolver.stepping.steps import STEP_ZERO_ITERATIONS
    model, _, _ = twisted_pair.build(length=L, n_elements=24, turns=0.5, mu=0.0, pull=PULL)
    with pytest.raises(bs.ConvergenceError, match=f"no equilibrium at t_start = 0.*in {2 * STEP_ZERO_ITERATIONS} "
                                                  "iterations"):
        bs.solve(model, steps=1, t_end=1e-9, max_iter=2)
