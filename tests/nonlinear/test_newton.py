"""Newton converges quadratically: the scaled residual is squared from one iteration to the next.

The residual history is the one the solver records (``Solution.stats[k]["residuals"]``,
the scaled residual of every iterate of step ``k``).  Near the solution an exact
tangent gives ``r_{k+1} <= C r_k^2``; ``assert_quadratic`` checks it on every pair
in the asymptotic range (``r_k < 1e-2``) whose successor is above the round-off
floor (estimated from the history).  The last tests show that the check fails for a linearly converging
Newton (a scaled tangent, a missing load stiffness), so it can fail.
"""

import numpy as np
import pytest

import beamsolver as bs
from beamsolver import geometry
from beamsolver.assembly.system import System
from helpers import assert_quadratic, quadratic_pairs  # noqa: F401

import bend45

def last_step_residuals(model, **options):
    options.setdefault("rtol", 1e-13)
    sol = bs.solve(model, steps=1, **options)
    assert sol.stats[-1]["cutbacks"] == 0
    return sol.stats[-1]["residuals"], sol


# ------------------------------------------------------------------ scenes
def _section():
    return bs.Section(EA=2e4, GA2=8e3, GA3=8e3, GJ=60.0, EI2=40.0, EI3=50.0, radius=0.02)


def _helix_roll_up(n=8, fraction=0.25, twist=1.0):
    """A straight cantilever under a follower moment with bending and torsion: it becomes a helix."""
    sec, L = _section(), 1.0
    m = bs.Model()
    b = m.add_beam(geometry.straight((0, 0, 0), (L, 0, 0), n), sec)
    m.clamp(b.first)
    m.add_load(b.last, moment=(twist * sec.C[3, 3] / L, 0.0, fraction * 2 * np.pi * sec.C[5, 5] / L),
               follower=True)
    return m, b


def _joined_roll_up(n=8, fraction=0.05):
    """The roll-up of a cantilever made of two beams joined in the middle.

    The joint takes the beam out of the strain-space chain update, so Newton
    iterates with the plain ``H exp(dq)`` update and needs several iterations.
    """
    sec, L = _section(), 1.0
    m = bs.Model()
    b1 = m.add_beam(geometry.straight((0, 0, 0), (L / 2, 0, 0), n // 2), sec)
    b2 = m.add_beam(geometry.straight((L / 2, 0, 0), (L, 0, 0), n // 2), sec)
    m.join(b1.last, b2.first)
    m.clamp(b1.first)
    m.add_load(b2.last, moment=(0.0, 0.0, fraction * 2 * np.pi * sec.C[5, 5] / L), follower=True)
    return m, b2


def _dead_loaded_cantilever(n=8, scale=1.0):
    """Dead tip force and dead tip moment in general directions: load stiffness matters."""
    sec, L = _section(), 1.0
    m = bs.Model()
    b = m.add_beam(geometry.straight((0, 0, 0), (L, 0, 0), n), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=scale * np.array([-20.0, 60.0, 90.0]), moment=scale * np.array([15.0, -30.0, 25.0]))
    return m, b


# ------------------------------------------------------------------ quadratic convergence
@pytest.mark.parametrize("n", [8, 16])
def test_bend45_single_step_is_quadratic(n):
    model, _ = bend45.build(n)
    r, sol = last_step_residuals(model)
    pairs = assert_quadratic(r)
    assert sol.stats[-1]["iterations"] <= 8
    assert len(pairs) >= 1


def test_helix_roll_up_is_quadratic():
    model, _ = _helix_roll_up()
    r, sol = last_step_residuals(model)
    assert sol.stats[-1]["iterations"] >= 3        # a real iteration history, not a one-shot
    assert_quadratic(r)


def test_joined_roll_up_smaller_moment_is_quadratic():
    """Roll-up to 5 % of the full circle through a joint: several plain Newton iterations.

    Without line search (see the xfail test below for why).
    """
    model, beam = _joined_roll_up(fraction=0.05)
    r, sol = last_step_residuals(model, line_search=False)
    assert sol.stats[-1]["iterations"] >= 3
    assert_quadratic(r)
    # and the answer is the exact arc
    x = sol.poses[-1][:, :3, 3]
    rho = 1.0 / (2 * np.pi * 0.05)
    assert np.abs(np.linalg.norm(x - [0.0, rho, 0.0], axis=1) - rho).max() < 1e-9


def test_joined_roll_up_with_line_search_converges_in_a_few_iterations():
    """The first Newton iterate raises the residual a lot (axial forces after a large rotation
    increment); the damped Newton accepts it because the Newton correction there is smaller
    (``solver.Newton._damped``), as plain Newton would (4 iterations; the residual line search
    it replaced took 22, and 7 with its natural-monotonicity test)."""
    model, _ = _joined_roll_up(fraction=0.05)
    sol = bs.solve(model, steps=1, max_iter=15, min_step_ratio=0.5)
    assert sol.stats[-1]["iterations"] <= 5
    assert "damped" not in sol.stats[-1]                 # every full Newton step was kept


def test_dead_loads_are_quadratic():
    model, beam = _dead_loaded_cantilever()
    r, sol = last_step_residuals(model)
    assert sol.stats[-1]["iterations"] >= 3
    assert_quadratic(r)
    # the tip really turned (the load stiffness is not a small correction)
    R = sol.rotation(beam.last)
    assert np.arccos(np.clip(R[0, 0], -1, 1)) > 0.5


# ------------------------------------------------------------------ the check can fail
def _scaled_tangent(monkeypatch, factor=1.5):
    """A linearly converging Newton: every tangent multiplied by ``factor`` (rate ``1 - 1/factor``)."""
    original = System.evaluate

    def evaluate(self, H, load_factors, tangent=True):
        r, kvals, info = original(self, H, load_factors, tangent)
        return r, (None if kvals is None else factor * kvals), info
    monkeypatch.setattr(System, "evaluate", evaluate)


def _without_load_stiffness(monkeypatch):
    """Drop the dead-load stiffness blocks (they follow the element entries in ``kvals``)."""
    original = System.evaluate

    def evaluate(self, H, load_factors, tangent=True):
        r, kvals, info = original(self, H, load_factors, tangent)
        if tangent:
            assert len(self.global_nodes) == 0
            kvals = kvals.copy()
            kvals[144 * self.n_elements:] = 0.0
        return r, kvals, info
    monkeypatch.setattr(System, "evaluate", evaluate)


def _fails_quadratic_check(model, **options):
    try:
        r, _ = last_step_residuals(model, min_step_ratio=0.5, max_iter=40, **options)
    except (bs.ConvergenceError, AssertionError):
        return True                 # did not even converge in one step
    try:
        assert_quadratic(r)
    except AssertionError:
        return True
    return False


def test_check_fails_for_a_linearly_converging_newton(monkeypatch):
    model, _ = bend45.build(8)
    assert not _fails_quadratic_check(model)
    _scaled_tangent(monkeypatch)
    model, _ = bend45.build(8)
    r, _ = last_step_residuals(model, max_iter=60)       # it still converges, at the rate 1/3 ...
    assert len(r) > 15
    assert _fails_quadratic_check(model)                  # ... which the check rejects


def test_check_fails_without_the_load_stiffness(monkeypatch):
    model, _ = _dead_loaded_cantilever(scale=0.3)
    assert not _fails_quadratic_check(model)       # the intact solver passes ...
    _without_load_stiffness(monkeypatch)
    model, _ = _dead_loaded_cantilever(scale=0.3)
    r, _ = last_step_residuals(model, max_iter=60)  # ... converges linearly without the load stiffness ...
    assert len(r) > 15
    assert _fails_quadratic_check(model)           # ... and fails the check


@pytest.mark.slow
def test_factorised_tangent_memory_serves_the_next_evaluation(monkeypatch):
    """Once an iterate's tangent is factorised its contact blocks are dropped
    (``Evaluation.drop_tangent``): the trial evaluation of the next iterate, which computes the next
    tangent, takes the same memory from the contact's tangent pool.  A 1+6 strand stretched in one
    step (clamped ends, no transformed nodes: the blocks reach ``extra`` as views of the pool's
    memory): the step's Newton iterations on one buffer, besides the start's (held by its
    converged evaluation).  (Without ``buffers.RELEASE_AT_COMMIT``, which lets the start's idle buffer go at its
    commit: ``tests/model/test_buffers.py``.)"""
    from beamsolver.driver import Convergence, Newton
    from beamsolver.nonlinear.problem import Problem
    from beamsolver.stepping.steps import Run

    monkeypatch.setattr("beamsolver.model.contact_options.EXACT_C_AXIAL", 0.0)   # the library's c: this path's buffers
    monkeypatch.setattr("beamsolver.model.buffers.RELEASE_AT_COMMIT", False)
    L = bs.cables.Layer
    st = bs.cables.build_strand([L(1e-3), L(1e-3, 6, lay_length=0.1)], 0.1, E=2e11, elements_per_lay=8, mu=0.3,
                                fit_core=True)
    st.clamp("bottom")
    for w in st.all_wires:
        st.model.prescribe(w.last, bs.motion.translation(lambda t: (0.0, 0.0, 1e-4 * t)))
    problem = Problem.from_model(st.model)
    pool = problem.contributions[0]._tangent_pool
    bases, take = set(), pool.take

    def counted(shape):
        view = take(shape)
        bases.add(id(view.base))
        return view
    pool.take = counted
    newton = Newton(problem, Convergence(), True, None)
    run = Run(problem, newton, None, np.linspace(0.0, 1.0, 2), 1e-3, False, dict(advice=lambda *a: ""))
    run.start(None, None)
    run.loop()
    sol = run.finish()
    assert sol.n_steps == 1 and int(sol.iterations[1]) >= 3
    assert len(bases) == 2


def test_the_full_step_trial_after_a_kept_full_step_has_the_tangent_and_the_same_iterates(monkeypatch):
    """Exact stick's line search (``Newton.backtrack``) evaluates its full-step trial without the tangent, unless the
    step's last line search kept the full step (``FULL_AFTER_FULL``: then the trial is likely kept, and its tangent is
    the next iteration's).  The residual does not depend on it: the shear lag (10 elements) takes the same iterates,
    residuals and poses bit for bit, with fewer evaluations (the main job: 588 -> 528)."""
    import shear_lag
    from beamsolver.nonlinear import newton
    from beamsolver.nonlinear.problem import Problem
    orig = Problem.evaluate
    runs = {}
    for flag in (False, True):
        count = [0, 0]

        def counted(self, H, t, tangent=True):
            count[0 if tangent else 1] += 1
            return orig(self, H, t, tangent=tangent)
        monkeypatch.setattr(Problem, "evaluate", counted)
        monkeypatch.setattr(newton, "FULL_AFTER_FULL", flag)
        sol = shear_lag.main(n_wire=10, stick="exact")[0]
        runs[flag] = (sol, list(count))
    (a, ca), (b, cb) = runs[False], runs[True]
    assert [s["residuals"] for s in a.stats] == [s["residuals"] for s in b.stats]
    assert all(np.array_equal(x, y) for x, y in zip(a.poses, b.poses))
    assert cb[1] < ca[1] and sum(cb) < sum(ca), (ca, cb)
