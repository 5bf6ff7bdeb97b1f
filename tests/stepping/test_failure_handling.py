"""No silent wrong answer, no hang, nothing lost: the solver-side items of issue 12.

Each test failed on the code before its fix (issue 12 item number in the name or docstring).
"""
import warnings

import numpy as np
import pytest

import beamsolver as bs
from beamsolver import failures
from beamsolver.nonlinear.convergence import CONTINUE, CONVERGED, DIVERGED, MAX_ITER

from limit_points import argyris_frame

STEEL = dict(E=200e9, nu=0.3)


def _rod(n=16, end=(1.0, 0.0, 0.0)):
    m = bs.Model()
    sec = bs.Section.circular(radius=0.01, **STEEL)
    b = m.add_beam(bs.geometry.straight((0, 0, 0), end, n), sec)
    m.clamp(b.first)
    return m, b, sec


# ------------------------------------------------------------------ item 1: motions are paths
@pytest.mark.parametrize("steps", [1, 2, 3, 8])
def test_prescribed_two_turns_twist_whatever_the_step_count(steps):
    """Two full turns of the free end of a clamped straight rod: torque GJ phi / L (exact for
    the element), in any number of steps (before: 0 in 1 or 2 steps, -GJ 2 pi / L in 3)."""
    m, b, sec = _rod()
    m.prescribe(b.last, bs.motion.rotation((1, 0, 0), 4 * np.pi))
    sol = bs.solve(m, steps=steps, verbose=False)
    assert sol.reaction(b.last)[3] == pytest.approx(sec.C[3, 3] * 4 * np.pi / 1.0, rel=1e-9)
    assert all(s.get("motion_rotation", 0.0) <= 0.6 * np.pi for s in sol.stats)


def test_fixed_rotation_value_is_an_angle_not_wrapped():
    """``fix(values={"rz": pi t})`` in one step twists by +pi (before: -pi, the wrong way)."""
    m, b, sec = _rod(end=(0.0, 0.0, 1.0))
    m.fix(b.last, ("ux", "uy", "rx", "ry", "rz"), values={"rz": lambda t: np.pi * t})
    sol = bs.solve(m, steps=1, verbose=False)
    assert sol.reaction(b.last)[5] == pytest.approx(sec.C[3, 3] * np.pi, rel=1e-9)


# ------------------------------------------------------------------ item 4: augmented Lagrangian
def _pressed_pair(tolerance):
    model = bs.Model()
    r = 0.05
    sec = bs.Section.circular(radius=r, E=1e7, nu=0.3)
    master = model.add_beam(bs.geometry.straight((0.1, -1, 0), (0.1, 1, 0), 5), sec)
    slave = model.add_beam(bs.geometry.straight((-1, 0, 2 * r), (1, 0, 2 * r), 4), sec)
    for n in (master.first, master.last, slave.first, slave.last):
        model.clamp(n)
    model.add_load(slave.nodes[2], force=(0.0, 0.0, -50.0))
    # a soft penalty: each multiplier update removes only part of the penetration
    model.add_contact(slave, master, penalty=1e2, tolerance=tolerance)
    return model


def test_unmet_contact_tolerance_is_an_error_or_a_recorded_warning():
    with pytest.raises(bs.ConvergenceError, match="augmented Lagrangian") as err:
        bs.solve(_pressed_pair(1e-8), steps=1, verbose=False)
    assert isinstance(err.value.failure, failures.AugmentationFailed)
    assert err.value.solution.n_steps == 0
    with pytest.warns(RuntimeWarning, match="augmented Lagrangian"):
        sol = bs.solve(_pressed_pair(1e-8), steps=1, verbose=False, allow_unmet_tolerance=True)
    assert "tolerance" in sol.message and sol.stats[-1]["warnings"]
    assert -sol.contact()["gap"].min() > 1e-8


# ------------------------------------------------------------------ item 5: unstable equilibria
def _column(load_factor, n=8):
    m = bs.Model()
    sec = bs.Section.circular(radius=0.01, **STEEL)
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n), sec)
    m.clamp(b.first)
    euler = np.pi**2 * sec.C[4, 4] / 4.0           # clamped-free column, L = 1
    m.add_load(b.last, force=(-load_factor * euler, 0.0, 0.0))
    return m


def test_straight_column_beyond_euler_load_is_flagged_unstable():
    with pytest.warns(bs.StabilityWarning, match="unstable"):
        sol = bs.solve(_column(2.0), steps=2, verbose=False, check_stability=True)
    assert sol.stats[1]["stable"] is True and sol.stats[2]["stable"] is False
    assert sol.stats[2]["negative_eigenvalues"] >= 1 and "unstable" in sol.message
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ok = bs.solve(_column(0.5), steps=2, verbose=False, check_stability=True)
    assert all(s["stable"] for s in ok.stats[1:]) and ok.message == ""


# ------------------------------------------------------------------ items 6, 7: bounded stepping
@pytest.mark.parametrize("ratio", [0, -1.0, 1e-17, np.nan, 2.0])
def test_min_step_ratio_out_of_range_is_refused(ratio):
    m, b, _ = _rod(4)
    with pytest.raises(bs.InputError, match="min_step_ratio"):
        bs.solve(m, steps=2, min_step_ratio=ratio)


def test_a_step_that_vanishes_at_t_is_refused_a_short_cut_back_is_raised():
    """Only a user's step below round-off at ``t`` is refused (issue 31 item 2); a smallest cut-back
    below it is raised to ``solver.STEP_ROUNDOFF`` ulps of ``t``, and the run is attempted."""
    m, b, _ = _rod(4)
    with pytest.raises(bs.InputError, match="round-off"):
        bs.solve(m, steps=1, t_start=1e15, t_end=1e15 + 1.0)
    sol = bs.solve(m, steps=1, t_start=1e12, t_end=1e12 + 1.0, min_step_ratio=1e-6, verbose=False)
    assert sol.converged and sol.times[-1] == 1e12 + 1.0


@pytest.mark.parametrize("t0", [0.1, 0.3, 0.7])
def test_smallest_cut_back_is_tried(t0):
    """Only steps of 1/8 of the user's step converge (3 iterations allowed): the third halving
    of 0.1 from t0 lands a rounding below 0.0125 and was refused before."""
    m = bs.Model()
    sec = bs.Section.circular(radius=0.01, **STEEL)
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (0.5, 0, 0), 4), sec)
    b = m.add_beam(bs.geometry.straight((0.5, 0, 0), (1, 0, 0), 4), sec)
    m.join(a.last, b.first)
    m.clamp(a.first)
    m.add_load(b.last, force=(0, 0, 3750.0), scale=lambda t: t - t0)
    sol = bs.solve(m, steps=1, t_start=t0, t_end=t0 + 0.1, max_iter=3, min_step_ratio=1 / 8, verbose=False)
    assert sol.n_steps == 8 and sol.times[-1] == t0 + 0.1


# ------------------------------------------------------------------ item 10: never store NaN
def test_nan_load_scale_is_named():
    m, b, _ = _rod(4)
    m.add_load(b.last, force=(0, 0, 1.0), scale=lambda t: np.nan)
    with pytest.raises(bs.InputError, match=r"add_load\((node )?4\): scale\(0\)"):
        bs.solve(m, steps=2, verbose=False)


def test_nan_load_scale_late_in_the_run_is_named():
    m, b, _ = _rod(4)
    m.add_load(b.last, force=(0, 0, 1.0), scale=lambda t: np.nan if 0.6 < t < 0.9 else t)
    with pytest.raises(bs.InputError, match=r"add_load\((node )?4\): scale\(0.75\)") as err:
        bs.solve(m, steps=4, verbose=False)
    sol = err.value.solution
    assert sol.n_steps == 2 and np.all(np.isfinite(sol.reactions)) and np.all(np.isfinite(sol.poses))


def test_nan_initial_poses_are_named():
    m, b, _ = _rod(4)
    P = m.poses0.copy()
    P[2, 0, 3] = np.nan
    with pytest.raises(bs.InputError, match=r"initial_poses"):
        bs.solve(m, steps=2, verbose=False, initial_poses=P)


def test_beams_on_one_centre_line_in_contact_are_named():
    m = bs.Model()
    sec = bs.Section.circular(radius=0.01, **STEEL)
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), sec)
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), sec)
    m.clamp(a.first)
    m.clamp(b.first)
    m.add_contact(a, b)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)    # numpy's division by the zero distance
        with pytest.raises(bs.InputError, match="add_contact no. 0.*share a centre line"):
            bs.solve(m, steps=2, verbose=False)


# ------------------------------------------------------------------ item 11 (second half)
def _joined_cantilever(scale, offset, n=10):
    m = bs.Model()
    sec = bs.Section.circular(radius=0.01 * scale, E=200e9 / scale**2, nu=0.3)
    a = m.add_beam(bs.geometry.straight((offset, 0, 0), (offset + 0.5 * scale, 0, 0), n // 2), sec)
    b = m.add_beam(bs.geometry.straight((offset + 0.5 * scale, 0, 0), (offset + scale, 0, 0), n // 2), sec)
    m.join(a.last, b.first)
    m.clamp(a.first)
    m.add_load(b.last, force=(0, 0, 2000.0))
    return m, b


@pytest.mark.parametrize("scale, offset", [(1.0, 1e6), (1e3, 1e9), (1e-3, 1e3)])
def test_convergence_floor_is_invariant_to_units_and_origin(scale, offset):
    """A joined cantilever (no strain-space update) 1e6 lengths from the origin, in metres,
    millimetres or kilometres, converges to the answer at the origin (before: "no convergence
    in 30 iterations": position round-off kept the increments above dtol)."""
    m0, b0 = _joined_cantilever(1.0, 0.0)
    ref = bs.solve(m0, steps=1, verbose=False).position(b0.last)
    m, b = _joined_cantilever(scale, offset)
    sol = bs.solve(m, steps=1, verbose=False, check_rigid_modes=False)
    tip = (sol.position(b.last) - (offset, 0, 0)) / scale
    np.testing.assert_allclose(tip, ref, atol=1e-6)


# ------------------------------------------------------------------ issue 13 item 3
def test_convergence_decides():
    c = bs.Convergence(rtol=1e-8, dtol=1e-11, max_iter=5, divergence=1e12)
    assert c.decide(1e-9, np.inf, 1) == CONVERGED
    assert c.decide(1.0, 1e-12, 1) == CONVERGED
    assert c.decide(1.0, 1e-10, 1, floor=1e-9) == CONVERGED
    assert c.decide(1e-9, 1e-12, 1, final=False) == CONTINUE
    assert c.decide(1.0, 1.0, 5) == MAX_ITER
    assert c.decide(1e13, 1.0, 2) == DIVERGED
    assert c.decide(1e-3, 1e-3, 2) == CONTINUE


def test_failures_are_typed_and_timings_recorded():
    import roll_up
    model, beam = roll_up.build(2)[:2]
    with pytest.raises(bs.ConvergenceError) as err:
        bs.solve(model, steps=1, min_step_ratio=0.5, verbose=False)
    assert isinstance(err.value.failure, failures.RotationLimit)
    m, b, _ = _rod(4)
    m.add_load(b.last, force=(0, 0, 1e3))
    sol = bs.solve(m, steps=2, verbose=False)
    t = sol.stats[-1]["timings"]
    assert set(t) == {"assembly", "contact", "linear_solve"} and t["assembly"] > 0 and t["linear_solve"] > 0


# ------------------------------------------------------------------ item 8: damped Newton stall
def test_argyris_frame_plain_newton_keeps_the_stable_branch():
    """Undamped Newton in one step to 1.5 N landed on the flat, unstable branch of the imperfect
    frame (tip barely out of plane), flagged only with ``check_stability``.  Now the step is cut
    back where it leaves the stable branch (``stable_branch``, issue 31): the buckled state."""
    m, b = argyris_frame(1.5, n=4)
    sol = bs.solve(m, steps=1, verbose=False, line_search=False, check_stability=True)
    assert sol.position(b.last)[2] > 50.0 and all(s["stable"] for s in sol.stats[1:])
    assert not any(s.get("left_stable_branch") for s in sol.stats)


def test_damped_newton_falls_back_to_newton_past_the_argyris_buckling_load():
    """Before: "damped Newton stalled" at F = 1.093 N with a positive definite tangent.  Now the
    stable imperfect path is followed past the buckling load, every step stable."""
    m, b = argyris_frame(1.1, n=4)
    sol = bs.solve(m, steps=11, verbose=False, check_stability=True)
    assert sol.times[-1] == 1.0 and all(s["stable"] for s in sol.stats[1:])
    assert sol.position(b.last)[2] > 10.0                      # buckled sideways
    assert any("undamped" in s for s in sol.stats)


# ------------------------------------------------------------------ item 14: messages
def test_failure_advice_reads_the_tangent():
    """A failure after an unstable equilibrium says the tangent is indefinite (a limit point or
    bifurcation), not "lower min_step_ratio"; after a stable one it says it is positive definite."""
    from beamsolver.stepping import diagnosis
    from beamsolver.nonlinear.problem import Problem
    for factor, expect in ((2.0, "already indefinite"), (0.5, "positive definite")):
        model = _column(factor)
        sol = bs.solve(model, steps=1, verbose=False)
        problem = Problem.from_model(model)
        advice = diagnosis.advice(failures.NotConverged("no convergence"), problem, sol.poses[-1], 1.0)
        assert expect in advice and ("min_step_ratio" in advice) == (factor < 1)


def _two_stiffnesses(ratio, unit=1.0):
    """Two joined steel beams, the second ``ratio`` times softer; lengths in metres / ``unit``."""
    m = bs.Model()
    sec = bs.Section.circular(radius=0.01 * unit, E=2e11 / unit**2)
    soft = bs.Section.circular(radius=0.01 * unit, E=2e11 / unit**2 / ratio)
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (0.5 * unit, 0, 0), 4), sec)
    b = m.add_beam(bs.geometry.straight((0.5 * unit, 0, 0), (unit, 0, 0), 4), soft)
    m.join(a.last, b.first)
    m.clamp(a.first)
    return m


def test_singular_tangent_advice_tells_ill_conditioning_from_a_free_mode():
    from beamsolver.stepping import diagnosis
    from beamsolver.nonlinear.problem import Problem
    from beamsolver.assembly.system import System
    for ratio, expect in ((1.0, "rigid-body mode"), (1e12, "ill-conditioned")):
        problem = Problem.from_model(_two_stiffnesses(ratio))
        H0 = problem.system.poses0
        assert expect in diagnosis.advice(failures.SingularTangent("singular"), problem, H0, 0.0)
    # units do not change the estimate: the same scene in millimetres
    spread = []
    for unit in (1.0, 1e3):
        s = System(_two_stiffnesses(1.0, unit))
        spread.append(diagnosis.stiffness_spread(s, s.matrix(s.evaluate(s.poses0, np.zeros(0))[1])))
    assert spread[0] == pytest.approx(spread[1], rel=1e-9) and spread[0] < diagnosis.ILL_CONDITIONED


def test_an_unconstrained_beam_is_reported_as_such():
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), bs.Section.circular(radius=0.01, E=2e11))
    m.add_load(b.last, force=(0, 0, 1.0))
    with pytest.raises(bs.ConvergenceError, match="rigid-body mode") as err:
        bs.solve(m, steps=1, check_rigid_modes=False, verbose=False)
    assert isinstance(err.value.failure, failures.SingularTangent)


def test_a_restart_state_with_a_zero_step_does_not_hang():
    """``resume["dt"] = 0`` (a hand-edited or corrupt file) made the stepping loop spin for ever."""
    m, b, _ = _rod(4)
    m.add_load(b.last, force=(0, 0, 1e3))

    def stop(info):
        if info["t"] > 0.55:
            raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt) as err:
        bs.solve(m, steps=4, callback=stop, verbose=False)
    part = err.value.solution
    part.resume["dt"] = 0.0
    sol = bs.solve(m, steps=4, restart=part, verbose=False)
    assert sol.n_steps == 4 and sol.times[-1] == 1.0


def test_a_motion_too_fast_for_the_smallest_step_is_refused_at_once():
    m, b, _ = _rod(8)
    m.prescribe(b.last, bs.motion.rotation((1, 0, 0), 1e6))     # 1e6 rad in one step
    with pytest.raises(bs.ConvergenceError, match="MAX_MOTION_ROTATION") as err:
        bs.solve(m, steps=1, verbose=False)
    assert isinstance(err.value.failure, failures.MotionTooFast) and err.value.solution.n_steps == 0


@pytest.mark.parametrize("t_fail", [0.5, 0.7, 0.9, 0.99])
def test_a_failure_at_the_smallest_step_stops_whatever_the_round_off_of_t(monkeypatch, t_fail):
    """Every step past ``t_fail`` fails: the halvings reach the smallest step and, when that fails too, the run
    stops with ``ConvergenceError``.  A smallest step of 2e-9 at t ~ 0.9 is 2e7 ulps of t: ``t + dt - t``
    differs from ``dt`` by up to ~5e-8 of it, more than ``STEP_TOLERANCE``; where it rounded up, the failed
    smallest step was taken for a longer one and tried again forever (the plectoneme's five-turn run with
    a dense LU at t = 0.939147036)."""
    from beamsolver.nonlinear import newton
    m, b, _ = _rod(4)
    m.add_load(b.last, force=(0, 0, 10.0), scale=lambda t: t)
    step, tries = newton.Newton.step, []

    def failing(self, H, t, H_target, t_prev=None):
        if t > t_fail:
            tries.append(t)
            if len(tries) > 200:
                raise RuntimeError(f"the same failed step is retried: {len(tries)} tries at t = {t!r}")
            raise failures.NotConverged("no convergence (test)", 1.0)
        return step(self, H, t, H_target, t_prev)
    monkeypatch.setattr(newton.Newton, "step", failing)
    with pytest.raises(bs.ConvergenceError, match="step fell below"):
        bs.solve(m, steps=1, min_step_ratio=2e-9, verbose=False)
    assert len(tries) <= 80 and t_fail < tries[-1] <= t_fail + 2e-9 * (1 + 1e-6)
