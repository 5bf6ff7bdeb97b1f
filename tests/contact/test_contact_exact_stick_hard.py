"""Exact stick on the hard scenes (issue 26, exact stick as the default; docs/theory_mortar.md section 3d).

The extreme twisted pair (``examples/twisted_pair_extreme.py``, reduced: 16 elements, half a turn in four steps):
with one ``c`` for every group the nearly sticking groups' slip direction reversed between Newton iterates, the
line search crawled and the steps were cut back (229 iterations, 5 cut-backs before ``contact.system.SLIP_C``).
"""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver.contact import system

import twisted_pair_extreme


def _extreme(monkeypatch, slip_c=True):
    monkeypatch.setattr(system, "SLIP_C", slip_c)
    model, plate, _ = twisted_pair_extreme.build(n_elements=16, turns=0.5, stick="exact")
    return bs.solve(model, steps=4, verbose=False), plate


def test_extreme_pair_twists_without_cut_backs(monkeypatch):
    """Measured: 91 iterations, no cut-back (one c for all groups: 229 and 5)."""
    sol, _ = _extreme(monkeypatch)
    assert sum(s.get("cutbacks", 0) for s in sol.stats) == 0
    assert sum(s["iterations"] for s in sol.stats) <= 100
    assert sol.times[-1] == 1.0


@pytest.mark.slow
def test_slip_scaled_c_gives_the_same_torque(monkeypatch):
    """``c`` is not in the equations a solution meets: the torque at half a turn with and without the slip-scaled
    ``c`` (measured: 2e-7 apart, their step sequences differ by the cut-backs)."""
    a, plate = _extreme(monkeypatch)
    b, _ = _extreme(monkeypatch, slip_c=False)
    assert a.reaction(plate, -1)[5] == pytest.approx(b.reaction(plate, -1)[5], rel=1e-5)


def test_sliding_c_scales_each_group_by_its_slip_against_the_largest():
    """``ContactSystem._sliding_c``: ``clip(|u_g| / max |u|, SLIP_C_FLOOR, 1)`` per group, the largest over the
    sliding groups of the group's declaration; sticking groups included; None when no group slid."""
    cs = system.ContactSystem.__new__(system.ContactSystem)
    cs._decl_eps_t = np.array([1e10, 1e10])
    m = dict(key=np.array([7, 3, 5, 9]), decl=np.array([0, 0, 0, 1]), stick=np.array([False, False, True, True]),
             lam=np.array([[1.0, 0, 0], [2.0, 0, 0], [0.5, 0, 0], [1.0, 0, 0]]),
             u=np.array([[0, 4e-6, 0], [0, 1e-6, 0], [0, 0, 1e-15], [0, 1e-15, 0]]))
    keys, f = cs._sliding_c(m)
    assert keys.tolist() == [3, 5, 7, 9]
    assert f == pytest.approx([0.25, system.SLIP_C_FLOOR, 1.0, 1.0])
    m["stick"][:] = True
    assert cs._sliding_c(m) is None


class _Stop(Exception):
    pass


def test_restart_takes_the_same_steps_with_extrapolated_multipliers_and_scaled_c(monkeypatch):
    """The state a restart needs besides the history (``ContactSystem.get_state``): the last two steps'
    multipliers (``_extrapolate``) and the groups' ``c`` factors (``_balanced_c``).  The reduced extreme pair
    stopped after its second step and restarted ends on the uninterrupted run's poses, bit for bit."""
    monkeypatch.setattr(system, "SLIP_C", True)
    full, _ = _extreme(monkeypatch)

    def stop(info):
        if info["t"] > 0.6:
            raise _Stop

    model, _, _ = twisted_pair_extreme.build(n_elements=16, turns=0.5, stick="exact")
    with pytest.raises(_Stop) as e:
        bs.solve(model, steps=4, callback=stop, verbose=False)
    part = e.value.solution
    state = part.contact_state
    assert "contact/tmult_steps" in state and "contact/slide_c_keys" in state
    model, _, _ = twisted_pair_extreme.build(n_elements=16, turns=0.5, stick="exact")
    rest = bs.solve(model, steps=4, restart=part, verbose=False)
    np.testing.assert_array_equal(rest.times, full.times)
    np.testing.assert_array_equal(rest.poses[-1], full.poses[-1])


def _refined_pair(**options):
    """The main job at 128 elements per wire (7.8 mm elements), its first step (1/8 turn) alone."""
    import twisted_pair
    model, plate, _ = twisted_pair.build(n_elements=128, turns=1.0 / 8.0, mu=0.3, **options)
    return bs.solve(model, steps=1, verbose=False), plate


@pytest.mark.slow
def test_refined_twisted_pair_converges_with_the_default_c():
    """Issue 26: with ``c = 24 EI / L_e^4`` (6.3e7 N/m^2 at 128 elements, 4096 times the 16-element main job's) the
    first step stalled at a scaled residual 1.16e-6 at every step size down to 2.4e-4 of it (22 s of CPU, then
    ``ConvergenceError``): the nearly unloaded groups slid with ``c |u|`` far above their traction and Newton
    reversed their slip from one iterate to the next.  The default ``c`` (``EXACT_C EI / (L_e L_s^3)``, 1.2e5 here)
    converges without cut-back (measured: 36 iterations), to the torque of an explicit ``c`` of 3e5 N/m^2."""
    sol, plate = _refined_pair()
    ref, _ = _refined_pair(penalty_t=3e5)
    assert sol.times[-1] == 1.0
    assert sum(s.get("cutbacks", 0) for s in sol.stats) == 0
    assert sum(s["iterations"] for s in sol.stats) <= 45
    assert sol.reaction(plate, -1)[5] == pytest.approx(ref.reaction(plate, -1)[5], rel=1e-6)


def test_default_c_grows_like_one_over_the_element_length(monkeypatch):
    """``contact.system.exact_c``: ``EXACT_C EI / (L_e L_s^3)``, ``L_s = n L_e / EXACT_N``: ``24 EI / L_e^4`` to the bit
    at 16 elements (the iteration counts are not smooth in ``c``: 2e-16 of it moved the extreme pair from 202 to 299
    iterations), 8 times the 16-element value at 128 elements of the same beam (``24 EI / L_e^4``: 4096 times), and
    the rule before with ``EXACT_N = None``; a slave's ``n`` is the median element count of its beams."""
    EI = 9.8e-3
    L16, L128 = np.full(16, 1.0 / 16), np.full(128, 1.0 / 128)
    assert system.exact_c(EI, L16, 16) == 24.0 * EI / (1.0 / 16) ** 4
    assert system.exact_c(EI, L128, 128) == pytest.approx(8.0 * system.exact_c(EI, L16, 16), rel=1e-14)
    assert system.exact_c(EI, L128, 128) == pytest.approx(24.0 * EI / ((1.0 / 128) * (1.0 / 16) ** 3), rel=1e-14)
    monkeypatch.setattr(system, "EXACT_N", None)
    assert system.exact_c(EI, L128, 128) == 24.0 * EI / (1.0 / 128) ** 4
    assert system._slave_elements([np.arange(8), np.arange(8, 20), np.arange(20, 44)]) == 12
