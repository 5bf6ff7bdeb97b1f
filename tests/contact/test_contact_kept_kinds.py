"""The search leaves out the closest points of crossings whose kind the step keeps as orthogonal
(``system.KEPT_KINDS_SKIP``): ``history.step_kinds`` overwrites their kind and an orthogonal pair reads no
closest point, so the pairs are those of every crossing's closest points, bit for bit; where
``rules.extend_wrap`` could read the fresh kinds (a new point pair at a slave element's end), all are computed.
"""
import dataclasses

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.contact import system
from beamsolver.contact.frames import LINE, ORTHOGONAL, POINT
from beamsolver.nonlinear.problem import Problem


def _scene():
    """A straight master crossed by a slave at 30 degrees (orthogonal, ratio sin^2 < 1/2) and one at 70 (a
    point pair), both a little above it."""
    m = bs.Model()
    sec = bs.Section.circular(radius=0.05, E=1e7)
    master = m.add_beam(bs.geometry.straight((-1, 0, 0), (1, 0, 0), 6), sec)
    for angle, x in ((30.0, -0.4), (70.0, 0.45)):
        a = np.deg2rad(angle)
        d = np.array([np.cos(a), np.sin(a), 0.0])
        c = np.array([x, 0.0, 0.099])
        m.add_contact(m.add_beam(bs.geometry.straight(c - 0.6 * d, c + 0.6 * d, 4), sec), master)
    return m


def _moved(H, seed):
    H = H.copy()
    H[:, :3, 3] += 1e-3 * np.random.default_rng(seed).standard_normal((len(H), 3))
    return H


def _search(monkeypatch, skip, force_all=False):
    """The pairs of a step's evaluations at three poses, and the closest-point rows computed at each."""
    monkeypatch.setattr(system, "KEPT_KINDS_SKIP", skip)
    if force_all:
        monkeypatch.setattr(system.ContactSystem, "_wrap_may_change", staticmethod(lambda *a: True))
    rows = []
    real = system.closest_points

    def counted(H, A1, *a, **k):
        rows.append(len(A1))
        return real(H, A1, *a, **k)
    monkeypatch.setattr(system, "closest_points", counted)
    problem = Problem.from_model(_scene(), check_rigid_modes=False)
    contact = problem.contact
    H0 = problem.system.poses0.copy()
    contact.begin_step(H0, 0.1)
    out, per_call = [], []
    for H in (H0, _moved(H0, 1), _moved(H0, 2)):
        n = len(rows)
        out.append(contact.pairs(H))
        per_call.append(sum(rows[n:]))
    return out, per_call


def _same(P, Q):
    for f in dataclasses.fields(P):
        a, b = getattr(P, f.name), getattr(Q, f.name)
        assert a.dtype == b.dtype and np.array_equal(a, b), f.name
        if a.dtype.kind == "f":
            assert np.array_equal(a.view(np.int64), b.view(np.int64)), f.name


@pytest.mark.parametrize("force_all", [False, True])
def test_kept_orthogonal_crossings_skip_their_closest_points_with_the_same_pairs(monkeypatch, force_all):
    before, rows_before = _search(monkeypatch, False)
    after, rows_after = _search(monkeypatch, True, force_all)
    assert {POINT, ORTHOGONAL} <= set(before[0].kind.tolist())
    for P, Q in zip(before, after):
        _same(P, Q)
    # the first evaluation of the step computes every crossing's closest points; the later ones the point pairs'
    # alone (the orthogonal crossing's kept kind), unless extend_wrap could read them (``force_all``)
    assert rows_after[0] == rows_before[0] > 0
    if force_all:
        assert rows_after == rows_before
    else:
        n_point = sum(1 for k in before[0].kind if k == POINT)
        assert all(0 < r < rows_before[0] for r in rows_after[1:])
        assert all(r >= n_point for r in rows_after[1:])


def test_wrap_may_change_reads_new_point_pairs_at_an_end():
    kinds = np.array([POINT, POINT, ORTHOGONAL, POINT])
    xi1 = np.array([0.5, 0.01, 0.99, 1.2])
    run = np.array([0, 1, 2, 3])
    assert not system.ContactSystem._wrap_may_change(kinds, xi1, run, np.array([-1, POINT, -1, POINT]))
    assert system.ContactSystem._wrap_may_change(kinds, xi1, run, np.array([-1, -1, -1, POINT]))
    assert system.ContactSystem._wrap_may_change(kinds, xi1, run, np.array([-1, POINT, -1, -1]))


def _line_scene(integration):
    """A slave lying along a bent master (line pairs; ``integration`` "points" or "segments") and a crossing slave
    (a point pair)."""
    m = bs.Model()
    sec = bs.Section.circular(radius=0.05, E=1e7)
    master = m.add_beam(bs.geometry.straight((-1, 0, 0), (1, 0, 0), 8), sec)
    m.add_contact(m.add_beam(bs.geometry.straight((-0.83, 0.0, 0.0999), (0.61, 0.02, 0.0995), 5), sec), master,
                  integration=integration)
    a = np.deg2rad(70.0)
    d = np.array([np.cos(a), np.sin(a), 0.0])
    c = np.array([0.45, 0.0, -0.099])
    m.add_contact(m.add_beam(bs.geometry.straight(c - 0.6 * d, c + 0.6 * d, 4), sec), master)
    return m


@pytest.mark.parametrize("integration", ["points", "segments"])
def test_search_centres_equal_the_computed_sections(monkeypatch, integration):
    """``SEARCH_CENTRES``: the centre points ``_centres`` gives for the pairs of ``pairs(H)`` (the Gauss-point rows'
    from their projections, the point pairs' computed) are the sections computed afresh, bit for bit."""
    monkeypatch.setattr(system, "SEARCH_CENTRES", True)
    problem = Problem.from_model(_line_scene(integration), check_rigid_modes=False)
    contact = problem.contact
    H0 = problem.system.poses0.copy()
    contact.begin_step(H0, 0.1)
    for H in (H0, _moved(H0, 3)):
        P = contact.pairs(H)
        assert {POINT, system.LINE} <= set(P.kind.tolist())
        assert contact._pair_centres[0] is P
        xC, xF = contact._centres(H, P)
        assert contact._pair_centres is None         # handed out once
        rC, rF = contact._points(H, P.e, P.xi1), contact._points(H, P.m, P.xi2)
        for a, b in ((xC, rC), (xF, rF)):
            assert a.shape == b.shape and np.array_equal(a.view(np.int64), b.view(np.int64))


def test_prev_points_kept_for_the_same_sections_and_renewed_at_a_step(monkeypatch):
    """``PREV_POINTS_KEPT``: the centre points at the step's start poses of the same elements and sections are the
    last call's (the same floats), computed afresh for other sections and after ``begin_step``."""
    monkeypatch.setattr(system, "PREV_POINTS_KEPT", True)
    problem = Problem.from_model(_line_scene("points"), check_rigid_modes=False)
    contact = problem.contact
    H0 = problem.system.poses0.copy()
    contact.begin_step(H0, 0.1)
    P = contact.pairs(H0)
    x = contact._centres(H0, P, prev=True)[0]
    assert contact._points(H0, P.e.copy(), P.xi1.copy(), prev=True, keep=True) is x
    assert contact._points(H0, P.e, P.xi1, prev=True) is not x       # (kept for the slave points alone)
    xi = P.xi1.copy()
    xi[0] = np.nextafter(xi[0], 2.0)
    assert contact._points(H0, P.e, xi, prev=True, keep=True) is not x
    H1 = _moved(H0, 5)
    contact.begin_step(H1, 0.2)
    y = contact._centres(H1, P, prev=True)[0]
    ref = contact._points(H1, P.e, P.xi1)
    assert y is not x and np.array_equal(y.view(np.int64), ref.view(np.int64))


def _bend():
    """A master along ``e_x`` bending up by 30 degrees at x = 0 (``polyline``), a one-element slave along ``e_x`` just
    above it: its Gauss points have line rows on the straight part (angle 0) and orthogonal rows on the bend's rising
    element (a crossing of ratio ``sin^2 30 < 1/2``)."""
    sec = bs.Section.circular(radius=0.05, E=1e7, nu=0.3)
    m = bs.Model()
    a = np.deg2rad(30.0)
    s = np.linspace(0.25, 1.0, 4)
    pts = np.concatenate([np.stack([np.linspace(-1.0, 0.0, 5), np.zeros(5), np.zeros(5)], 1),
                          np.stack([s * np.cos(a), 0.0 * s, s * np.sin(a)], 1)])
    master = m.add_beam(bs.geometry.polyline(pts), sec)
    slave = m.add_beam(bs.geometry.straight((-0.5, 0, 0.0995), (0.1, 0, 0.0995), 1), sec)
    m.clamp(master.first)
    m.clamp(master.last)
    m.clamp(slave.first)
    m.add_contact(slave, master, integration="points")
    return Problem.from_model(m, check_rigid_modes=False), slave


def test_a_gauss_points_owner_keeps_its_projection_kind_within_a_step():
    """Gauss point 3 of the slave: owned by a line row at dx = 0 and, decided afresh, by an orthogonal row at
    dx = 0.02 (the nearer).  Within a step (no ``begin_step`` between) it keeps the line row while one is accepted
    (``history.step_point_kinds``): the two kinds measure and load the point differently (the plectoneme's force
    jumped by 0.5 N and 96 N between Newton iterates); a new step decides afresh."""
    problem, slave = _bend()
    cs, H0 = problem.contact, problem.system.poses0

    def kind_of_gp3(dx):
        H = H0.copy()
        H[slave.nodes, 0, 3] += dx
        P = cs.pairs(H)
        sel = P.gp == 3
        assert sel.sum() == 1
        return int(P.kind[sel][0])

    cs.history.begin_step()
    assert kind_of_gp3(0.0) == LINE
    assert kind_of_gp3(0.02) == LINE                # held (decided afresh: orthogonal, was so within the step)
    cs.history.begin_step()
    assert kind_of_gp3(0.02) == ORTHOGONAL          # a new step decides afresh
    assert kind_of_gp3(0.0) == ORTHOGONAL           # ... and keeps that (the orthogonal row still accepted)
    monkey = system.HOLD_POINT_KINDS
    try:
        system.HOLD_POINT_KINDS = False
        cs.history.begin_step()
        assert kind_of_gp3(0.0) == LINE
        assert kind_of_gp3(0.02) == ORTHOGONAL      # (without the hold: each evaluation decides)
    finally:
        system.HOLD_POINT_KINDS = monkey


@pytest.mark.slow
@pytest.mark.parametrize("ends", ["fixed", "free"])
def test_a_touching_strand_s_step_0_decides_point_kinds_at_each_iterate(ends):
    """Step 0 of a touching 1+6 strand at 20 degrees (``examples/strand_sweep.py``, the sweep's scene): its wires
    move apart from the touching start over 14-74 Newton iterations, and a Gauss point's owner must follow them
    from one projection kind to the other; holding the kind of the first iterate (``history.step_point_kinds``)
    for step 0 left it without an equilibrium in 120 iterations (scaled residual 1.94 / 0.268).  Step 0 cannot be
    cut back, so there each evaluation decides (``Problem.hold_point_kinds``, ``Run._solve_start``)."""
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "examples"))
    import strand_sweep
    model = strand_sweep.build(lay_angle=20.0, ends=ends)[0]
    sol = bs.solve(model, verbose=False, **strand_sweep.solve_options)
    assert sol.converged and sol.times[-1] == 1.0
