"""Contact switched in pseudo-time (add_contact(..., active_from=, friction_from=)): a pretension
applied frictionless, then friction from zero traction, equals the two-model workaround."""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver import cables
from beamsolver.contact import OPEN, SLIP, STICK

E = 200e9
EPS, TWIST = 2e-4, 0.02          # axial strain of the pull (t in [0, 1]), plate twist [rad] (t in [1, 2])


def _strand(mu, **switch):
    beta = np.deg2rad(12.0)
    L = 0.5 * 2 * np.pi * 2.0e-3 / np.tan(beta)
    st = cables.build_strand([cables.Layer(1.0e-3, 1), cables.Layer(1.0e-3, 6, lay_angle=beta)], L, E,
                             elements_per_lay=16, mu=mu, contact=False)
    st.model.add_contact(st.wires[1], st.wires[0], mu=mu, **switch)
    st.clamp("bottom")
    plate = st.plate("top")

    def motion(t):
        G = bs.motion.rotation((0, 0, 1), lambda s: TWIST * max(s - 1.0, 0.0), (0, 0, L))(t)
        G[2, 3] += EPS * L * min(t, 1.0)
        return G
    st.model.prescribe(plate, motion)
    return st.model, st, plate


def test_friction_from_equals_frictionless_solve_then_frictional_restart():
    model, st, plate = _strand(0.3, friction_from=1.0)
    one = bs.solve(model, steps=4, t_end=2.0)
    assert one.converged
    k1 = int(np.argmin(np.abs(one.times - 1.0)))
    assert one.times[k1] == pytest.approx(1.0)
    c1 = one.contacts[k1]
    closed = c1["normal_force"] > 0
    assert closed.sum() > 20
    assert np.all(c1["tangential_force"] == 0.0)                      # frictionless up to t = 1
    assert set(np.unique(c1["status"][closed])) == {SLIP}
    assert np.all(c1["status"][~closed] == OPEN)
    after = one.contacts[k1 + 1]
    assert np.any(after["status"] == STICK) and np.abs(after["tangential_force"]).max() > 0

    m0, _, _ = _strand(0.0)
    pre = bs.solve(m0, steps=2, t_end=1.0)
    np.testing.assert_allclose(pre.poses[-1], one.poses[k1], rtol=0, atol=1e-12)
    m1, _, p1 = _strand(0.3)
    rest = bs.solve(m1, steps=2, t_start=1.0, t_end=2.0, initial_poses=pre.poses[-1])
    assert rest.converged
    scale = np.abs(one.reaction(plate)).max()
    np.testing.assert_allclose(rest.reaction(p1), one.reaction(plate), rtol=0, atol=1e-7 * scale)
    np.testing.assert_allclose(rest.poses[-1][:, :3, 3], one.poses[-1][:, :3, 3], rtol=0, atol=1e-12)
    ft = np.linalg.norm(one.contacts[-1]["tangential_force"], axis=1)
    np.testing.assert_allclose(np.sort(np.linalg.norm(rest.contacts[-1]["tangential_force"], axis=1)),
                               np.sort(ft), rtol=0, atol=1e-6 * ft.max())


def test_friction_on_from_the_start_differs():
    """The same history with friction during the pull: the wires stick while stretched, so the
    twist meets a different state (the switch is not a no-op)."""
    on = bs.solve(_strand(0.3)[0], steps=4, t_end=2.0)
    model, st, plate = _strand(0.3, friction_from=1.0)
    off = bs.solve(model, steps=4, t_end=2.0)
    k1 = int(np.argmin(np.abs(on.times - 1.0)))
    assert np.abs(on.contacts[k1]["tangential_force"]).max() > 0
    assert not np.allclose(on.reaction(plate), off.reaction(plate), rtol=1e-6, atol=0)


def test_active_from_switches_the_whole_declaration():
    model, st, plate = _strand(0.0, active_from=1.0)
    sol = bs.solve(model, steps=4, t_end=2.0, check_rigid_modes=False)
    k1 = int(np.argmin(np.abs(sol.times - 1.0)))
    assert all(len(c.get("gap", ())) == 0 for c in sol.contacts[:k1 + 1])
    assert (sol.contacts[-1]["normal_force"] > 0).sum() > 20


def test_switch_times_are_checked():
    model, st, plate = _strand(0.0)
    with pytest.raises(bs.InputError, match="friction_from"):
        model.add_contact(st.wires[1][0], st.wires[0][0], mu=0.2, friction_from=np.nan)
