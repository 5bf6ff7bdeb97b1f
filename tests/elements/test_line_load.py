"""Line loads (Model.add_line_load, beamsolver.elements.line_load): consistent nodal loads, their stiffness
on the group, and cantilevers under uniform load against closed forms and an elastica shooting."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import beamsolver as bs
from beamsolver import se3
from beamsolver.elements import line_load

EI = 2.0
STIFF = 1e7          # EA, GA: a nearly inextensible, unshearable beam (the elastica's assumptions)


def _random_elements(n=6, seed=0):
    rng = np.random.default_rng(seed)
    HA = se3.exp(rng.normal(size=(n, 6)))
    HB = HA @ se3.exp(0.6 * rng.normal(size=(n, 6)))
    return HA, HB, rng.uniform(0.5, 2.0, n), rng.normal(size=(n, 3)), rng.normal(size=(n, 3))


@pytest.mark.parametrize("follower", [False, True])
def test_load_stiffness_matches_central_differences_on_the_group(follower):
    HA, HB, L, q, m = _random_elements()
    f, K = line_load.nodal_loads_and_tangent(HA, HB, L, q, m, follower)
    assert np.allclose(f, line_load.nodal_loads(HA, HB, L, q, m, follower), rtol=0, atol=1e-14)
    eps = 1e-6
    Kfd = np.zeros_like(K)
    for k in range(12):
        d = np.zeros(6)
        d[k % 6] = eps
        plus, minus = se3.exp(d), se3.exp(-d)
        if k < 6:
            fp, fm = (line_load.nodal_loads(HA @ E, HB, L, q, m, follower) for E in (plus, minus))
        else:
            fp, fm = (line_load.nodal_loads(HA, HB @ E, L, q, m, follower) for E in (plus, minus))
        Kfd[:, :, k] = (fp - fm) / (2 * eps)
    assert np.abs(K - Kfd).max() < 1e-8 * np.abs(K).max()


def test_dead_load_resultant_is_the_applied_force_and_its_moment():
    """A rigid translation ``c`` of the element is ``dq(xi) = (R(xi)^T c, 0)`` exactly, so the nodal
    forces sum (globally) to ``q L``; a rigid rotation gives the moment ``L int x(xi) x q + m L``."""
    HA, HB, L, q, m = _random_elements(seed=3)
    f = line_load.nodal_loads(HA, HB, L, q, m).reshape(-1, 2, 6)
    R = np.stack([HA[:, :3, :3], HB[:, :3, :3]], axis=1)
    x = np.stack([HA[:, :3, 3], HB[:, :3, 3]], axis=1)
    F = np.einsum("nkij,nkj->nki", R, f[..., :3])
    M = np.einsum("nkij,nkj->nki", R, f[..., 3:]) + np.cross(x, F)
    assert np.allclose(F.sum(axis=1), q * L[:, None], rtol=0, atol=1e-12)
    h = se3.log(se3.relative(HA, HB))

    def moment(xis, ws):
        out = m * L[:, None]
        for xi, w in zip(xis, ws):
            out = out + w * L[:, None] * np.cross(se3.interpolate(HA, h, xi)[:, :3, 3], q)
        return out
    assert np.allclose(M.sum(axis=1), moment(line_load.XI, line_load.WEIGHTS), rtol=0, atol=1e-12)
    xs, ws = np.polynomial.legendre.leggauss(40)          # quadrature error on these strongly curved elements
    assert np.abs(M.sum(axis=1) - moment(0.5 * (xs + 1), 0.5 * ws)).max() < 1e-4 * np.abs(M).max()


def _cantilever(n, q, follower=False):
    sec = bs.Section(EA=STIFF, GA2=STIFF, GA3=STIFF, GJ=1.0, EI2=EI, EI3=EI, radius=0.01)
    model = bs.Model()
    beam = model.add_beam(bs.geometry.straight((0, 0, 0), (1.0, 0, 0), n), sec)
    model.clamp(beam.first)
    model.add_line_load(beam, force_per_length=(0, 0, -q), follower=follower)
    return model, beam


def test_small_deflection_is_q_L4_over_8_EI_at_second_order():
    """Tip deflection of a cantilever (L = 1) under a small uniform load: the Timoshenko closed form
    ``q L^4 / 8 EI + q L^2 / 2 GA``; the error falls as ``h^2``."""
    q = 1e-4
    ref = q / (8 * EI) + q / (2 * STIFF)
    ns, err = [4, 8, 16], []
    for n in ns:
        model, beam = _cantilever(n, q)
        sol = bs.solve(model, steps=1)
        assert sol.converged
        err.append(abs(-sol.position(beam.last)[2] / ref - 1.0))
    rate = -np.polyfit(np.log(ns), np.log(err), 1)[0]
    assert abs(rate - 2.0) < 0.05
    assert err[-1] < 2e-3


def _elastica_tip(lam):
    """Tip ``(x, z)`` of an inextensible cantilever (L = 1) under a dead uniform load ``lam EI`` (-z):
    ``theta'' = -lam (1 - s) cos(theta)``, ``theta(0) = 0``, ``theta'(1) = 0`` by shooting on ``theta'(0)``."""
    def run(k0):
        return solve_ivp(lambda s, y: [y[1], -lam * (1 - s) * np.cos(y[0]), np.cos(y[0]), -np.sin(y[0])],
                         (0, 1), [0.0, k0, 0.0, 0.0], rtol=1e-12, atol=1e-12)
    k0 = brentq(lambda k: run(k).y[1, -1], 0.0, lam / 2 + 1e-9, xtol=1e-14)
    y = run(k0).y[:, -1]
    return y[2], y[3]


def test_large_deflection_matches_the_elastica_with_distributed_load():
    lam = 6.0                                        # q L^3 / EI: the tip drops by about 0.56 L
    x_ref, z_ref = _elastica_tip(lam)
    tips = []
    for n in (16, 32):
        model, beam = _cantilever(n, lam * EI)
        sol = bs.solve(model, steps=6)
        assert sol.converged
        tips.append(sol.position(beam.last)[[0, 2]])
    err = [np.hypot(*(t - (x_ref, z_ref))) for t in tips]
    assert z_ref < -0.5
    assert err[1] < 2e-3 and err[1] < 0.3 * err[0]      # second order: a quarter per halving


def test_follower_line_load_is_non_conservative_and_differs_from_dead():
    dead = bs.solve(_cantilever(16, 6.0 * EI)[0], steps=6)
    model, beam = _cantilever(16, 6.0 * EI, follower=True)
    from beamsolver.nonlinear.problem import Problem
    assert not Problem.from_model(model).conservative
    fol = bs.solve(model, steps=6)
    assert fol.converged
    # a follower load stays normal to the bent beam: it bends it further than the dead load
    assert fol.position(beam.last)[0] < dead.position(beam.last)[0] - 0.05


def test_line_load_input_errors():
    model, beam = _cantilever(4, 1.0)
    with pytest.raises(bs.InputError, match="force_per_length"):
        model.add_line_load(beam, force_per_length=(0, np.nan, 0))
    with pytest.raises(bs.InputError, match="Beam of this model"):
        model.add_line_load(bs.Model(), force_per_length=(0, 0, 1))
    with pytest.raises(bs.InputError, match="scale"):
        model.add_line_load(beam, force_per_length=(0, 0, 1), scale=2.0)
    quad = bs.Model()
    b3 = quad.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), beam.section, element="se3-3")
    with pytest.raises(bs.InputError, match="two-node"):
        quad.add_line_load(b3, force_per_length=(0, 0, 1))


def test_line_loads_drive_arc_length_and_step_zero():
    """The path-following rate and the step-0 check see line loads (System.load_factors, loads_act)."""
    model, beam = _cantilever(16, 6.0 * EI)
    ref = bs.solve(model, steps=6).position(beam.last)
    model, beam = _cantilever(16, 6.0 * EI)
    arc = bs.solve(model, steps=6, path="arc-length")
    assert arc.times[-1] == pytest.approx(1.0) and np.allclose(arc.position(beam.last), ref, atol=1e-9)
    model, beam = _cantilever(4, 1e-4)
    model.line_loads[0].scale = lambda t: 1.0           # acting already at t_start: step 0 is solved
    sol = bs.solve(model, steps=1)
    assert sol.stats[0]["iterations"] > 0 and sol.position(beam.last, step=0)[2] < -1e-6


@pytest.mark.parametrize("follower", [False, True])
@pytest.mark.parametrize("scale", [0.0, 1e-7, 0.6, 2.9])
def test_compiled_loads_and_stiffness_are_the_numpy_forms_to_round_off(scale, follower):
    """``line_load_jit`` (the default) against the numpy form: same formulas, the same complex steps; element
    twists from zero (series of every coefficient) to near pi (closed forms)."""
    rng = np.random.default_rng(7)
    n = 40
    HA = se3.exp(rng.normal(size=(n, 6)))
    w = rng.normal(size=(n, 6))
    w[:, 3:] *= (scale / np.linalg.norm(w[:, 3:], axis=1))[:, None]
    HB = HA @ se3.exp(np.where(scale > 0, 1.0, 0.0) * w)
    L, q, m = rng.uniform(0.5, 2.0, n), rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    f, K = line_load.nodal_loads_and_tangent(HA, HB, L, q, m, follower)
    f1 = line_load.nodal_loads(HA, HB, L, q, m, follower)
    line_load.use_numpy(True)
    try:
        f0, K0 = line_load.nodal_loads_and_tangent(HA, HB, L, q, m, follower)
    finally:
        line_load.use_numpy(False)
    assert np.abs(f - f0).max() <= 1e-14 * np.abs(f0).max()
    assert np.abs(f1 - f0).max() <= 1e-14 * np.abs(f0).max()
    assert np.abs(K - K0).max() <= 1e-13 * np.abs(K0).max()


def test_a_line_load_scaled_to_zero_is_not_evaluated(monkeypatch):
    """``System.evaluate`` skips the rows of a line load whose scale is zero at ``t`` (the strand's P-delta load
    during the pull): no kernel call, and the residual and tangent those of the model without the load."""
    import beamsolver as bs
    from beamsolver.nonlinear.problem import Problem

    def model(with_load):
        m = bs.Model()
        b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), bs.Section.circular(0.01, 1e9))
        m.clamp(b.first)
        m.add_load(b.last, force=(0.0, 1.0, 0.0))
        if with_load:
            m.add_line_load(b, force_per_length=(0.0, 0.0, 3.0), scale=lambda t: max(t - 1.0, 0.0))
        return m
    calls = []
    tangent = line_load.nodal_loads_and_tangent
    monkeypatch.setattr(line_load, "nodal_loads_and_tangent", lambda *a, **k: calls.append(1) or tangent(*a, **k))
    problems = [Problem.from_model(model(w)) for w in (True, False)]
    H = problems[0].system.poses0 @ se3.exp(np.random.default_rng(3).normal(scale=1e-2, size=(5, 6)))
    e1, e0 = (p.evaluate(H, 0.5, tangent=True) for p in problems)
    assert not calls
    assert np.array_equal(e1.r, e0.r) and np.array_equal(e1.kvals, e0.kvals)
    problems[0].evaluate(H, 1.5, tangent=True)
    assert calls
