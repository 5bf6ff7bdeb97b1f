"""Default tangential penalty: sliding starts at an elastic slip of ``slip_tolerance`` slave
element lengths (Abaqus' default penalty friction), whatever the normal force."""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver.nonlinear.problem import Problem
from beamsolver import se3
from beamsolver.contact.law import PENALTY_T_MIN
from beamsolver.errors import InputError

R = 0.05
SEC = bs.Section.circular(radius=R, E=1e7, nu=0.3)
MU = 0.4


def _crossing(depth, **options):
    """Crossing beams pressed together by the reference overlap ``depth`` (kept: ``adjust=0``)."""
    options.setdefault("adjust", 0.0)
    m = bs.Model()
    master = m.add_beam(bs.geometry.straight((0, -1, 0), (0, 1, 0), 5), SEC)
    slave = m.add_beam(bs.geometry.straight((-1, 0, 2 * R - depth), (1, 0, 2 * R - depth), 5), SEC)
    m.clamp(master.first)
    m.clamp(slave.first)
    m.add_contact(slave, master, mu=MU, **options)
    problem = Problem.from_model(m, check_rigid_modes=False)
    H = problem.system.poses0.copy()
    problem.contact.commit(H)                 # friction history at the start
    return problem, H, slave


def _slide(problem, H, slave, s):
    G = se3.exp(np.array([s, 0, 0, 0, 0, 0.0]))
    H = H.copy()
    H[slave.nodes] = se3.compose(np.broadcast_to(G, (len(slave.nodes), 4, 4)), H[slave.nodes])
    problem.contact.commit(H)
    return problem.contact.results(H)


@pytest.mark.parametrize("depth,fraction", [(1e-2 * R, f) for f in (0.25, 0.5, 0.9, 0.99, 1.01, 1.5, 4.0)]
                         + [(1e-4 * R, f) for f in (0.25, 0.9, 0.99, 1.01, 4.0)])
def test_sliding_starts_at_the_elastic_slip(depth, fraction):
    """Above the floor's traction ``lam_min = PENALTY_T_MIN penalty es`` (here 20 N/m, the
    traction of a 4e-5 R penetration) sliding starts at the elastic slip ``es`` exactly."""
    problem, H, slave = _crossing(depth)
    es = 0.005 * 0.4                         # slip tolerance x slave element length
    res = _slide(problem, H, slave, fraction * es)
    on = res["normal_force"] > 0
    assert on.sum() == 1
    lam_n = res["normal_force"][on] / res["weight"][on]
    assert lam_n > PENALTY_T_MIN * 1e7 * es
    ratio = np.linalg.norm(res["tangential_force"][on]) / (MU * res["normal_force"][on])
    if fraction < 1:
        assert res["stick"][on].all()
        assert ratio == pytest.approx(fraction, rel=1e-6)         # |lam_T| = mu lam_N s / es
    else:
        assert not res["stick"][on].any()
        assert ratio == pytest.approx(1.0, rel=1e-12)


def test_measured_stick_slope_is_mu_normal_force_over_the_elastic_slip():
    """d|F_T|/ds of a sticking point = mu N / (slip_tolerance L_e), N the point's normal force."""
    problem, H, slave = _crossing(1e-3 * R)
    es = 0.005 * 0.4
    s1, s2 = 0.1 * es, 0.3 * es
    f1, f2 = (_slide(problem, H, slave, s) for s in (s1, s2))
    on = f1["normal_force"] > 0
    slope = (np.linalg.norm(f2["tangential_force"][on]) - np.linalg.norm(f1["tangential_force"][on])) / (s2 - s1)
    np.testing.assert_allclose(slope, MU * f1["normal_force"][on] / es, rtol=1e-3)


def test_below_the_floor_the_stiffness_is_held():
    """A just-touching point (lam_N < lam_min) keeps the stiffness ``mu lam_min / es`` and
    slides at the smaller slip ``es lam_N / lam_min`` (documented in stick_penalty)."""
    problem, H, slave = _crossing(1e-6 * R)
    es = 0.005 * 0.4
    s = 0.01 * es
    res = _slide(problem, H, slave, s)
    on = res["normal_force"] > 0
    lam_n = res["normal_force"][on] / res["weight"][on]
    lam_min = PENALTY_T_MIN * 1e7 * es
    assert lam_n < lam_min and res["stick"][on].all()
    lam_t = np.linalg.norm(res["tangential_force"][on]) / res["weight"][on]
    np.testing.assert_allclose(lam_t, MU * lam_min / es * s, rtol=1e-6)


def test_explicit_penalty_t_overrides_the_slip_tolerance():
    problem, H, slave = _crossing(1e-2 * R, penalty_t=1e3)
    s = 1e-5
    res = _slide(problem, H, slave, s)
    on = res["normal_force"] > 0
    w = res["weight"][on]
    assert res["stick"][on].all()
    np.testing.assert_allclose(np.linalg.norm(res["tangential_force"][on], axis=1), 1e3 * s * w, rtol=1e-6)


@pytest.mark.parametrize("bad", [0.0, -1.0, np.nan])
def test_bad_slip_tolerance_is_refused(bad):
    with pytest.raises(InputError, match="slip_tolerance"):
        _crossing(1e-2 * R, slip_tolerance=bad)
