"""Past ``max_iter`` Newton goes on while a non-smooth (contact) problem converges fast (``Newton.converging``:
``GRACE_RATE``, ``GRACE_ITER``), and only then: a semi-smooth Newton whose contact active set settles late (the
rope's loaded step, ``test_rope_loaded_step``) is not stopped two iterations before its quadratic end; for a
smooth problem ``max_iter`` stays a hard cap."""
import pytest

import beamsolver as bs
from beamsolver.nonlinear import newton as nw
from helpers import crossing_at_nodes

import bend45


def test_contact_converging_fast_at_the_budget_goes_on():
    """Two beams crossing at nodes, pushed together, one step: scaled residuals 1, 0.76, 1e-3, 8.7e-6,
    1.7e-12 (converged at iteration 4); with ``max_iter = 3`` the iterate at the budget is in the quadratic
    phase, with ``max_iter = 2`` it is not (a cut-back)."""
    m, *_ = crossing_at_nodes()
    sol = bs.solve(m, steps=1, max_iter=3, min_step_ratio=1.0, verbose=False)
    assert sol.stats[-1]["iterations"] == 4 and sol.stats[-1]["cutbacks"] == 0
    m, *_ = crossing_at_nodes()
    with pytest.raises(bs.ConvergenceError):
        bs.solve(m, steps=1, max_iter=2, min_step_ratio=1.0, verbose=False)


def test_smooth_problem_stops_at_the_budget():
    """bend45 (no contact: a smooth problem) converges at iteration 6 (residuals 1, 0.66, 0.40, 0.077,
    2.4e-3, 3.4e-8, 1.5e-11); ``max_iter = 5`` stops it there."""
    model, _ = bend45.build(8)
    assert bs.solve(model, steps=1, verbose=False).stats[-1]["iterations"] == 6
    model, _ = bend45.build(8)
    with pytest.raises(bs.ConvergenceError):
        bs.solve(model, steps=1, max_iter=5, min_step_ratio=1.0, verbose=False)


@pytest.mark.parametrize("residuals, extra, expected", [
    ([1e-2, 1e-3, 1e-4], 0, True),
    ([1e-2, 1e-3, 1e-4], nw.GRACE_ITER, False),               # at most GRACE_ITER more
    ([1e-2, 9e-3, 8e-3], 0, False),                           # a crawl
    ([1e-2, 1e-4, 5e-4], 0, False),                           # the last one rose
    ([1e-3, 1e-4], 0, False),                                 # too short a history
])
def test_converging_rule(residuals, extra, expected):
    assert nw.Newton.converging(residuals, extra) is expected
