"""System-level contact tangent against central finite differences of the residual.

Unknowns are perturbed on the group through ``System.update``; the assembled
tangent (elements + contact) is compared column by column with
``(r(H exp(+e dz)) - r(H exp(-e dz))) / 2e`` for every free unknown, in each
regime (open, closed frictionless, stick, slip) and for each projection
(line, orthogonal, point).  The error is measured relative to the largest
entry of the contact tangent (of the full tangent when contact is open).  These are the Gauss-point
law's tangents (``stick="penalty"``); exact stick's bordered tangent is checked in
``test_contact_exact_stick.py``.
"""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver import se3
from beamsolver.nonlinear.problem import Problem
from beamsolver.contact.frames import LINE, ORTHOGONAL, POINT
from helpers import contact_tangent_error

R = 0.05
SEC = bs.Section.circular(radius=R, E=1e7, nu=0.3)


def _crossing(mu):
    m = bs.Model()
    master = m.add_beam(bs.geometry.straight((0, -1, 0), (0, 1, 0), 5), SEC)
    slave = m.add_beam(bs.geometry.straight((-1, 0.03, 2 * R), (1, -0.05, 2 * R), 5), SEC)
    m.clamp(master.first)
    m.clamp(master.last)
    m.clamp(slave.first)
    m.add_contact(slave, master, mu=mu, stick="penalty")
    return m, slave, master, np.array([1.0, 0.0, 0.0])


def _parallel(mu):
    m = bs.Model()
    master = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), SEC)
    slave = m.add_beam(bs.geometry.straight((0.1, -0.02, 2 * R), (0.9, 0.03, 2 * R + 0.01), 4), SEC)
    m.clamp(master.first)
    m.clamp(master.last)
    m.clamp(slave.first)
    m.add_contact(slave, master, mu=mu, stick="penalty")
    return m, slave, master, np.array([1.0, 0.0, 0.0])


def _wrap(mu):
    m = bs.Model()
    post = m.add_beam(bs.geometry.straight((0, 0, -0.5), (0, 0, 0.5), 5), SEC)
    rc = 2 * R
    phi = np.linspace(-0.6, 0.9, 5)
    x = rc * np.stack([np.cos(phi), np.sin(phi), 0.01 * phi], axis=1)
    t = np.stack([-np.sin(phi), np.cos(phi), 0.01 + 0 * phi], axis=1)
    rope = m.add_beam(bs.geometry.frames_from_tangents(x, t, e2=(0, 0, 1)), SEC)
    m.clamp(post.first)
    m.clamp(post.last)
    m.clamp(rope.first)
    m.add_contact(rope, post, mu=mu, stick="penalty")
    return m, rope, post, np.array([0.0, 0.0, 1.0])


SCENES = {"line": (_parallel, LINE), "point": (_crossing, POINT), "orthogonal": (_wrap, ORTHOGONAL)}


def _move(H, nodes, G):
    H = H.copy()
    H[nodes] = se3.compose(np.broadcast_to(G, (len(nodes), 4, 4)), H[nodes])
    return H


def _towards_master(problem, H, slave, master, depth):
    """Translate the slave so that its closest contact point penetrates by ``depth``."""
    system = problem.system
    P = problem.contact.pairs(H)
    from beamsolver.contact.system import _interp_pos
    xC = _interp_pos(H, system.enodes, P.e, P.xi1)
    xF = _interp_pos(H, system.enodes, P.m, P.xi2)
    d = xF - xC
    dist = np.linalg.norm(d, axis=1)
    k = int(np.argmin(dist))
    n = d[k] / dist[k]
    G = np.eye(4)
    G[:3, 3] = n * (dist[k] - 2 * R + depth)
    return _move(H, slave.nodes, G)


def _fd_error(problem, H, eps=1e-7):
    worst, ev = contact_tangent_error(problem, H, eps)
    return worst, ev.details["contact"]


def _state(scene, regime):
    build, kind = SCENES[scene]
    mu = {"open": 0.3, "frictionless": 0.0, "stick": 0.5, "slip": 0.1, "stick_new": 0.5}[regime]
    model, slave, master, axis = build(mu)
    problem = Problem.from_model(model, check_rigid_modes=False)
    H = problem.system.poses0.copy()
    depth = -1e-3 * R if regime == "open" else 2e-3 * R
    H = _towards_master(problem, H, slave, master, depth)
    if regime == "stick_new":
        problem.contact.begin_step(H, 0.0)             # no history: it starts from the step's poses
    else:
        problem.contact.commit(H)                      # friction history at H
    # then slide the slave (and turn it a little): within the cone, or far beyond the
    # elastic slip (0.005 of the slave element length, at most 0.04 R here) for "slip"
    slide = {"open": 1e-4, "frictionless": 1e-3, "stick": 1e-6, "slip": 0.08, "stick_new": 1e-6}[regime] * R
    G = se3.exp(np.concatenate([slide * axis + [0, slide, 0], [slide, 0.0, 0.5 * slide]]))
    H = _move(H, slave.nodes, G)
    return problem, H, kind


@pytest.mark.parametrize("regime", ["open", "frictionless", "stick", "slip", "stick_new"])
@pytest.mark.parametrize("scene", ["line", "orthogonal", "point"])
def test_contact_tangent_matches_finite_differences(scene, regime):
    problem, H, kind = _state(scene, regime)
    P = problem.contact.pairs(H)
    assert set(P.kind.tolist()) == {kind}
    err, cinfo = _fd_error(problem, H)
    # the regime is the one asked for
    problem.contact.commit(H)
    res = problem.contact.results(H)
    if regime == "open":
        assert np.all(res["normal_force"] == 0.0) and np.all(res["gap"] > 0)
    else:
        assert cinfo["n_active"] > 0 and res["normal_force"].max() > 0
    on = res["normal_force"] > 0
    if regime in ("stick", "stick_new"):
        assert res["stick"][on].all()
        assert np.abs(res["tangential_force"]).max() > 0
    if regime == "slip":
        # points with history slide (a point that has just come into contact starts in stick)
        moved = on & (np.linalg.norm(res["slip_increment"], axis=1) > 0)
        assert moved.any() and not res["stick"][moved].any()
        lam_t = np.linalg.norm(res["tangential_force"], axis=1)
        np.testing.assert_allclose(lam_t[moved], 0.1 * res["normal_force"][moved], rtol=1e-10)
    assert err < 1e-6, err
