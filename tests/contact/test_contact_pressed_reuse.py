"""The normal law's active set near the solution (``newton.NORMAL_SWITCHES``) evaluates the contact at the full Newton
step to see which points it opens; with ``newton.PRESSED_AT_TRIAL`` that evaluation is made with the multipliers of
the line search's full step, which the normal law does not depend on, and the line search's first trial at the same
poses reuses it (``ContactSystem._local_blocks``' kept blocks; ``force_open(None)`` keeps them when nothing was forced).
"""
import numpy as np

import beamsolver as bs
from beamsolver.contact import system as contact_system
from beamsolver.nonlinear import newton

import shear_lag


def _solve(monkeypatch, reuse, with_tangent=True):
    """The shear lag with or without the reuse (``with_tangent``: ``newton.TANGENT_AT_PRESSED``): ``(solution, contact
    evaluations computed, exact stick's forces-only passes)``."""
    monkeypatch.setattr(newton, "PRESSED_AT_TRIAL", reuse)
    monkeypatch.setattr(newton, "TANGENT_AT_PRESSED", with_tangent)
    computed, forces_only = [0], [0]
    params, mortar = contact_system.ContactSystem._params, contact_system.ContactSystem._mortar

    def counted(self, P, sel, H):
        computed[0] += 1
        return params(self, P, sel, H)

    def counted_mortar(self, H, P, sel, p, idx, out, tangent=True, *a, **k):
        forces_only[0] += not tangent
        return mortar(self, H, P, sel, p, idx, out, tangent, *a, **k)

    with monkeypatch.context() as m:
        m.setattr(contact_system.ContactSystem, "_params", counted)
        m.setattr(contact_system.ContactSystem, "_mortar", counted_mortar)
        sol = bs.solve(shear_lag.build()[0], **shear_lag.solve_options)
    return sol, computed[0], forces_only[0]


def test_the_full_step_s_pressed_points_serve_the_line_search_s_first_trial(monkeypatch):
    """The shear lag: the same iterates, residuals and poses bit for bit with and without the reuse, and fewer contact
    evaluations computed (70 -> 64 when written)."""
    before, n_before, _ = _solve(monkeypatch, False)
    after, n_after, _ = _solve(monkeypatch, True)
    assert [s["residuals"] for s in after.stats] == [s["residuals"] for s in before.stats]
    assert np.array_equal(np.array(after.poses), np.array(before.poses))
    assert n_after < n_before


def test_the_pressed_points_do_not_depend_on_the_multipliers_trial_length(monkeypatch):
    """Every call of the shear lag's Newton loop: the pressed points with the multipliers' trial length 0 and 1 are
    the same (what ``PRESSED_AT_TRIAL`` relies on)."""
    points = contact_system.ContactSystem.pressed_points
    seen = []

    def both(self, H, law=False, tangent=False):
        ms = self._ms
        self.multiplier_trial(0.0)
        a = points(self, H)
        self.multiplier_trial(1.0)
        b = points(self, H)
        self.multiplier_trial(ms)
        seen.append((self._mstep is not None and len(self._mstep[0]) > 0, np.array_equal(a, b)))
        return points(self, H, law, tangent)

    monkeypatch.setattr(contact_system.ContactSystem, "pressed_points", both)
    sol = bs.solve(shear_lag.build()[0], **shear_lag.solve_options)
    assert sol.converged and all(equal for _, equal in seen)
    assert sum(step for step, _ in seen) > 5          # with a Newton step of the multipliers to move


def test_the_full_step_s_pressed_points_carry_the_tangent_the_trial_asks_for(monkeypatch):
    """The shear lag: where the line search's full-step trial asks for the tangent (``newton.FULL_AFTER_FULL``), the
    pressed points' evaluation it reuses computes it (``newton.TANGENT_AT_PRESSED``): exact stick's mortar kernel
    runs once at those poses, not a forces-only pass and then the tangent's; the same residuals and poses bit for
    bit, the same contact evaluations, fewer forces-only passes."""
    before, n_before, lazy_before = _solve(monkeypatch, True, False)
    after, n_after, lazy_after = _solve(monkeypatch, True, True)
    assert [s["residuals"] for s in after.stats] == [s["residuals"] for s in before.stats]
    assert np.array_equal(np.array(after.poses), np.array(before.poses))
    assert n_after == n_before
    assert lazy_after < lazy_before


def test_the_iteration_s_factor_is_let_go_before_the_pressed_points_tangent(monkeypatch):
    """With ``TANGENT_AT_PRESSED`` the line search's full-step contact tangent is computed inside
    ``Newton._normal_branches`` (the full step's ``pressed_points``): the iteration's factorised tangent (the
    ``Augmented`` system: ``K'``, ``A`` and the factor of ``A``) is dropped first (``DROP_FACTOR``), as ``iterate`` drops
    it before the line search, so that the two are not held together (the 61-wire strand's peak in the non-lagged
    mode, the issue-30 target's).  The same residuals and poses bit for bit as without ``TANGENT_AT_PRESSED``."""
    import weakref
    from beamsolver.nonlinear import linsolve, problem

    monkeypatch.setattr(linsolve, "LAGGED", False)
    last, alive = [], []
    direction, pressed = newton.Newton.direction, problem.Problem.pressed_points

    def watched(self, ev, dz_c=None):
        lu, dzf = direction(self, ev, dz_c)
        last[:] = [weakref.ref(lu)]
        return lu, dzf

    def seen(self, H, law=False, tangent=False):
        if tangent:
            alive.append(last[0]() is not None)
        return pressed(self, H, law, tangent)

    before = _solve(monkeypatch, True, False)[0]
    monkeypatch.setattr(newton.Newton, "direction", watched)
    monkeypatch.setattr(problem.Problem, "pressed_points", seen)
    after = _solve(monkeypatch, True, True)[0]
    assert alive and not any(alive), alive
    assert [s["residuals"] for s in after.stats] == [s["residuals"] for s in before.stats]
    assert np.array_equal(np.array(after.poses), np.array(before.poses))
