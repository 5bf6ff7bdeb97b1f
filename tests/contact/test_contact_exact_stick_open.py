"""Exact stick's Newton evaluations leave out the points of certainly open groups (``contact.system.SKIP_OPEN``,
``ContactSystem._open_points``): far from the normal law's band, in groups with zero multipliers and no point in
the band.  They act on nothing, so the residual is the same bits, the Newton step the same to round-off, and the
committed history (which takes every point) the same as with every point evaluated."""
import numpy as np
import pytest
import scipy.sparse.linalg as spla

from beamsolver import se3
from beamsolver.contact import system as csys
from beamsolver.nonlinear.problem import Problem
from test_contact_exact_stick import R, _move, _parallel


def _lifted(lift=0.1):
    """``(problem, H)``: ``_parallel``'s slave pressed at its clamped end and lifted by ``lift R`` at the other:
    the far groups are open (their points in the search's overlap, out of the normal law's band)."""
    model, slave, master = _parallel(0.5, n_slave=8)
    problem = Problem.from_model(model, check_rigid_modes=False)
    H = problem.system.poses0.copy()
    H[slave.nodes, 2, 3] += -2e-3 * R + lift * R * np.linspace(0.0, 1.0, len(slave.nodes))
    return problem, H, slave


def _run(monkeypatch, skip, keys_lam=None):
    """The lifted scene with ``SKIP_OPEN = skip``: begun and committed, slid, evaluated with the tangent, its
    Newton step solved directly, then committed there: ``(r, dq, dlam, skipped, history)``."""
    monkeypatch.setattr(csys, "SKIP_OPEN", skip)
    monkeypatch.setattr(csys, "SKIP_MIN", 0)        # (a small scene: 30 far points)
    problem, H, slave = _lifted()
    c = problem.contact
    problem.begin_step(H, 0.0)
    problem.commit(H)
    problem.begin_step(H, 0.1)
    if keys_lam is not None:
        c.history.update_multipliers(tmult=keys_lam)
    H = _move(H, slave.nodes, se3.exp(np.array([1e-7 * R, 1e-7 * R, 0.0, 1e-7 * R, 0.0, 0.0])))
    ev = problem.evaluate(H, 0.1, tangent=True)
    skipped = c._skipped
    A, b = problem.linear_system(ev)
    dq, dl = problem.split_solution(ev, spla.spsolve(A.tocsc(), b))
    dl = dict(zip(ev.mult["key"].tolist(), dl))
    problem.commit(H)
    hist = c.history
    return ev.r.copy(), dq, dl, skipped, (hist.friction["key"].copy(), hist.friction["H_LK"].copy(),
                                          hist.tmult[0].copy(), hist.tmult[1].copy())


def _same(a, b):
    r0, dq0, dl0, _, h0 = a
    r1, dq1, dl1, _, h1 = b
    assert np.array_equal(r0, r1)
    assert np.abs(dq1 - dq0).max() <= 1e-12 * np.abs(dq0).max()
    # the multipliers' step: the same on the groups both have, zero on the open ones left out
    scale = max(np.abs(v).max() for v in dl0.values())
    assert set(dl1) <= set(dl0)
    for k, v in dl0.items():
        assert np.abs(dl1.get(k, 0.0) - v).max() <= 1e-12 * scale
        if k not in dl1:
            assert not v.any()
    for x, y in zip(h0, h1):
        assert np.array_equal(x, y)


def test_open_groups_are_left_out_and_change_nothing(monkeypatch):
    full, skip = _run(monkeypatch, False), _run(monkeypatch, True)
    assert full[3] == 0 and skip[3] >= 20          # 25 of the 40 points: the far groups'
    assert len(skip[2]) < len(full[2])             # groups left out
    _same(full, skip)


def test_a_group_with_a_multiplier_keeps_its_points(monkeypatch):
    """A far group given a traction is not open: its points are evaluated (fewer left out), the answers as with every
    point."""
    monkeypatch.setattr(csys, "SKIP_OPEN", False)
    problem, H, slave = _lifted()
    c = problem.contact
    problem.begin_step(H, 0.0)
    problem.evaluate(H, 0.0, tangent=False)
    P, sel = c._cache[1], c._cache[2]
    far = int(np.argmax(P.xi1[sel] + P.e[sel]))            # the point farthest along the slave
    key = ((P.decl[sel][far] * np.int64(len(H)) + P.nodes[sel][far, 1]) * c.n_beams + c.el_beam[P.m[sel][far]])
    keys_lam = (np.array([key]), np.array([[0.0, 3.0, -2.0]]))
    full, skip = _run(monkeypatch, False, keys_lam), _run(monkeypatch, True, keys_lam)
    open_only = _run(monkeypatch, True)
    assert 0 < skip[3] < open_only[3]
    _same(full, skip)


@pytest.mark.parametrize("lift", [0.3, 0.6])
def test_every_group_open_but_one(monkeypatch, lift):
    """Lifted further: most points left out, the same residual bits."""
    rs = []
    monkeypatch.setattr(csys, "SKIP_MIN", 0)
    for flag in (False, True):
        monkeypatch.setattr(csys, "SKIP_OPEN", flag)
        problem, H, slave = _lifted(lift)
        problem.begin_step(H, 0.0)
        ev = problem.evaluate(H, 0.0, tangent=True)
        rs.append((ev.r.copy(), problem.contact._skipped))
    assert rs[0][1] == 0 and rs[1][1] > 0
    assert np.array_equal(rs[0][0], rs[1][0])


def test_too_few_far_points_are_not_tried(monkeypatch):
    """Below ``SKIP_MIN`` far points nothing is left out (the look-ups would cost what they save)."""
    monkeypatch.setattr(csys, "SKIP_OPEN", True)
    problem, H, slave = _lifted()
    problem.begin_step(H, 0.0)
    problem.evaluate(H, 0.0, tangent=False)
    assert problem.contact._skipped == 0
    monkeypatch.setattr(csys, "SKIP_MIN", 0)
    problem.begin_step(H, 0.0)
    problem.evaluate(H, 0.0, tangent=False)
    assert problem.contact._skipped > 0
