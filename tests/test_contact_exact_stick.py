"""Exact stick (``stick="exact"``, mortar nodal multipliers, ``contact/mortar.py``).

Tangent against central finite differences perturbing on the group (stick, slip, turned
multipliers); shear lag on a rigid rod (slip zone ``F / (mu q)``, unloaded stick zone) at two
meshes; answers independent of the augmentation penalty; the patch test with friction (stick
everywhere, no slip); option checks.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

import beamsolver as bs
from beamsolver import se3
from beamsolver.problem import Problem

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
import contact_patch  # noqa: E402
import shear_lag  # noqa: E402

R = 0.05
SEC = bs.Section.circular(radius=R, E=1e7, nu=0.3)


def _parallel(mu, n_slave=4, **options):
    """A slave beam slightly skew above a clamped master (non-matching meshes, 3-D)."""
    m = bs.Model()
    master = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 5), SEC)
    slave = m.add_beam(bs.geometry.straight((0.1, 0.002, 2 * R), (0.9, -0.002, 2 * R), n_slave), SEC)
    m.clamp(master.first)
    m.clamp(master.last)
    m.clamp(slave.first)
    m.add_contact(slave, master, mu=mu, stick="exact", **options)
    return m, slave, master


def _move(H, nodes, G):
    H = H.copy()
    H[nodes] = se3.compose(np.broadcast_to(G, (len(nodes), 4, 4)), H[nodes])
    return H


def _pressed(problem, slave, depth):
    """Translate the slave down so that its lowest contact point penetrates by ``depth``."""
    H = problem.system.poses0.copy()
    z = H[slave.nodes, 2, 3].min()
    G = np.eye(4)
    G[2, 3] = 2 * R - z - depth
    H = _move(H, slave.nodes, G)
    # bend it a little so the pressure varies along the slave
    H[slave.nodes, 2, 3] -= depth * np.linspace(0.0, 1.0, len(slave.nodes)) ** 2
    return H


def _fd_error(problem, H, eps=1e-7):
    """Largest difference between the assembled tangent and central differences of the residual
    over the free unknowns, relative to the largest contact tangent entry."""
    system = problem.system
    ev = problem.evaluate(H, 0.0, tangent=True)
    K = problem.full_tangent(ev).toarray()
    free = system.free_dofs
    n = system.n_nodes
    Kc = np.zeros_like(K)
    np.add.at(Kc, (ev.extra[0], ev.extra[1]), ev.extra[2])
    scale = np.abs(Kc[np.ix_(free, free)]).max()
    worst = 0.0
    for d in free:
        dz = np.zeros(6 * n)
        dz[d] = eps
        rp = problem.evaluate(problem.update(H, dz.reshape(n, 6)), 0.0, tangent=False).r
        rm = problem.evaluate(problem.update(H, -dz.reshape(n, 6)), 0.0, tangent=False).r
        worst = max(worst, np.abs((rp - rm)[free] / (2 * eps) - K[free, d]).max() / scale)
    return worst


@pytest.mark.parametrize("regime", ["stick", "slip", "turned"])
def test_exact_stick_tangent_matches_finite_differences(regime):
    model, slave, master = _parallel(0.5 if regime != "slip" else 0.05)
    problem = Problem.from_model(model, check_rigid_modes=False)
    c = problem.contact
    H = _pressed(problem, slave, 2e-3 * R)
    c.begin_step(H, 0.0)
    c.commit(H)                                 # history and nodal multipliers (zero) at H
    if regime == "turned":                      # multipliers in the nodes' frames, not zero
        keys, lam = c._tmult
        c._tmult = (keys, np.random.default_rng(3).normal(size=lam.shape) * 50.0)
    slide = {"stick": 1e-7, "slip": 2e-3, "turned": 1e-7}[regime] * R
    G = se3.exp(np.array([slide, slide, 0.0, slide, 0.0, 0.5 * slide]))
    H = _move(H, slave.nodes, G)
    err = _fd_error(problem, H)
    m = c._local_blocks(H, True)[5]["mortar"]
    stick = m["stick"][np.linalg.norm(m["lam"], axis=1) > 0]
    if regime == "slip":
        assert not stick.all()
    else:
        assert stick.all() and len(stick)
    assert err < 1e-6, err
