"""System-level checks: assembled tangent = derivative of the assembled residual; reactions."""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver import geometry, se3
from beamsolver.assembly.system import GLOBAL, System

from helpers import check_tangent as _check_tangent, deformed_state as _deformed, rel_err, spd_matrix


def _section(full=False):
    if full:
        return bs.Section.from_matrix(spd_matrix(np.random.default_rng(5)), radius=0.05)
    return bs.Section(EA=1e3, GA2=4e2, GA3=5e2, GJ=20.0, EI2=30.0, EI3=40.0, radius=0.05)


def _bent_cantilever(full=False, n=4):
    m = bs.Model()
    b = m.add_beam(geometry.arc(radius=1.0, angle=1.2, n_elements=n), _section(full))
    m.clamp(b.first)
    return m, b


@pytest.mark.parametrize("full", [False, True])
def test_dead_loads_load_stiffness(full):
    m, b = _bent_cantilever(full)
    m.add_load(b.last, force=(3.0, -5.0, 7.0), moment=(1.0, 2.0, -4.0))
    m.add_load(b.nodes[2], force=(0.0, 0.0, -9.0), moment=(-2.0, 0.5, 0.0), scale=lambda t: 2.0 * t)
    system, K, fd = _check_tangent(m)
    # without the load stiffness the check would fail: it is not negligible
    m2, b2 = _bent_cantilever(full)
    s2 = System(m2)
    H = _deformed(s2, np.random.default_rng(0))
    _, kv, _ = s2.evaluate(H, np.zeros(0))
    K0 = s2.full_matrix(kv).toarray()[np.ix_(s2.free_dofs, s2.free_dofs)]
    assert rel_err(K0, fd) > 1e-4


def test_follower_loads():
    m, b = _bent_cantilever()
    m.add_load(b.last, force=(3.0, -5.0, 7.0), moment=(1.0, 2.0, -4.0), follower=True)
    m.add_load(b.nodes[1], force=(0.0, 4.0, 0.0), follower=True)
    m.add_load(b.nodes[2], force=(1.0, 0.0, -2.0), moment=(0.0, 0.0, 3.0))   # plus a dead one
    _check_tangent(m, seed=1)


def test_partial_fix_global_unknowns():
    m = bs.Model()
    b = m.add_beam(geometry.helix(radius=0.3, pitch=1.2, length=1.0, n_elements=5), _section(True))
    m.fix(b.first, ("ux", "uy", "uz", "rz"))
    m.fix(b.nodes[2], ("ux", "ry"))
    m.fix(b.last, ("ux", "uy", "rx", "ry"))
    m.add_load(b.nodes[2], force=(1.0, 2.0, -3.0), moment=(0.5, -1.0, 2.0))
    m.add_load(b.last, force=(0.0, 0.0, 6.0), moment=(0.0, 0.0, 1.5))
    m.add_load(b.nodes[3], force=(2.0, 0.0, 1.0), follower=True)
    system, K, fd = _check_tangent(m, seed=2)
    assert len(system.global_nodes) == 3 and np.all(system.kind[system.global_nodes] == GLOBAL)


def test_join_with_different_frames():
    m = bs.Model()
    b1 = m.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), 3), _section())
    b2 = m.add_beam(geometry.straight((1, 0, 0), (1.2, 0.8, 0.5), 3), _section(True))
    b3 = m.add_beam(geometry.arc(radius=0.8, angle=1.0, n_elements=2, origin=(1, 0, 0)), _section())
    m.join(b1.last, b2.first)
    m.join(b2.first, b3.first)
    m.clamp(b1.first)
    m.fix(b3.last, ("uz",))
    m.add_load(b2.last, force=(1.0, -2.0, 3.0), moment=(0.3, 0.2, -0.1))
    m.add_load(b2.first, force=(0.0, 5.0, 0.0), moment=(1.0, 0.0, 0.0))    # dead load on a member
    m.add_load(b3.first, moment=(0.0, 0.0, 2.0), follower=True)
    system, K, fd = _check_tangent(m, seed=3)
    assert len(system.members) == 2
    P = m.poses0
    assert not np.allclose(P[b1.last, :3, :3], P[b2.first, :3, :3])


def test_newton_quadratic_on_joined_frame():
    """A consequence of an exact tangent: the residual falls quadratically."""
    m = bs.Model()
    b1 = m.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), 4), _section())
    b2 = m.add_beam(geometry.straight((1, 0, 0), (1, 1, 0.3), 4), _section())
    m.join(b1.last, b2.first)
    m.clamp(b1.first)
    m.add_load(b2.last, force=(0.5, -1.0, 2.0), moment=(0.2, 0.0, 0.3))
    res = []
    bs.solve(m, steps=1, rtol=1e-13, callback=lambda i: res.append(i["residual"]))
    r = np.array([x for x in res if x > 0])
    # find two consecutive iterations in the asymptotic range and check the order
    pairs = [(a, c) for a, c in zip(r[:-1], r[1:]) if 1e-11 < c and a < 1e-2]
    assert pairs, r
    for a, c in pairs:
        assert c < 50.0 * a**2 + 1e-12, r


def test_reaction_balances_loads_bent_cantilever():
    m, b = _bent_cantilever(n=8)
    loads = [(b.last, np.array([3.0, -5.0, 7.0]), np.array([1.0, 2.0, -4.0])),
             (b.nodes[4], np.array([0.0, 0.0, -6.0]), np.array([-2.0, 0.5, 0.0]))]
    for node, F, M in loads:
        m.add_load(node, force=F, moment=M)
    sol = bs.solve(m, steps=4)
    x = sol.poses[-1][:, :3, 3]
    root = x[b.first]
    assert np.abs(x[b.last] - m.poses0[b.last, :3, 3]).max() > 0.05    # really deformed
    F_tot = sum(F for _, F, _ in loads)
    M_tot = sum(M + np.cross(x[node] - root, F) for node, F, M in loads)
    R = sol.reaction(b.first)
    assert np.abs(R[:3] + F_tot).max() <= 1e-7 * np.abs(F_tot).max()
    assert np.abs(R[3:] + M_tot).max() <= 1e-7 * np.abs(M_tot).max()
    # free nodes carry no reaction (the residual at convergence)
    free = np.delete(np.arange(m.n_nodes), b.first)
    assert np.abs(sol.reactions[-1][free]).max() <= 1e-7 * np.abs(F_tot).max()
