"""The stable-branch rule of load stepping (``stable_branch``, issue 31 item 1) and the determinant
sign that flags the steps it checks (``linsolve``)."""
import itertools
import warnings

import numpy as np
import pytest
import scipy.sparse as sp

import beamsolver as bs
from beamsolver.stepping import stable_branch
from beamsolver.nonlinear.linsolve import Solver, permutation_sign


def _sign_by_inversions(p):
    return -1 if sum(a > b for a, b in itertools.combinations(p, 2)) % 2 else 1


@pytest.mark.parametrize("n", [1, 2, 3, 7, 40])
def test_permutation_sign_counts_inversions(n, rng):
    for _ in range(10):
        p = rng.permutation(n)
        assert permutation_sign(p) == _sign_by_inversions(p)


def test_splu_determinant_sign_is_numpys(rng):
    for k in range(12):
        A = rng.standard_normal((25, 25))
        K = sp.csc_matrix(A + A.T + (k - 4.0) * np.eye(25))
        assert Solver("splu").factorize(K).det_sign() == np.sign(np.linalg.det(K.toarray()))


def _perfect_column(ratio, n=16):
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n),
                   bs.Section(EA=1e7, GA2=1e7, GA3=1e7, GJ=1.0, EI2=4.0, EI3=1.0, radius=0.01))
    m.clamp(b.first)
    m.add_load(b.last, force=(-ratio * np.pi**2 / 4.0, 0.0, 0.0))
    return m, b


def test_a_perfect_column_past_p_cr_is_kept_unstable_and_said_so():
    """No stable state near the straight path past P_cr: steps are cut back (at most RETRIES times
    a step, RETRIES_RUN in a row of steps), then the straight (unstable) column is kept with a
    StabilityWarning and ``left_stable_branch``."""
    m, b = _perfect_column(1.5)
    with pytest.warns(bs.StabilityWarning, match="stable branch ends here"):
        sol = bs.solve(m, steps=2, verbose=False)
    flagged = [s for s in sol.stats if s.get("left_stable_branch")]
    assert len(flagged) == 1 and sum(s["cutbacks"] for s in sol.stats) <= stable_branch.RETRIES_RUN
    assert sol.n_steps <= 16               # 14: homing in on P_cr by halves, then regrowing to t = 1
    assert abs(sol.position(b.last)[1]) < 1e-9 and "stable branch ends here" in sol.message


def test_below_p_cr_nothing_is_checked_or_said():
    m, b = _perfect_column(0.9)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol = bs.solve(m, steps=4, verbose=False)
    assert sol.message == "" and not any(s.get("left_stable_branch") for s in sol.stats)


def test_switched_off_stability_checks_leave_the_path_alone():
    """``check_stability=False`` decides nothing about stability: no step of the perfect column past P_cr is cut
    back for leaving the stable branch and nothing is said (with checks: cut back, kept, warned, above).  The
    frictionless long-lay strand's elastic check (examples/strand_bending.py) needs it: its wires' torsion-bending
    modes, which the frictionless contact barely holds, cross zero under the pull (docs/benchmarks.md, session 9)."""
    m, b = _perfect_column(1.5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol = bs.solve(m, steps=2, verbose=False, check_stability=False)
    assert sol.n_steps == 2 and sum(s["cutbacks"] for s in sol.stats) == 0
    assert not any(s.get("left_stable_branch") for s in sol.stats) and sol.message == ""
    assert abs(sol.position(b.last)[1]) < 1e-9
