"""The loaded step of a rope piece converges in one step (issue 30; ``Newton.backtrack``'s watchdog and
``Newton.converging``).

The 40 mm piece of the scaling benchmark's rope (``benchmarks/scaling_scenes.py``: six 1+6+12 strands
around a 1+6+12 wire strand core, 133 wires, 6597 elements, mu = 0.3) stretched by a strain of 1e-4 in one
step: ~18 000 Gauss points of the outer strands' layer-on-layer contacts carry tractions of the order of
the smoothed normal law's ``penalty x smoothing`` and cross its kinks (and the friction law's) by thousands
per iteration.  Before the watchdog the residual line search crawled (steps of 0.1 .. 0.01 for 20
iterations) and the step failed at ``max_iter`` (scaled residual 1.4e-2; three halvings, 134 iterations
in all).
"""
import pytest

import beamsolver as bs

from rope_loaded_step import rope

# stick "penalty" (the first test): what it tests is the line search on the normal law's kinks; with exact stick (the
# default) the loaded step stopped at a scaled residual 0.0019 after 30 iterations: a front where the wires lift
# off moves one node per Newton iteration and the Armijo search halves the steps (docs/theory_mortar.md 3d,
# "The rope piece's loaded step"; the penalty stick has the same front and passes with its watchdog); the second
# test: exact stick, with the normal law's active set (``newton.NORMAL_SWITCHES``, session 8).  The rope piece is
# benchmarks/rope_loaded_step.py's.


def _rope(length, stick="penalty"):
    return rope(length, stick)


@pytest.mark.slow
def test_rope_piece_loaded_step_converges_without_cut_back():
    sol = bs.solve(_rope(0.04), steps=1, min_step_ratio=1.0, verbose=False)
    st = sol.stats[-1]
    assert st["cutbacks"] == 0
    assert st["iterations"] <= 35
    assert st["residuals"][-1] <= 1e-8


@pytest.mark.slow
def test_rope_piece_loaded_step_converges_with_exact_stick():
    """Exact stick, the default, with the normal law's active set in Newton's direction (``newton.NORMAL_SWITCHES``,
    session 8): the points that press at the iterate but not at the full step are linearised open and the direction
    solved again, so the lift-off front moves several nodes per iteration.  Measured: 19 iterations, 93 s of CPU
    (with ``NORMAL_SWITCHES = 0`` a scaled residual of 0.0019 after 30 iterations: this file's first test pins the
    penalty stick for its line search)."""
    sol = bs.solve(_rope(0.04, stick="exact"), steps=1, min_step_ratio=1.0, verbose=False)
    st = sol.stats[-1]
    assert st["cutbacks"] == 0
    assert st["iterations"] <= 35
    assert st["residuals"][-1] <= 1e-8
