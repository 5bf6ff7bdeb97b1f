"""Unstable equilibria are said by default (issue 28 item 5): every converged step records ``stable``
(``stepping.stability``), an unstable one is warned about once a run, ``stable=None`` always comes with
its reason, and options that would do nothing together are refused."""
import warnings

import numpy as np
import pytest
import scipy.sparse as sp

import beamsolver as bs
from beamsolver.nonlinear.definiteness import Inertia, negative_eigenvalues
from beamsolver.stepping import stable_branch

from published.scenes import argyris_frame, column  # noqa: E402
import crossing_beams  # noqa: E402
from limit_points import truss  # noqa: E402


def _solve(model, **kw):
    """``(solution, warnings)`` of a quiet solve, every warning recorded."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = bs.solve(model, verbose=False, **kw)
    return sol, [w for w in caught if issubclass(w.category, bs.StabilityWarning)]


def _stable(sol):
    return [s["stable"] for s in sol.stats]


# ------------------------------------------------------------------ said by default
@pytest.mark.parametrize("EI2, count", [(1.0, 2), (4.0, 1)])
def test_a_perfect_column_at_twice_p_cr_is_said_unstable(EI2, count):
    """Straight, kick-free clamped-free column at 2 P_cr in one step: it stays straight.  A round
    section has a double buckling eigenvalue (det > 0: the determinant sign the stable-branch rule
    reads sees nothing) and was returned without a word; now the step says ``stable=False`` and
    one warning names the step, its time and the count."""
    m, b, _ = column(ratio=2.0, kick=0.0, EI2=EI2)
    sol, said = _solve(m, steps=1)
    assert np.abs(sol.position(b.last)[1:]).max() < 1e-9            # straight: the unstable equilibrium
    assert sol.stats[0]["stable"] is True and sol.stats[-1]["stable"] is False
    assert sol.stats[-1]["negative_eigenvalues"] == count
    assert len(said) == 1 and f"has {count} negative eigenvalue(s)" in str(said[0].message)
    first = _stable(sol).index(False)                 # the rectangle: after the stable-branch rule's cut-backs
    assert f"step {first} (t = {sol.times[first]:.6g})" in str(said[0].message) and "unstable" in sol.message


def test_argyris_frame_with_plain_newton_on_the_unstable_branch_is_said(monkeypatch):
    """Plain Newton (``line_search=False``) on Argyris' frame with the stable-branch rule off (a
    user following the branch Newton finds) ends on the unstable in-plane branch: said."""
    monkeypatch.setattr(stable_branch, "ENABLED", False)
    m, b = argyris_frame(1.5)
    sol, said = _solve(m, steps=4, line_search=False)
    assert abs(sol.position(b.last)[2]) < 1.0                        # in plane: not the buckled branch
    assert sol.stats[-1]["stable"] is False and sol.stats[-1]["negative_eigenvalues"] >= 1
    assert len(said) == 1 and "unstable" in str(said[0].message)


def test_argyris_frame_kept_unstable_by_the_rule_records_it():
    """A nearly perfect frame: the stable-branch rule keeps the unstable state after its cut-backs;
    its step records ``stable=False`` (it recorded nothing) and one warning says the branch ends."""
    m, b = argyris_frame(1.5, imperfection=1e-6)
    sol, said = _solve(m, steps=2, line_search=False)
    assert None not in _stable(sol) and sol.stats[-1]["stable"] is False
    assert len(said) == 1 and "stable branch ends here" in str(said[0].message)


def test_a_stable_run_records_stable_everywhere_and_says_nothing():
    m, b, _ = column(ratio=0.9, kick=0.01)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol = bs.solve(m, steps=4, verbose=False)
    assert _stable(sol) == [True] * 5 and sol.message == ""
    assert all(s["negative_eigenvalues"] == 0 and "stable_note" not in s for s in sol.stats)


def test_arc_length_records_the_unstable_branch_it_follows():
    """The truss snap-through by arc length: the steps between the two limit points record
    ``stable=False``; the first is said (without load-stepping advice)."""
    m, apex = truss()
    sol, said = _solve(m, steps=10, t_end=1.5, path="arc-length")
    t, stable = sol.times, _stable(sol)
    assert None not in stable and len(said) == 1 and "branch_switching" not in str(said[0].message)
    falling = np.flatnonzero(np.diff(t) < 0) + 1              # past the upper limit, before the lower one
    assert len(falling) and all(stable[k] is False for k in falling[1:-1])
    assert stable[0] is True and stable[-1] is True           # snapped through


# ------------------------------------------------------------------ None only with its reason
def test_friction_records_none_with_its_reason():
    m, _, _ = crossing_beams.build(load=50.0, n_elements=8, mu=0.3)
    sol, said = _solve(m, steps=2)
    assert _stable(sol) == [None] * 3 and not said
    assert all("friction" in s["stable_note"] for s in sol.stats)
    sol, said = _solve(crossing_beams.build(load=50.0, n_elements=8, mu=0.3)[0], steps=2, check_stability=True)
    assert len(said) == 1 and "stable=None" in str(said[0].message) and "friction" in str(said[0].message)


def test_follower_loads_record_none_with_their_reason():
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), bs.Section.circular(radius=0.01, E=2e11))
    m.clamp(b.first)
    m.add_load(b.last, force=(0, 0, 10.0), follower=True)
    sol, _ = _solve(m, steps=2)
    assert _stable(sol) == [None] * 3 and all("follower loads" in s["stable_note"] for s in sol.stats)


def test_switched_off_says_so():
    m, b, _ = column(ratio=2.0, kick=0.0, EI2=1.0)
    sol, said = _solve(m, steps=1, check_stability=False)
    assert _stable(sol) == [None, None] and not said
    assert all("check_stability=False" in s["stable_note"] for s in sol.stats)


@pytest.mark.parametrize("check", [None, True])
def test_stabilized_runs_record_the_models_stability(check):
    """With ``stabilize`` the problem has no potential (viscous forces), which made ``check_stability``
    record ``stable=None`` silently.  The model's own tangent (damping left out) is checked: the
    perfect round column stays straight under damping too and is said unstable."""
    m, b, _ = column(ratio=2.0, kick=0.0, EI2=1.0)
    sol, said = _solve(m, steps=4, stabilize=True, check_stability=check)
    assert None not in _stable(sol) and sol.stats[-1]["stable"] is False
    assert sol.stats[-1]["negative_eigenvalues"] == 2 and "without the stabilisation" in sol.stats[-1]["stable_note"]
    assert len(said) == 1
    m, b, _ = column(ratio=0.5, kick=0.01)
    sol, said = _solve(m, steps=4, stabilize=True, check_stability=check)
    assert _stable(sol) == [True] * 5 and not said


@pytest.mark.parametrize("options, match", [
    (dict(check_stability=False, modes=2), "check_stability=False contradicts modes=2"),
    (dict(check_stability=False, branch_switching="auto"), "contradicts branch_switching='auto'"),
    (dict(branch_switching="auto", stabilize=True), "two ways past an instability"),
    (dict(check_stability="yes"), "check_stability must be"),
])
def test_combinations_that_would_do_nothing_are_refused(options, match):
    m, _, _ = column(ratio=0.5, kick=0.01)
    with pytest.raises(bs.InputError, match=match):
        bs.solve(m, steps=1, verbose=False, **options)


@pytest.mark.parametrize("options", [dict(modes=1), dict(branch_switching=True)])
def test_modes_and_switching_without_a_potential_are_refused(options):
    m, _, _ = crossing_beams.build(load=50.0, n_elements=8, mu=0.3)
    with pytest.raises(bs.InputError, match="friction in contact"):
        bs.solve(m, steps=1, verbose=False, **options)


# ------------------------------------------------------------------ the cheap inertia
def _banded(n, shift, rng, width=3):
    """Symmetric, banded after a random symmetric permutation, diagonal scales over 4 decades."""
    diags = [rng.standard_normal(n - abs(k)) for k in range(-width, width + 1)]
    A = sp.diags(diags, range(-width, width + 1))
    A = 0.5 * (A + A.T) + (2.0 * width + shift) * sp.identity(n)
    p = rng.permutation(n)
    S = sp.diags(10.0 ** rng.uniform(0, 4, n))
    return sp.csc_matrix(sp.csr_matrix(S @ A @ S)[p][:, p])


def _same(a, b):
    """Equal counts, lowest eigenvalues equal to Lanczos' round-off (both ``None`` when definite)."""
    return a[0] == b[0] and (a[1] is None and b[1] is None or a[1] == pytest.approx(b[1], rel=1e-10))


@pytest.mark.parametrize("n", [40, 900])
def test_inertia_is_negative_eigenvalues(n, rng):
    inertia = Inertia()
    for shift in (-3.0, -1.0, 0.5, 4.0):
        K = _banded(n, shift, rng)
        assert _same(inertia(K), negative_eigenvalues(K))
    assert inertia.layouts == 4                       # a new pattern each time
    K = _banded(n, 4.0, rng)
    assert inertia(K) == (0, None)
    K.data *= -1.0 if n < 100 else 2.0                # the same pattern (negative definite: dense path only)
    assert _same(inertia(K), negative_eigenvalues(K)) and inertia(K)[0] == (n if n < 100 else 0)
    assert inertia.layouts == 5                       # the same pattern: the layout kept


def test_inertia_falls_back_on_unsymmetric_patterns_and_wide_bands(rng):
    n = 200
    K = _banded(n, 4.0, rng).tolil()
    K[0, n - 1] = 1e-3                                # structurally unsymmetric
    K = sp.csc_matrix(K)
    assert Inertia()(K) == negative_eigenvalues(K) == (0, None)
    dense = rng.standard_normal((n, n))
    for shift, definite in ((-0.1, False), (0.1, True)):          # full: no band, the sparse LDL^T
        K = sp.csc_matrix(dense @ dense.T + shift * n * np.eye(n))
        assert _same(Inertia()(K), negative_eigenvalues(K)) and (Inertia()(K)[0] == 0) == definite


def test_an_unsolved_step_zero_off_equilibrium_is_not_judged():
    """Step 0 kept as given (nothing acts at t_start) is checked only if it is an equilibrium:
    given poses bent off the reference are not one, and their stability is not defined."""
    m, b, _ = column(ratio=0.5, kick=0.01)
    H = bs.solve(m, steps=1, verbose=False).poses[-1]           # bent; at t = 0 no load holds it
    sol, said = _solve(m, steps=1, initial_poses=H)
    assert sol.stats[0]["stable"] is None and "not an equilibrium" in sol.stats[0]["stable_note"]
    assert sol.stats[1]["stable"] is True and not said
