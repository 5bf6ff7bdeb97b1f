"""Extreme contact penalties (issue 28 item 12): a failed solve names the penalty, and ``solve``
warns once when ``penalty x L_e`` exceeds the beams' ``EA / L_e`` by ``ILL_CONDITIONED_PENALTY``.

Before: a penalty 1e11 times its default ended with "large rotations of slender beams need
small load steps ..." (the tangent's generic advice), at t_start with "start the loads from
zero", and nothing warned about the penalty."""
import warnings

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.contact.conditioning import ILL_CONDITIONED_PENALTY, STIFF_PENALTY, penalty_ratios
from beamsolver.nonlinear.problem import Problem

import twisted_pair_extreme as twisted_pair

R, E = 0.05, 1e7
SEC = bs.Section.circular(radius=R, E=E, nu=0.3)


def _pressed(penalty=None):
    """A slave (2 elements of 0.3) moved down by 0.5 R onto a clamped-clamped master
    (7 elements of 2/7) across it, centre lines 2.2 R apart."""
    m = bs.Model()
    master = m.add_beam(bs.geometry.straight((0, -1, 0), (0, 1, 0), 7), SEC, name="master")
    slave = m.add_beam(bs.geometry.straight((-0.3, 0, 2.2 * R), (0.3, 0, 2.2 * R), 2), SEC, name="slave")
    m.clamp(master.first)
    m.clamp(master.last)

    def down(t):
        G = np.eye(4)
        G[2, 3] = -0.5 * R * t
        return G
    for node in slave.nodes:
        m.prescribe(node, down)
    m.add_contact(slave, master, penalty=penalty)
    return m


def test_penalty_ratio_is_penalty_times_element_length_over_axial_stiffness_per_length():
    m = _pressed(penalty=3e9)
    (r,) = penalty_ratios(m, Problem.from_model(m).system)
    EA = E * np.pi * R**2
    assert r.default == pytest.approx(E, rel=1e-12)                # the default: the softer section's E
    assert r.rho == pytest.approx(3e9 * 0.3**2 / EA, rel=1e-12)     # the slave's longer elements
    assert r.beam.name == "slave" and r.penalty == 3e9 and r.index == 0
    (d,) = penalty_ratios(_pressed(), Problem.from_model(_pressed()).system)
    assert d.penalty == d.default and d.rho == pytest.approx(0.3**2 / (np.pi * R**2), rel=1e-12)


def test_default_penalty_solves_without_a_conditioning_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error", bs.ConditioningWarning)
        sol = bs.solve(_pressed(), steps=2)
    assert sol.converged


def test_an_ill_conditioning_penalty_is_warned_once_naming_it():
    """``rho`` just above ``ILL_CONDITIONED_PENALTY`` (penalty 1e12 = 1e5 x its default): one
    warning at solve, naming the declaration, the penalty and the ratio; the solve still converges."""
    penalty = 1e12
    assert penalty * 0.3**2 / (E * np.pi * R**2) > ILL_CONDITIONED_PENALTY
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = bs.solve(_pressed(penalty), steps=2)
    ours = [w for w in caught if issubclass(w.category, bs.ConditioningWarning)]
    assert len(ours) == 1 and sol.converged
    text = str(ours[0].message)
    assert "add_contact no. 0" in text and "penalty 1e+12" in text and "1.15e+06" in text and "'slave'" in text


def test_a_failed_solve_names_the_penalty_not_large_rotations():
    with pytest.warns(bs.ConditioningWarning):
        with pytest.raises(bs.ConvergenceError) as err:
            bs.solve(_pressed(1e18), steps=2, min_step_ratio=0.25, max_iter=10)
    msg = str(err.value)
    assert "add_contact no. 0 has penalty 1e+18 (1e+11 times its default 1e+07)" in msg
    assert "1.15e+12" in msg and "ill-conditioned" in msg and "lower it" in msg
    assert "large rotations" not in msg


@pytest.mark.slow
def test_no_equilibrium_at_t_start_names_the_penalty():
    """The 20 mm twisted pair (4 elements) with penalty 1e18 (5e6 x its default) finds no first state."""
    m = twisted_pair.build(turns=0.25, n_elements=4)[0]
    m.contacts[0].penalty = 1e18
    with pytest.warns(bs.ConditioningWarning):
        with pytest.raises(bs.ConvergenceError, match=r"no equilibrium at t_start = 0.*add_contact no\. 0 has "
                                                      r"penalty 1e\+18 \(5e\+06 times its default 2e\+11\)"):
            bs.solve(m, steps=2)


def test_a_stiff_but_well_conditioned_penalty_is_named_when_the_solve_fails():
    """``STIFF_PENALTY`` times the default with ``rho`` below the warning: no warning, but a failed
    solve names the penalty (and says nothing of ill-conditioning)."""
    penalty = STIFF_PENALTY * E
    assert penalty * 0.3**2 / (E * np.pi * R**2) < ILL_CONDITIONED_PENALTY
    with warnings.catch_warnings():
        warnings.simplefilter("error", bs.ConditioningWarning)
        with pytest.raises(bs.ConvergenceError) as err:
            bs.solve(_pressed(penalty), steps=1, max_iter=1, min_step_ratio=0.5)
    msg = str(err.value)
    assert "add_contact no. 0 has penalty 1e+09 (100 times its default 1e+07)" in msg
    assert "ill-conditioned" not in msg and "jump with penetrations" in msg


def test_a_non_finite_failure_also_names_the_penalty():
    """The 1e18 report of the issue was "line search found no finite residual": whatever the
    failure, the error names a stiff penalty (here the failure is raised by the callback)."""
    from beamsolver.failures import NonFinite

    def callback(info):
        if info["t"] > 0.0:
            raise NonFinite("line search found no finite residual along the Newton direction")
    with pytest.warns(bs.ConditioningWarning):
        with pytest.raises(bs.ConvergenceError, match=r"no finite residual.*add_contact no\. 0 has penalty 1e\+18"):
            bs.solve(_pressed(1e18), steps=1, min_step_ratio=0.5, callback=callback)
