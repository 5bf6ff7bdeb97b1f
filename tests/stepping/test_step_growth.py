"""Step growth after a cut-back (issue 12 item 8): the step does not regrow every third step to a
size that has just failed (``stepping.next_step``, ``stepping.after_failure``)."""

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.stepping.steps import EASY_ITERATIONS, EASY_RUN, WAIT_MAX, after_failure, growth, next_step

from argyris_frame import frame


@pytest.mark.parametrize("dt", [1e-3, 0.25, 1.0])
@pytest.mark.parametrize("iterations", [1, 6, 7, 30])
@pytest.mark.parametrize("easy", [0, 1, 2, 5])
def test_without_a_failed_size_the_rule_is_the_fixed_one(dt, iterations, easy):
    assert next_step(dt, iterations, easy) == (growth(iterations, easy) * dt, np.inf, EASY_RUN)


def test_growth_back_to_a_failed_size_waits_for_wait_easy_steps():
    assert next_step(0.5, 4, 2, failed=1.0, wait=4) == (0.5, 1.0, 4)       # would reach the failed size
    assert next_step(0.5, 4, 3, failed=1.0, wait=4) == (0.5, 1.0, 4)
    assert next_step(0.5, 4, 4, failed=1.0, wait=4) == (1.0, 1.0, 4)       # waited: tries it again
    assert next_step(0.25, 4, 2, failed=1.0, wait=8) == (0.5, 1.0, 8)      # below it: grows as before
    assert next_step(0.5, 4, 2, failed=1.0, wait=EASY_RUN) == (1.0, 1.0, EASY_RUN)   # first retry: fixed rule


def test_a_converged_step_of_the_failed_size_forgets_it():
    assert next_step(1.0, 3, 5, failed=1.0, wait=16) == (2.0, np.inf, EASY_RUN)
    assert next_step(1.0 - 1e-12, 3, 5, failed=1.0, wait=16) == (2.0 * (1.0 - 1e-12), np.inf, EASY_RUN)


def test_a_size_failing_again_doubles_the_wait_up_to_wait_max():
    assert after_failure(1.0) == (1.0, EASY_RUN)                 # a first failure: the fixed rule
    failed, wait, waits = 1.0, EASY_RUN, []
    for _ in range(8):
        failed, wait = after_failure(1.0, failed, wait)
        waits.append(wait)
    assert waits[:4] == [4, 8, 16, 32] and max(waits) == WAIT_MAX
    assert after_failure(2.0, 1.0, 8) == (2.0, 16)                # larger than a size that failed
    assert after_failure(0.5, 1.0, 8) == (0.5, 8)                 # smaller: a new size, the wait stays


def _failed_sizes(sol):
    return [x for s in sol.stats[1:] for x in s.get("failed_dt", [])]


def _window(**kw):
    """Argyris' frame (4 elements per leg) from F = 1.0725 N to 1.0945 N in one user step, at most 6
    Newton iterations a step (with 12, the plain Newton after a stalled damped iteration passes it
    in 3 steps since issue 31, and no size fails twice)."""
    m, b = frame(1.1, imperfection=1e-4, n=4)
    pre = bs.solve(m, steps=3, t_end=0.975, verbose=False)
    return m, bs.solve(m, steps=1, t_start=0.975, t_end=0.995, initial_poses=pre.poses[-1], max_iter=6,
                       verbose=False, **kw)


@pytest.fixture(scope="module")
def window():
    calls = []
    m, sol = _window(callback=lambda info: calls.append((info["t"], info["iteration"])))
    return m, sol, calls


def test_frame_past_buckling_does_not_keep_regrowing_to_a_failed_size(window):
    """The fixed rule (``WAIT_MAX = 2``) failed 9 times there on a size at least the previous
    failed one (17 cut-backs)."""
    m, sol, _ = window
    failed = _failed_sizes(sol)
    assert sum(s["cutbacks"] for s in sol.stats[1:]) == len(failed)
    repeats = sum(later >= earlier * (1 - 1e-9) for earlier, later in zip(failed, failed[1:]))
    assert repeats <= 4, failed
    assert sol.times[-1] == pytest.approx(0.995, abs=1e-12)
    assert sol.resume["wait"] >= EASY_RUN and (sol.resume["failed"] is None or sol.resume["failed"] > 0)


def test_a_restart_keeps_the_failed_size_memory(window):
    """Stopped right after a size failed again (wait 4 or more), the restart steps as the whole run."""
    m, full, calls = window
    steps = [j for j, s in enumerate(full.stats[1:], 1) for _ in s.get("failed_dt", [])]
    failed = _failed_sizes(full)
    j = next(steps[i] for i in range(1, len(failed)) if failed[i] >= failed[i - 1] * (1 - 1e-9))
    last = max(i for i, c in enumerate(calls) if c == (full.times[j], full.stats[j]["iterations"]))
    count = [0]

    def stop(info):
        count[0] += 1
        if count[0] > last + 1:
            raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt) as err:
        _window(callback=stop)
    part = err.value.solution
    assert part.n_steps == j and part.resume["wait"] >= 2 * EASY_RUN and part.resume["failed"] > 0
    sol = bs.solve(m, steps=1, t_start=0.975, t_end=0.995, max_iter=6, restart=part, verbose=False)
    np.testing.assert_array_equal(sol.times, full.times)
    np.testing.assert_allclose(sol.poses[-1], full.poses[-1], rtol=0, atol=1e-12)


def test_easy_limit_is_the_users_steps_iterations_when_more():
    from beamsolver.stepping.steps import easy_limit
    assert easy_limit(None) == EASY_ITERATIONS
    assert easy_limit(3) == EASY_ITERATIONS
    assert easy_limit(21) == 21


@pytest.mark.slow
def test_contact_steps_regrow_after_a_cut_back():
    """Three touching wires (examples/three_wires.py) with E one ulp above its default: step 2
    (0.25 -> 0.375 turns) fails twice and the rest ran at 1/4 of the user's step (29 steps,
    343 Newton iterations), since a contact step never took the 6 iterations of an 'easy' one.
    Steps as easy as the user's steps were (at most the iterations of the last step taken at
    the user's size) regrow; on a machine where no step is cut back the run has 8 steps."""
    from three_wires import build
    sol = bs.solve(build(E=float(np.nextafter(200e9, np.inf)))[0], steps=8)
    assert sol.converged and sol.times[-1] == 1.0
    assert len(sol.times) <= 16, [s["dt"] for s in sol.stats]


def test_steady_is_about_the_previous_steps_iterations_within_the_budget():
    from beamsolver.stepping.steps import STEADY_GROWTH, STEADY_SHARE, steady
    assert not steady(3, None, 30)                                  # no step before: not steady
    assert steady(11, 10, 30) and steady(int(STEADY_GROWTH * 8 + 1), 8, 30)
    assert not steady(12, 8, 30)                                    # rising: 8 -> 12
    assert steady(20, 22, 30) and not steady(21, 22, 30)            # within STEADY_SHARE of max_iter only
    assert not steady(9, 9, 12) and steady(8, 9, 12) and STEADY_SHARE * 12 == 8


def _forced_cut_back():
    """A callback that fails the first Newton iteration after ``t_start`` once (a retryable ``NotConverged``)."""
    from beamsolver.failures import NotConverged
    done = []

    def callback(info):
        if not done and info["t"] > 0.0:
            done.append(info["t"])
            raise NotConverged("failure forced by the test")
    return callback


def test_slip_steps_regrow_after_a_forced_cut_back():
    """Issue 27 item 6.  The 20 mm twisted pair (examples/twisted_pair_extreme.py, 16 steps, never cut back:
    17 states, 135 iterations) with its first step forced to fail: the steps at half size then
    take a steady 10-14 iterations (slip), never as few as ``EASY_ITERATIONS``, and no step had
    been taken at the user's size: with ``easy_limit`` alone the step stayed halved until the
    iterations fell to 6 near the end (25 states, 214 iterations).  Steady steps regrow.  (The penalty
    stick: the scene is one that is never cut back.)"""
    from twisted_pair_extreme import build
    sol = bs.solve(build(stick="penalty")[0], steps=16, callback=_forced_cut_back())
    assert sol.converged and sol.times[-1] == 1.0
    assert sum(s["cutbacks"] for s in sol.stats) == 1 and sol.stats[1]["cutbacks"] == 1
    half = [s["dt"] < 0.75 / 16 for s in sol.stats[1:]]
    first_full = half.index(False)
    assert first_full <= 6, [s["dt"] for s in sol.stats]          # regrew within 6 steps (was 16)
    assert len(sol.times) <= 20
    # not straight back into the size that failed at nearly the same state: past the failed step's end
    assert sol.times[first_full] >= 1.0 / 16


@pytest.mark.slow
def test_a_restart_keeps_the_previous_iterations_of_steady():
    """The forced twisted pair stopped after its third step (half size, one steady step running):
    the restart needs the previous step's iterations (``resume["previous"]``) to regrow where
    the whole run did."""
    from twisted_pair_extreme import build
    model = build(stick="penalty")[0]
    calls, force = [], _forced_cut_back()

    def record(info):
        force(info)
        calls.append(info["t"])
    full = bs.solve(model, steps=16, callback=record)
    j = 3
    assert full.stats[j]["dt"] < 0.75 / 16 and full.stats[j + 1]["dt"] < 0.75 / 16   # stopped inside the stretch
    last = max(i for i, t in enumerate(calls) if t == full.times[j])
    count, force = [0], _forced_cut_back()

    def stop(info):
        force(info)
        count[0] += 1
        if count[0] > last + 1:
            raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt) as err:
        bs.solve(model, steps=16, callback=stop)
    part = err.value.solution
    assert part.n_steps == j and part.resume["previous"] == full.stats[j]["iterations"]
    sol = bs.solve(model, steps=16, restart=part)
    np.testing.assert_array_equal(sol.times, full.times)


def _driven(motion, fixed, loads):
    """A stand-in system for ``stepping.kinks``: one prescribed node turned by ``motion(t)`` about e_z, one ``fix``
    value ``fixed(t)`` and one load factor ``loads(t)``."""
    from types import SimpleNamespace

    def poses(t):
        a = motion(t)
        R = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
        H = np.eye(4)
        H[:3, :3] = R
        return H[None]
    return SimpleNamespace(prescribed_nodes=[0], prescribed_poses=poses, fix_values=[(1, 4, fixed)],
                           load_scales=[loads], load_factors=lambda t: np.array([loads(t)]))


def test_kinks_of_the_loading_path_are_reversals_starts_and_stops():
    """``kinks.kink``: the increments of the prescribed poses, the fix values or the load factors turn back, or one
    of them starts or stops, between ``t0 -> t1`` and ``t1 -> t2``; a path going on (faster or slower) has none."""
    from beamsolver.stepping.kinks import kink
    tri = lambda t: 0.1 * (t if t <= 1.0 else 2.0 - t)        # noqa: E731  up, then back
    ramp = lambda t: 0.1 * t                                   # noqa: E731
    zero = lambda t: 0.0                                       # noqa: E731
    assert not kink(_driven(ramp, ramp, ramp), 0.5, 0.75, 1.0)
    assert not kink(_driven(lambda t: t**2, ramp, zero), 0.5, 0.75, 1.5)      # faster, same direction
    assert kink(_driven(tri, zero, zero), 0.75, 1.0, 1.25)                     # the motion turns back
    assert kink(_driven(zero, tri, zero), 0.75, 1.0, 1.25)                     # a fix value turns back
    assert kink(_driven(zero, zero, tri), 0.75, 1.0, 1.25)                     # a load turns back
    start = lambda t: 0.0 if t <= 1.0 else 0.1 * (t - 1.0)     # noqa: E731
    stop = lambda t: min(t, 1.0)                               # noqa: E731
    assert kink(_driven(start, zero, stop), 0.75, 1.0, 1.25) == "start"        # pull stops, bending starts
    assert kink(_driven(zero, start, zero), 0.75, 1.0, 1.25) == "start"        # a fix value starts
    assert kink(_driven(zero, zero, start), 0.75, 1.0, 1.25) == "kink"         # a load starts
    assert kink(_driven(tri, zero, zero), 0.75, 1.0, 1.25) == "kink"
    assert not kink(_driven(start, zero, stop), 1.0, 1.25, 1.5)


def test_the_step_after_a_kink_starts_at_the_size_that_converged_after_the_last_kink(monkeypatch):
    """``Run.loop``: the first kink of a triangle history (no memory; ``kinks.FIRST`` = 1) is tried at the grown size; a
    failure there halves it; the next kink starts at the size that converged after the first one, and ``resume``
    keeps it (restart)."""
    from beamsolver.stepping import kinks, steps as steps_mod
    from beamsolver.failures import NotConverged
    monkeypatch.setattr(kinks, "FIRST", 1.0)
    model = bs.Model()
    beam = model.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), bs.Section.circular(radius=0.01, E=2e11, nu=0.3))
    model.fix(beam.first)
    tri = lambda t: t if t <= 1.0 else (2.0 - t if t <= 2.0 else t - 2.0)     # noqa: E731
    model.add_load(beam.last, force=(0.0, 1.0, 0.0), scale=tri)
    real = steps_mod.Run.newton_step
    tried = []

    def step(self, t_next, start=None):
        tried.append((self.t, t_next))
        if abs(self.t - 1.0) < 1e-9 and t_next - self.t > 0.3:        # the first reversal: the grown step fails
            raise NotConverged("forced", 1.0)
        return real(self, t_next, start)
    monkeypatch.setattr(steps_mod.Run, "newton_step", step)
    sol = bs.solve(model, steps=6, t_end=3.0, verbose=False)
    assert sol.converged
    kinked = [(float(sol.times[k - 1]), float(s["dt"])) for k, s in enumerate(sol.stats) if s.get("kink")]
    assert [t for t, _ in kinked] == pytest.approx([1.0, 2.0])
    assert kinked[0][1] == pytest.approx(0.25) and kinked[1][1] == pytest.approx(0.25)
    assert [(a, b) for a, b in tried if abs(a - 2.0) < 1e-9][0][1] == pytest.approx(2.25)   # not 2.5 first
    assert sol.resume["kink_size"] == pytest.approx(0.25)


def test_the_first_kink_of_a_run_starts_at_a_share_of_the_step(monkeypatch):
    """``kinks.FIRST`` (default 1: the step as grown): with no size known, the step after the first kink where a
    prescribed motion or ``fix`` value starts to move is ``FIRST`` times the step as grown (the strand bending cycle's
    bending after the pull: the user's step and its half failed there); a load that turns back is not such a kink."""
    from beamsolver.stepping import kinks
    assert kinks.FIRST == 1.0
    monkeypatch.setattr(kinks, "FIRST", 0.25)
    for start in (True, False):
        model = bs.Model()
        beam = model.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4),
                              bs.Section.circular(radius=0.01, E=2e11, nu=0.3))
        model.fix(beam.first)
        if start:        # a pull, then a motion of the end from rest
            model.add_load(beam.last, force=(100.0, 0.0, 0.0), scale=lambda t: min(t, 1.0))
            model.fix(beam.last, ("uz",), values={"uz": lambda t: 1e-3 * max(t - 1.0, 0.0)})
        else:            # a load that turns back
            model.add_load(beam.last, force=(0.0, 1.0, 0.0), scale=lambda t: t if t <= 1.0 else 2.0 - t)
        sol = bs.solve(model, steps=4, t_end=2.0, verbose=False)
        kinked = [float(s["dt"]) for s in sol.stats if s.get("kink")]
        assert kinked == [pytest.approx(0.125 if start else 0.5)], (start, kinked)
