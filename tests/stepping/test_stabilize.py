"""Viscous stabilisation (``solve(stabilize=)``, ``beamsolver.stabilize``): its tangent, its effect on a
stable answer (bounded by the reported dissipated fraction, vanishing with it) and a column taken past
buckling to the elastica, where plain load control returns the unstable straight state."""
import warnings

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import ellipk

import beamsolver as bs
from beamsolver import se3, stabilize
from beamsolver.assembly.system import System
from beamsolver.nonlinear.problem import Problem


def _cantilever(n=6):
    sec = bs.Section.circular(radius=1e-2, E=200e9, nu=0.3)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n), sec)
    m.clamp(b.first)
    return m, b, sec


def _assembled(system, stab, H, tangent=True):
    """Residual ``(6 n,)`` and dense tangent of the stabilisation through the generic assembler."""
    blocks, _ = stab.evaluate(H, tangent)
    r, (rows, cols, vals), _, _ = system.assemble_blocks(H, blocks)
    K = np.zeros((len(r), len(r)))
    np.add.at(K, (np.ravel(rows), np.ravel(cols)), vals)
    return r, K


def test_viscous_tangent_matches_finite_differences():
    m, b, _ = _cantilever()
    system = System(m)
    rng = np.random.default_rng(3)
    stab = stabilize.Stabilization(system, factor=0.7)
    H_prev = system.update(system.poses0, 0.2 * rng.standard_normal((system.n_nodes, 6)))
    H = system.update(H_prev, 0.3 * rng.standard_normal((system.n_nodes, 6)))
    stab.t_last = 0.3
    stab.begin_step(H_prev, 0.35)
    assert stab.dt == pytest.approx(0.05)
    r, K = _assembled(system, stab, H)
    eps = 1e-6
    for node in stab.nodes:
        for k in range(6):
            e = np.zeros(6)
            e[k] = eps
            Hp, Hm = H.copy(), H.copy()
            Hp[node] = H[node] @ se3.exp(e)
            Hm[node] = H[node] @ se3.exp(-e)
            fd = (_assembled(system, stab, Hp, False)[0] - _assembled(system, stab, Hm, False)[0]) / (2 * eps)
            col = K[:, 6 * node + k]
            assert np.abs(fd - col).max() <= 1e-7 * np.abs(K).max()
    # the force is c M* log(H_prev^-1 H) / dt, zero at nodes without damping (the clamp)
    assert np.all(r[6 * b.first:6 * b.first + 6] == 0.0)
    h = se3.log(se3.relative(H_prev[b.last], H[b.last]))
    m_u, m_w = stab.m[list(stab.nodes).index(b.last)]
    assert np.allclose(r[6 * b.last:6 * b.last + 6], 0.7 / 0.05 * np.r_[m_u * h[:3], m_w * h[3:]], rtol=1e-13)


def test_a_stable_answer_moves_by_less_than_the_reported_fraction_and_linearly_with_it():
    m, b, sec = _cantilever(10)
    EI = sec.C[4, 4]
    m.add_load(b.last, force=(0, 3 * EI, 0.5 * EI))
    ref = bs.solve(m, steps=10, verbose=False)
    assert "stabilization" not in ref.stats[-1]
    u = np.linalg.norm(ref.position(b.last) - (1, 0, 0))
    diffs, fractions = [], []
    for f in (1e-2, 1e-3, 1e-4):
        sol = bs.solve(m, steps=10, stabilize=f, verbose=False)
        diffs.append(np.linalg.norm(sol.position(b.last) - ref.position(b.last)) / u)
        st = sol.stats[-1]["stabilization"]
        fractions.append(st["fraction"])
        assert st["factor"] > 0 and st["dissipated_total"] > 0
        assert diffs[-1] < fractions[-1]
    diffs, fractions = np.array(diffs), np.array(fractions)
    assert np.allclose(diffs[:-1] / diffs[1:], 10.0, rtol=0.02)
    assert np.allclose(fractions[:-1] / fractions[1:], 10.0, rtol=0.02)
    assert diffs[-1] < 2e-6


def _column(ratio):
    m, b, sec = _cantilever(16)
    P = ratio * np.pi**2 * sec.C[4, 4] / 4.0
    m.add_load(b.last, force=(-P, 1e-4 * P / ratio, 0), scale=lambda t: min(t, 1.0))
    return m, b


def _tip_rotation(sol, node):
    R = sol.rotation(node)
    return np.arctan2(R[1, 0], R[0, 0])


def test_column_past_buckling_reaches_the_elastica_with_stabilisation():
    ratio = 2.0
    k2 = brentq(lambda q: (2 * ellipk(q) / np.pi) ** 2 - ratio, 1e-9, 1 - 1e-12)
    alpha = 2 * np.arcsin(np.sqrt(k2))          # Timoshenko & Gere: P / P_cr = (2 K(k) / pi)^2, k = sin(alpha/2)
    m, b = _column(ratio)
    plain = bs.solve(m, steps=20, t_end=2.0, verbose=False)
    assert abs(_tip_rotation(plain, b.last)) < 1e-2          # the unstable, nearly straight state
    with pytest.warns(bs.StabilizationWarning, match="polluted"):
        sol = bs.solve(m, steps=20, t_end=2.0, stabilize=2e-4, verbose=False)
    assert _tip_rotation(sol, b.last) == pytest.approx(alpha, rel=2e-3)
    st = [s["stabilization"] for s in sol.stats[1:]]
    assert st[-1]["dissipated"] < 1e-8 * st[-1]["strain_energy"]     # at rest again
    assert max(s["fraction"] for s in st) > 0.05                     # the snap's energy went into damping
    assert any(s.get("cutbacks", 0) for s in sol.stats)                # saddle steps were refused


def test_saddle_step_is_refused():
    m, b = _column(2.0)
    problem = Problem.from_model(m)
    stab = stabilize.Stabilization(problem.system, factor=1e-12)
    problem.contributions.append(stab)
    stab.t_last = 0.0
    problem.begin_step(problem.system.poses0, 1.0)
    ev = problem.evaluate(problem.system.poses0, 1.0)
    with pytest.raises(stabilize.StabilizedSaddle, match="too weak"):
        stab.check(problem.tangent(ev), 1.0)


@pytest.mark.parametrize("bad", ["yes", -1e-3, 0.0, dict(fraction=-1), dict(fractoin=1e-3), dict(factor=np.nan)])
def test_bad_stabilize_option_is_refused(bad):
    m, b, _ = _cantilever(2)
    m.add_load(b.last, force=(0, 1.0, 0))
    with pytest.raises(bs.InputError, match="stabilize"):
        bs.solve(m, steps=1, stabilize=bad, verbose=False)


def test_explicit_factor_damps_from_the_first_step():
    m, b, _ = _cantilever(4)
    m.add_load(b.last, force=(0, 1e3, 0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bs.StabilizationWarning)
        sol = bs.solve(m, steps=2, stabilize=dict(factor=1e-3), verbose=False)
    assert sol.stats[1]["stabilization"]["factor"] == 1e-3
    assert sol.stats[1]["stabilization"]["dissipated"] > 0


def test_three_node_elements_are_damped_with_their_own_energy_and_masses():
    """The damping reads the element contract (``ElementType.energy``) and lumps each element at all
    its nodes: a three-node beam is damped, its recorded strain energy is that of its elements (the
    two-node formula on its end nodes would differ), and ``M*`` carries the same total as the same
    beam of two-node elements (the mid nodes take their share: 1/3 of each element)."""
    sec = bs.Section.circular(radius=1e-3, E=200e9, nu=0.3)
    models = {}
    for kind, n in (("se3-3", 4), ("se3-2", 8)):
        m = bs.Model()
        b = m.add_beam(bs.geometry.straight(start=(0, 0, 0), end=(1, 0, 0), n_elements=n), sec, element=kind)
        m.clamp(b.first)
        m.add_load(b.last, force=(0, 0, 1e-2))
        models[kind] = m
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bs.StabilizationWarning)
        sol = bs.solve(models["se3-3"], steps=2, stabilize=dict(factor=1e-3), verbose=False)
    rec = sol.stats[-1]["stabilization"]
    assert rec["dissipated"] > 0
    system = Problem.from_model(models["se3-3"]).system
    (g,) = system.groups
    energy = float(g.element_type.energy(sol.poses[-1], g.nodes, g.ref).sum())
    assert rec["strain_energy"] == energy
    two_node = float(bs.elements.get("se3-2").energy(sol.poses[-1], g.nodes[:, [0, -1]],
                                                      bs.elements.get("se3-2").reference(
                                                          system.poses0[g.nodes[:, [0, -1]]], g.ref.C)).sum())
    assert abs(two_node - energy) > 1e-3 * energy          # the old formula would be another number
    totals = []
    for sys_k in (system, Problem.from_model(models["se3-2"]).system):
        (g,) = sys_k.groups
        full = stabilize.mass_scales(sys_k.rep[g.nodes], g.ref.L, g.ref.C, sys_k.length_scale, sys_k.n_nodes)
        totals.append(full.sum(axis=0))
        assert np.all(full > 0)
    np.testing.assert_allclose(totals[0], totals[1], rtol=1e-12)
    assert np.all(stabilize.Stabilization(system, factor=1.0).m > 0)      # the mid nodes are damped too


def test_restart_continues_with_the_same_damping():
    """A stabilised run interrupted and restarted with the same arguments ends where the
    uninterrupted one does: the restart keeps the damping factor ``c`` and the dissipated total
    (it used to calibrate ``c`` again, its first step undamped: near a snap, the wrong moment)."""
    m, b, sec = _cantilever(8)
    EI = sec.C[4, 4]
    m.add_load(b.last, force=(0, 3 * EI, 0.5 * EI))
    args = dict(steps=10, stabilize=1e-2, verbose=False)
    ref = bs.solve(m, **args)

    def stop(info):
        if info["t"] > 0.55:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt) as e:
        bs.solve(m, callback=stop, **args)
    first = e.value.solution
    assert first.times[-1] == pytest.approx(0.5)
    sol = bs.solve(m, restart=first, **args)
    assert np.array_equal(sol.times, ref.times)
    for k in range(1, len(ref.times)):
        assert sol.stats[k]["stabilization"]["factor"] == ref.stats[k]["stabilization"]["factor"]
    st, st_ref = sol.stats[-1]["stabilization"], ref.stats[-1]["stabilization"]
    assert st["dissipated_total"] == pytest.approx(st_ref["dissipated_total"], rel=1e-9)
    assert np.abs(sol.poses[-1] - ref.poses[-1]).max() < 1e-12
