"""Contact patch test (issue 26): two parallel straight beams on non-matching meshes pressed by a
uniform line load (``examples/contact_patch.py``).  Closed form: uniform pressure ``q``, straight
beams; with an axial traction ``tau < mu q``: stick everywhere, uniform traction ``tau``, no slip.

``integration="segments"`` (``projection.segment_bounds``) integrates the products of slave and
master shape functions exactly on straight beams: the test passes to round-off (measured: pressure
spread 3e-11 .. 5e-10 q, traction spread 4e-10 .. 7e-9 tau, slip 1e-16 m).  The Gauss points of
``integration="points"`` do not (pressure spread 0.12 q on 7 / 10 elements)."""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver.contact.options import SEGMENT_POINTS
from beamsolver.contact.projection import element_twists, segment_bounds
from beamsolver.nonlinear.problem import Problem

import contact_patch as cp

Q, TAU = 100.0, 15.0


def _solve(n_slave, n_master, steps=4, t_end=1.0, tau=TAU, **kw):
    model, slave, master = cp.build(n_slave=n_slave, n_master=n_master, q=Q, tau=tau, **kw)
    sol = bs.solve(model, steps=steps, t_end=t_end, check_rigid_modes=False)
    return sol, slave, master


@pytest.mark.parametrize("n_slave, n_master", [(7, 10), (10, 7)])
def test_frictionless_pressure_is_uniform_to_round_off_with_segments(n_slave, n_master):
    sol, slave, master = _solve(n_slave, n_master, steps=2, t_end=0.5, mu=0.0, tau=0.0, integration="segments")
    p, _, _ = cp.tractions(sol)
    assert len(p) == SEGMENT_POINTS * (n_slave + n_master - 1)     # one segment per (slave, master) overlap
    assert abs(p.mean() - Q) <= 1e-9 * Q
    assert np.ptp(p) <= 1e-8 * Q
    for beam in (slave, master):
        assert cp.straightness(sol, beam) <= 1e-13           # penetration ~1e-7 m: straight beams


def test_point_integration_fails_the_patch_test():
    """The same scene with the Gauss points fixed per slave element: the master's kinks inside the
    slave elements are integrated inexactly (this is what segments repair)."""
    sol, slave, master = _solve(7, 10, steps=2, t_end=0.5, mu=0.0, tau=0.0, integration="points")
    p, _, _ = cp.tractions(sol)
    assert np.ptp(p) > 0.05 * Q
    assert cp.straightness(sol, master) > 1e-9


@pytest.mark.parametrize("n_slave, n_master", [(7, 10), (10, 7)])
def test_exact_stick_holds_a_uniform_traction_without_slip(n_slave, n_master):
    sol, slave, master = _solve(n_slave, n_master, integration="segments", stick="exact")
    p, t, stick = cp.tractions(sol)
    assert stick.all()
    assert abs(-t.mean() - TAU) <= 1e-8 * TAU               # on the slave: against the pull
    assert np.ptp(t) <= 1e-7 * TAU
    assert np.ptp(p) <= 1e-8 * Q
    assert cp.relative_slip(sol, slave, master) <= 1e-14
    for beam in (slave, master):
        assert cp.straightness(sol, beam) <= 1e-13


def test_penalty_stick_slips_elastically_by_the_same_amount_everywhere():
    sol, slave, master = _solve(7, 10, integration="segments", stick="penalty")
    _, t, stick = cp.tractions(sol)
    assert stick.all()
    assert abs(-t.mean() - TAU) <= 1e-3 * TAU
    assert np.ptp(t) <= 0.01 * TAU
    xs = sol.displacement(-1)[slave.nodes, 0]
    xm = np.interp(np.linspace(0, 1, len(slave.nodes)), np.linspace(0, 1, len(master.nodes)),
                   sol.displacement(-1)[master.nodes, 0])
    slip = xs - xm
    assert slip.mean() > 1e-5                                # the penalty's elastic slip
    assert np.ptp(slip) <= 1e-3 * slip.mean()                # uniform (measured 3.6e-4)


def _helix(n, turns=0.3, radius=0.01, length=1.0, z0=0.0):
    t = np.linspace(0.0, 1.0, n + 1)
    return np.stack([length * t, radius * np.cos(2 * np.pi * turns * t), radius * np.sin(2 * np.pi * turns * t) + z0],
                    axis=1)


def _model_of(points_a, points_b, r=0.005):
    model = bs.Model()
    sec = bs.Section.circular(radius=r, E=1e9, nu=0.3)
    a = model.add_beam(bs.geometry.polyline(points_a), sec)
    b = model.add_beam(bs.geometry.polyline(points_b), sec)
    return Problem.from_model(model, check_rigid_modes=False).system, a, b


def test_segment_bounds_on_straight_beams_are_the_master_nodes():
    system, slave, master = _model_of(np.linspace((0, 0, 0.02), (1, 0, 0.02), 8),
                                      np.linspace((0, 0, 0), (1, 0, 0), 11))
    H, en = system.poses0, system.enodes
    h = element_twists(H, en)
    e, m = np.meshgrid(slave.elements, master.elements, indexing="ij")
    e, m = e.ravel(), m.ravel()
    lo, hi = segment_bounds(H, en, h, e, m, np.ones(len(e), dtype=bool))
    j, k = e - slave.elements[0], m - master.elements[0]
    want_lo = np.clip(k / 10 * 7 - j, 0, 1)
    want_hi = np.clip((k + 1) / 10 * 7 - j, 0, 1)
    assert np.abs(lo - want_lo).max() <= 1e-13 and np.abs(hi - want_hi).max() <= 1e-13
    assert abs(np.sum(hi - lo) - 7.0) <= 1e-12                # the slave covered once


def test_segment_ends_next_to_a_slave_node_snap_to_it(monkeypatch):
    """A master node within ``SEGMENT_SNAP`` of a slave node (equal meshes: the twisted pair's) gives no sliver
    segment: the bound is the slave node itself, the neighbour's segment covers the element, the slave is still
    covered once; without the snap the sliver is there."""
    from beamsolver.contact import projection
    xm = np.linspace(0.0, 1.0, 11)
    xm[3] = 2.0 / 7.0 + 3e-5 / 7.0          # a master node 3e-5 element lengths inside slave element 2
    system, slave, master = _model_of(np.linspace((0, 0, 0.02), (1, 0, 0.02), 8),
                                      np.stack([xm, 0 * xm, 0 * xm], axis=1))
    H, en = system.poses0, system.enodes
    h = element_twists(H, en)
    e, m = np.meshgrid(slave.elements, master.elements, indexing="ij")
    e, m = e.ravel(), m.ravel()
    for snap, slivers in ((0.0, 1), (projection.SEGMENT_SNAP, 0)):
        monkeypatch.setattr(projection, "SEGMENT_SNAP", snap)
        lo, hi = segment_bounds(H, en, h, e, m, np.ones(len(e), dtype=bool))
        on = hi > lo
        assert int(np.sum(on & (hi - lo < 1e-4))) == slivers
        assert abs(np.sum(hi - lo) - 7.0) <= 1e-12
        j = (e - slave.elements[0] == 2) & on            # element 2 also holds master node 4 (at 0.8)
        assert j.sum() == 2 + slivers and lo[j].min() == 0.0 and hi[j].max() == 1.0


def test_segments_tile_a_curved_slave_element():
    """On helices (curved, twisted elements) the segments of one slave element against consecutive
    master elements meet (the plane through their shared node) and cover it once."""
    system, slave, master = _model_of(_helix(6, z0=0.0), _helix(9, radius=0.0105, z0=0.0))
    H, en = system.poses0, system.enodes
    h = element_twists(H, en)
    for j in slave.elements[1:-1]:
        m = master.elements
        lo, hi = segment_bounds(H, en, h, np.full(len(m), j), m, np.ones(len(m), dtype=bool))
        on = hi > lo
        assert on.sum() >= 2
        assert np.abs(lo[on][1:] - hi[on][:-1]).max() <= 1e-12
        assert abs(lo[on][0]) <= 1e-15 and abs(hi[on][-1] - 1.0) <= 1e-15


def test_integration_option_is_checked():
    model = bs.Model()
    sec = bs.Section.circular(radius=0.01, E=1e9, nu=0.3)
    a = model.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 2), sec)
    b = model.add_beam(bs.geometry.straight((0, 0, 0.02), (1, 0, 0.02), 2), sec)
    with pytest.raises(bs.InputError, match="integration"):
        model.add_contact(a, b, integration="mortar")


class _Stop(Exception):
    pass


def test_segment_keys_restart_exactly():
    """The friction history of segment points (keys with the segment's slot) is checked and given back by
    a restart: the restarted run ends as the uninterrupted one (shear lag, 20 wire / 13 rod elements)."""
    import shear_lag

    def stop(info):
        if info["t"] > 0.6:
            raise _Stop

    model, wire, _ = shear_lag.build(integration="segments")
    full = bs.solve(model, steps=4, verbose=False)
    model, _, _ = shear_lag.build(integration="segments")
    with pytest.raises(_Stop) as e:
        bs.solve(model, steps=4, callback=stop, verbose=False)
    part = e.value.solution
    assert len(part.contact_state["contact/history.key"]) > 0
    model, _, _ = shear_lag.build(integration="segments")
    rest = bs.solve(model, steps=4, restart=part, verbose=False)
    np.testing.assert_array_equal(rest.contact()["tangential_force"], full.contact()["tangential_force"])
    assert not full.contact()["stick"].all()          # the pull slides part of the wire: the history matters


def test_a_wrap_end_keeps_whole_element_points():
    """A slave element meeting the same master beam in an orthogonal pair too is not segmented (its
    points keep one owner each: nothing counted twice); line pairs elsewhere are, each with its slot."""
    from beamsolver.contact.frames import LINE, ORTHOGONAL
    model = bs.Model()
    sec = bs.Section.circular(radius=0.01, E=1e9, nu=0.3)
    a = model.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), sec)
    b = model.add_beam(bs.geometry.straight((0, 0, 0.02), (1, 0, 0.02), 3), sec)
    model.add_contact(b, a, integration="segments")
    cs = Problem.from_model(model, check_rigid_modes=False).contact
    e = np.array([4, 4, 5, 5, 6])
    m = np.array([0, 1, 1, 2, 3])
    seg, slot = cs._segments(e, m, np.array([LINE, ORTHOGONAL, LINE, LINE, LINE]))
    assert seg.tolist() == [False, False, True, True, True]
    assert slot.tolist() == [cs.n_slots, cs.n_slots, 1 % cs.n_slots, 2 % cs.n_slots, 3 % cs.n_slots]
    assert cs.n_slots >= 3                   # masters one slave element can overlap (1/3 over 1/4, stretch 2)


def _tilted_segments(mu):
    """``test_contact_tangent``'s line scene (a tilted slave partly touching, 4 / 4 elements, offset) with
    segments."""
    import test_contact_tangent as tc
    m = bs.Model()
    master = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), tc.SEC)
    slave = m.add_beam(bs.geometry.straight((0.1, -0.02, 2 * tc.R), (0.9, 0.03, 2 * tc.R + 0.01), 4), tc.SEC)
    m.clamp(master.first)
    m.clamp(master.last)
    m.clamp(slave.first)
    m.add_contact(slave, master, mu=mu, integration="segments")
    return m, slave, master, np.array([1.0, 0.0, 0.0])


@pytest.mark.parametrize("regime", ["open", "frictionless", "stick", "slip", "stick_new"])
def test_segment_tangent_matches_finite_differences(regime, monkeypatch):
    """The tangent with the moving segment ends' terms (``segment_tangent``) against central differences
    of the residual (measured 4e-10 .. 5e-9; without the terms 1.4e-3)."""
    import test_contact_tangent as tc
    from beamsolver.contact.frames import LINE
    monkeypatch.setitem(tc.SCENES, "line", (_tilted_segments, LINE))
    problem, H, kind = tc._state("line", regime)
    P = problem.contact.pairs(H)
    assert set(P.kind.tolist()) == {kind}
    span = P.weight / (problem.contact.decls[0].seg_gauss[1][P.gp] * problem.system.L[P.e])
    moving = (P.xi1 - span * problem.contact.decls[0].seg_gauss[0][P.gp] > 1e-9) | \
        (P.xi1 + span * (1 - problem.contact.decls[0].seg_gauss[0][P.gp]) < 1 - 1e-9)
    assert moving.any()                                  # segments that end at a master node
    err, _ = tc._fd_error(problem, H)
    assert err < 1e-6, err
