"""A fast subset of benchmarks/stability.py: stiff and extreme cases either converge to the right
answer or stop with a clear error (never NaN, a hang, or a silent wrong answer)."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import stability as S  # noqa: E402


@pytest.mark.parametrize("ratio", [10, 1e3, 1e5])
def test_slender_roll_up_is_exact_and_quadratic(ratio):
    sol, _, err = S.roll_up(radius=1.0 / ratio, n=16)
    assert err < 1e-9
    assert S._quadratic(sol) < 50.0


@pytest.mark.parametrize("ratio", [10, 1e5])
def test_slender_bend_converges_quadratically(ratio):
    r = S.case_slender_bend(ratio)
    assert r["outcome"] == "converged" and r["max_iterations"] <= 8
    q = float(r["accuracy"].split("r+/r^2 ")[1].split(";")[0])
    assert q < 50.0


def test_units_do_not_change_the_iterations():
    a, _, ea = S.roll_up(turns=0.75, n=12, steps=2, L=1.0, radius=0.01, E=210e9)
    b, _, eb = S.roll_up(turns=0.75, n=12, steps=2, L=1000.0, radius=10.0, E=210e3)
    assert a.iterations.tolist() == b.iterations.tolist()
    assert ea < 1e-9 and eb < 1e-9


def test_bar_twisted_by_twenty_turns_is_exact():
    r = S.case_twist(20, 100)
    assert r["outcome"] == "converged"
    assert float(r["accuracy"].split("twist rate error ")[1].split(";")[0]) < 1e-10


def test_element_turning_by_pi_is_refused_with_advice():
    r = S.case_near_pi()
    assert r["outcome"].startswith("ConvergenceError") and "refine the mesh" in r["outcome"]


def test_one_step_and_many_steps_give_the_same_bend():
    one, many = S.case_steps(1), S.case_steps(100)
    for r in (one, many):
        assert r["outcome"] == "converged"
        assert float(r["accuracy"].split("tip error vs converged ")[1].split(" ")[0]) == pytest.approx(0.166, abs=1e-3)


def test_cut_back_then_regrowth():
    r = S.case_cutback()
    assert r["outcome"] == "converged" and "regrew: yes" in r["accuracy"]
    assert r["smallest_step"] == pytest.approx(0.125)


@pytest.mark.parametrize("case", [lambda: S.case_penalty(1e-3), lambda: S.case_penalty(1e3), S.case_augmented,
                                  lambda: S.case_radius_ratio(100), lambda: S.case_angle(1e-4),
                                  lambda: S.case_initial(-0.01), lambda: S.case_initial(0.01)])
def test_contact_extremes_balance(case):
    r = case()
    assert r["outcome"] == "converged"
    balance = float(r["accuracy"].split("balance ")[1].split(",")[0])
    assert balance < 1e-6


def test_augmented_lagrangian_meets_its_tolerance_with_prescribed_motion():
    r = S.case_augmented()
    pen = float(r["accuracy"].split("penetration ")[1].split(" R")[0])
    assert pen <= 1e-6


def test_contact_lost_and_regained():
    r = S.case_lost_regained()
    assert r["outcome"] == "converged" and "as expected" in r["accuracy"]


def test_stick_slip_reversal_obeys_coulomb():
    r = S.case_reversal()
    assert r["outcome"] == "converged" and "force reverses: yes" in r["accuracy"]
    ratios = [float(x) for part in r["accuracy"].split(";")[0].split(",") for x in part.split()[-1].split("-")]
    np.testing.assert_allclose(ratios, 1.0, atol=1e-6)
