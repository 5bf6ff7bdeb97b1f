"""Contact scenes with reference answers: crossing, capstan, rolling; choice rule; results."""

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.nonlinear.problem import Problem
from beamsolver.contact.frames import LINE, ORTHOGONAL, POINT

import capstan
import crossing_beams
import rolling


def _rates(residuals, floor=1e-10):
    """``log r_{k+1} / log r_k`` over the converging tail (``r_k < 1e-2``, ``r_{k+1}`` above round-off)."""
    r = np.asarray(residuals)
    return [np.log(b) / np.log(a) for a, b in zip(r[:-1], r[1:]) if a < 1e-2 and b > floor and b < a]


# ------------------------------------------------------------------ crossing
@pytest.fixture(scope="module")
def crossing():
    return {tol: crossing_beams.main(load=50.0, n_elements=8, tolerance=tol) for tol in (None, 1e-6)}


def test_crossing_contact_force_equals_load(crossing):
    for tol, (force, pen, sol) in crossing.items():
        c = sol.contact()
        assert len(c["gap"]) == 1 and c["kind"][0] == POINT
        np.testing.assert_allclose(force, 50.0, rtol=1e-6)
        fz = np.sum(c["normal_force"] * c["normal"][:, 2])
        np.testing.assert_allclose(fz, -50.0, rtol=1e-9)


def test_crossing_penetration_below_tolerance_only_with_augmented_lagrangian(crossing):
    pen_penalty, pen_al = crossing[None][1], crossing[1e-6][1]
    assert pen_al < 1e-6
    assert pen_penalty > 1e-6          # 50 N / (E L_e) = 2e-5 m with the default penalty
    np.testing.assert_allclose(pen_penalty, 50.0 / (1e7 * 0.25), rtol=1e-3)
    assert all(s.get("augmentations", 0) >= 1 for s in crossing[1e-6][2].stats[1:])


def test_newton_is_quadratic_frictionless(crossing):
    """``r_{k+1} <= 50 r_k^2`` on the converging tail (the suite's quadratic criterion; a linear
    rate fails it once ``r_k < 1e-2``)."""
    sol = crossing[None][2]
    pairs = [(a, b) for s in sol.stats[1:] for a, b in zip(s["residuals"][:-1], s["residuals"][1:])
             if a < 1e-2 and b > 1e-13]
    assert len(pairs) >= 2 and all(b <= 50.0 * a * a for a, b in pairs), pairs


# ------------------------------------------------------------------ rolling
@pytest.fixture(scope="module")
def rolled():
    return {mu: rolling.main(mu=mu, theta=1.0, steps=11) for mu in (0.5, 0.0)}


def test_rolling_distance_is_R_theta(rolled):
    d, exact, ft, sol = rolled[0.5]
    # the SE(3) slip of rolling is R dtheta^3 / 12 per step: the distance error
    # is theta R dtheta^2 / 12 (dtheta = 0.1); a centre-line slip would stop the rolling
    expected_error = exact * 0.1**2 / 12.0
    assert abs(d - exact) < 1.25 * expected_error, (d, exact)
    normal = max(sol.contact(k)["normal_force"].max() for k in range(1, len(sol.times)))
    assert ft < 1e-4 * normal
    assert all(sol.contact(k)["stick"].all() for k in range(2, len(sol.times)))


def test_rolling_frictionless_turns_in_place(rolled):
    d, exact, ft, sol = rolled[0.0]
    assert abs(d) < 1e-9 * exact and ft == 0.0
    mid = sol.rotation(rolling.build()[1].nodes[3])
    assert np.isclose(np.arctan2(mid[2, 1], mid[1, 1]), 1.0, atol=1e-6)   # it turned by theta


def test_newton_is_quadratic_with_friction(rolled):
    sol = rolled[0.5][3]
    rates = [q for s in sol.stats[2:] for q in _rates(s["residuals"])]
    assert len(rates) >= 5 and min(rates) > 1.8, rates
    assert max(sol.iterations[2:]) <= 5


# ------------------------------------------------------------------ capstan
@pytest.mark.parametrize("mu", [0.1, 0.3])
@pytest.mark.parametrize("theta", [0.5 * np.pi, np.pi])
def test_capstan_ratio(mu, theta):
    ratio, exact, sol = capstan.main(mu=mu, theta=theta)
    assert abs(ratio / exact - 1.0) < 0.02, (ratio, exact)
    c = sol.contact()
    assert set(c["kind"].tolist()) == {ORTHOGONAL}
    on = c["normal_force"] > 0
    assert not c["stick"][on].any()                 # the whole wrap slides


# ------------------------------------------------------------------ choice rule
def _pair_kinds(angle_deg, wrap=False, **options):
    m = bs.Model()
    sec = bs.Section.circular(radius=0.05, E=1e7)
    master = m.add_beam(bs.geometry.straight((-1, 0, 0), (1, 0, 0), 3), sec)
    if wrap:   # an arc winding around the master axis (e_x) at the distance of the radii
        phi = np.linspace(-0.8, 0.8, 5)
        x = np.stack([0.1 + 1e-3 * phi, 0.1 * np.cos(phi), 0.1 * np.sin(phi)], axis=1)
        t = np.stack([1e-3 + 0 * phi, -np.sin(phi), np.cos(phi)], axis=1)
        P = bs.geometry.frames_from_tangents(x, t)
    else:
        a = np.deg2rad(angle_deg)
        d = np.array([np.cos(a), np.sin(a), 0.0])
        P = bs.geometry.straight(0.1 * np.array([0, 0, 1.0]) - 0.7 * d + [0.1, 0, 0],
                                 0.1 * np.array([0, 0, 1.0]) + 0.7 * d + [0.1, 0, 0], 3)
    slave = m.add_beam(P, sec)
    m.add_contact(slave, master, **options)
    problem = Problem.from_model(m, check_rigid_modes=False)
    P = problem.contact.pairs(problem.system.poses0)
    return set(P.kind.tolist())


def test_choice_rule_line_angle():
    assert _pair_kinds(19.0) == {LINE}
    assert LINE not in _pair_kinds(21.0)
    assert _pair_kinds(29.0, line_angle=np.deg2rad(30.0)) == {LINE}
    assert LINE not in _pair_kinds(31.0, line_angle=np.deg2rad(30.0))


def test_choice_rule_point_ratio():
    # straight beams: reduced-Hessian ratio = sin^2(angle); default 0.5 <-> 45 degrees
    assert _pair_kinds(44.0) == {ORTHOGONAL}
    assert _pair_kinds(46.0) == {POINT}
    assert _pair_kinds(59.0, point_ratio=np.sin(np.deg2rad(60.0)) ** 2) == {ORTHOGONAL}
    assert _pair_kinds(61.0, point_ratio=np.sin(np.deg2rad(60.0)) ** 2) == {POINT}
    assert _pair_kinds(90.0) == {POINT}


def test_choice_rule_wrapping_is_orthogonal():
    assert _pair_kinds(None, wrap=True) == {ORTHOGONAL}


# ------------------------------------------------------------------ results, several declarations
def test_contact_results_keys_and_per_declaration_mu():
    m = bs.Model()
    sec = bs.Section.circular(radius=0.05, E=1e7)
    master = m.add_beam(bs.geometry.straight((0, -1, 0), (0, 1, 0), 5), sec)
    m.clamp(master.first)
    m.clamp(master.last)
    slaves = []
    for y, mu in ((-0.5, 0.1), (0.5, 0.4)):
        s = m.add_beam(bs.geometry.straight((-0.5, y, 0.1), (0.5, y, 0.1), 5), sec)
        # pressed down (t <= 0.5), then dragged along the master by 2 mm
        motion = bs.motion.translation(lambda t: (0.0, 2e-3 * max(2 * t - 1, 0.0), -2e-5 * min(2 * t, 1.0)))
        m.prescribe(s.first, motion)
        m.prescribe(s.last, motion)
        m.add_contact(s, master, mu=mu)
        slaves.append(s)
    sol = bs.solve(m, steps=4)
    c = sol.contact()
    for key, shape in (("position", (3,)), ("gap", ()), ("normal_force", ()), ("tangential_force", (3,)),
                       ("stick", ()), ("slip_increment", (2,)), ("kind", ()), ("angle", ())):
        assert key in c and c[key].shape == (len(c["gap"]),) + shape, key
    assert len(c["gap"]) == 2 and np.all(c["kind"] == POINT)
    np.testing.assert_allclose(c["angle"], 90.0)
    ft = np.linalg.norm(c["tangential_force"], axis=1)
    order = np.argsort(c["position"][:, 1])
    np.testing.assert_allclose(ft[order] / c["normal_force"][order], [0.1, 0.4], rtol=1e-8)
    assert not c["stick"].any()
    # the slip increment of the last step: the drag of 1 mm along the master
    np.testing.assert_allclose(np.linalg.norm(c["slip_increment"], axis=1), 1e-3, rtol=1e-3)
    np.testing.assert_allclose(c["position"][order, 1], [-0.5 + 2e-3, 0.5 + 2e-3], atol=1e-5)  # beams bend
    with pytest.raises(bs.InputError):
        m.add_contact(master, master)


# ------------------------------------------------------------------ examples at reduced size
def test_examples_run_at_reduced_size():
    ratio, exact, _ = capstan.main(mu=0.3, theta=0.5 * np.pi, n_arc=8, steps=6)
    assert abs(ratio / exact - 1.0) < 0.05, (ratio, exact)
    d, exact, ft, _ = rolling.main(mu=0.5, theta=0.5, steps=6, n_elements=3)
    assert abs(d / exact - 1.0) < 0.01
    force, pen, _ = crossing_beams.main(load=10.0, n_elements=4, tolerance=1e-7)
    assert abs(force - 10.0) < 1e-5 and pen < 1e-7
    for mod in (capstan, rolling, crossing_beams):
        assert callable(mod.main) and callable(mod.build)


def test_point_pair_keeps_its_friction_history_across_master_elements():
    """Rolling under a steady tangential load (below mu N): the crossing moves onto the next
    master element and keeps its stored traction (no reset, no cut-back, no jump)."""
    model, slave, master = rolling.build(mu=0.5, theta=5.0)
    for node in (slave.first, slave.last):
        model.add_load(node, force=(0.0, 1.0, 0.0), scale=lambda t: min(t / 0.1, 1.0))
    sol = bs.solve(model, steps=41)
    steps = range(1, len(sol.times))
    elements = [int(sol.contact(k)["master_element"][0]) for k in steps]
    assert len(set(elements)) == 2                              # it crossed an element boundary
    assert all(s["cutbacks"] == 0 for s in sol.stats[1:])
    assert all(sol.contact(k)["stick"].all() for k in steps)
    ft = np.array([sol.contact(k)["tangential_force"][0, 1] for k in steps])
    after = ft[np.array(sol.times[1:]) > 0.1 + 1e-9]
    np.testing.assert_allclose(after, -2.0, rtol=2e-3)
