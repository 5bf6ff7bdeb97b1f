"""Step 0 of a touching strand with exact stick's friction: an attempt that cycles is given up at once (issue 30,
session 11).

A strand built with its layers touching (``build_strand(fit_core=True)``) is pushed at t_start by the smoothed normal
law alone.  With exact stick's friction (augmented-Lagrangian updates at step 0, the stick band ``mu lamN / eps``
picometres wide) Newton alternates between two states: every sliding group's slip, hence its traction, reverses at
every iteration and the scaled residual stays near 0.075 (docs/benchmarks.md, "Step 0 of touching strands, session
11").  The stall rule (``steps.STEP_ZERO_STALL``) gave up 10 iterations after the lowest residual; two Newton
directions running that reverse the one before (``steps.STEP_ZERO_CYCLE``, ``newton.CYCLE_COS``) now give up at once,
and the fallback without that friction finds the same state, to the bit.
"""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver.stepping import steps


def _strand(n_layers, elements_per_lay=12):
    L = bs.cables.Layer
    r, lay = 1e-3, 0.1
    st = bs.cables.build_strand([L(r)] + [L(r, 6 * k, lay_length=lay) for k in range(1, n_layers + 1)], lay, E=2e11,
                                elements_per_lay=elements_per_lay, mu=0.3, contact_options=dict(stick="exact"),
                                fit_core=True, touch_tol=-0.5)
    st.clamp("bottom")
    for w in st.all_wires:
        st.model.prescribe(w.last, bs.motion.translation(lambda t: (0.0, 0.0, 1e-4 * st.length * t)))
    return st


def _solve(n_layers, monkeypatch, cycle):
    monkeypatch.setattr(steps, "STEP_ZERO_CYCLE", cycle)
    calls = []
    sol = bs.solve(_strand(n_layers).model, steps=1, callback=lambda d: calls.append(d["t"]))
    return sol, sum(1 for t in calls if t == 0.0)


@pytest.mark.slow
def test_a_touching_strand_s_cycling_attempt_with_friction_is_given_up_at_once(monkeypatch):
    """1+6+12 wires, 12 elements a lay: the attempt with friction took 14 iterations (its lowest residual at the 4th)
    and the fallback 8; now the attempt stops at the cycle, and the states (step 0 and the stretched step) are the
    same bits."""
    before, calls_before = _solve(2, monkeypatch, 0)
    after, calls_after = _solve(2, monkeypatch, 2)
    assert calls_before == 22
    assert calls_after <= 15
    warned = [w for w in after.stats[0].get("warnings", []) if "exact stick's friction" in w]
    assert warned and "cycling" in warned[0]
    assert after.converged and after.stats[-1]["iterations"] == before.stats[-1]["iterations"]
    for k in range(len(before)):
        assert np.array_equal(after.poses[k], before.poses[k])


@pytest.mark.slow
@pytest.mark.parametrize("n_layers", [1])
def test_a_strand_whose_step_zero_converges_with_friction_is_untouched(monkeypatch, n_layers):
    """1+6 wires: step 0 converges with friction (7 iterations and two augmented-Lagrangian re-solves): no Newton
    direction reverses the one before twice running, the same bits with and without the rule."""
    before, _ = _solve(n_layers, monkeypatch, 0)
    after, _ = _solve(n_layers, monkeypatch, 2)
    assert not after.stats[0].get("warnings")
    for k in range(len(before)):
        assert np.array_equal(after.poses[k], before.poses[k])


@pytest.mark.slow
def test_step_zero_s_attempt_with_friction_is_given_up_after_its_update_budget(monkeypatch):
    """``steps.STEP_ZERO_UPDATES``: the attempt with friction may take that many augmented-Lagrangian updates (the
    37-wire strand twin's took 17, 46 s); the 1+6 strand's needs 2: with a budget of 1 it falls back, and says why,
    with the default budget it is untouched (the same bits as without a budget)."""
    monkeypatch.setattr(steps, "STEP_ZERO_UPDATES", 0)
    free, _ = _solve(1, monkeypatch, 2)
    assert free.stats[0]["augmentations"] == 2
    monkeypatch.setattr(steps, "STEP_ZERO_UPDATES", 4)
    default, _ = _solve(1, monkeypatch, 2)
    for k in range(len(free)):
        assert np.array_equal(default.poses[k], free.poses[k])
    monkeypatch.setattr(steps, "STEP_ZERO_UPDATES", 1)
    short, _ = _solve(1, monkeypatch, 2)
    warned = [w for w in short.stats[0].get("warnings", []) if "exact stick's friction" in w]
    assert warned and "1 augmented-Lagrangian updates" in warned[0]
    assert short.converged
