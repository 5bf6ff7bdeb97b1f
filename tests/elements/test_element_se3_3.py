"""The three-node element ``"se3-3"`` (``elements.se3_3``) and the element contract it proves.

Forces against the energy and the tangent against the forces by central differences on the
group; the series tangent operator against the closed form; constant strain (roll-up, helix)
exact to round-off; frame invariance; a cantilever converging to the two-node element's answer
under refinement, with its rate; quadratic Newton; a model mixing two- and three-node beams
(assembled tangent, output).
"""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver import elements, geometry, se3
from beamsolver.elements.se3_3 import shape, strain_jets
from beamsolver.errors import InputError

from helpers import random_pose, rel_err, spd_matrix

T3 = elements.get("se3-3")
SEC = bs.Section(EA=1e3, GA2=4e2, GA3=5e2, GJ=20.0, EI2=30.0, EI3=40.0, radius=0.05)


def _elements(rng, n=3, full=True):
    """Reference poses of ``n`` curved, twisted 3-node elements, ``C`` and a deformed state."""
    P = geometry.helix(0.4, 1.5, 3.0, 8)[:2 * n + 1]
    P0 = np.stack([P[2 * i:2 * i + 3] for i in range(n)])
    C = np.stack([spd_matrix(rng) if full else SEC.C for _ in range(n)])
    ref = T3.reference(P0, C)
    H = P0 @ se3.exp(0.2 * rng.standard_normal((n, 3, 6)))
    return P0, ref, H


def _perturbed(H, j, e):
    q = np.zeros((len(H), 18))
    q[:, j] = e
    return H @ se3.exp(q.reshape(len(H), 3, 6))


def test_series_tangent_equals_closed_form(rng):
    """``k = T(phi) phi'`` by the series equals the closed-form right tangent of ``se3``."""
    h1, h2 = 2.0 * rng.standard_normal((2, 5, 6))
    for s in (0.0, 0.21, 0.5, 1.0):
        n1, n2, d1, d2 = shape(s)
        k = strain_jets(h1, h2, s, order=0)[0]
        expected = np.einsum("nij,nj->ni", se3.tangent(n1 * h1 + n2 * h2), d1 * h1 + d2 * h2)
        assert np.abs(k - expected).max() < 1e-13 * np.abs(expected).max()


def test_strain_jets_are_the_derivatives(rng):
    h1, h2 = rng.standard_normal((2, 4, 6))
    k, kd, kdd = strain_jets(h1, h2, 0.3)
    x, eps = np.concatenate([h1, h2], axis=1), 1e-6
    for a in range(12):
        dx = np.zeros(12)
        dx[a] = eps
        p = strain_jets((x + dx)[:, :6], (x + dx)[:, 6:], 0.3, order=1)
        m = strain_jets((x - dx)[:, :6], (x - dx)[:, 6:], 0.3, order=1)
        assert rel_err(kd[:, a], (p[0] - m[0]) / (2 * eps)) < 1e-8
        assert rel_err(kdd[:, a], (p[1] - m[1]) / (2 * eps)) < 1e-8


@pytest.mark.parametrize("full", [False, True])
def test_forces_are_the_energy_gradient_and_tangent_their_derivative(rng, full):
    """Central differences perturbing on the group, ``H_i exp(hat(q_i))``."""
    P0, ref, H = _elements(rng, full=full)
    f, K, _ = T3.evaluate(H, None, ref, True)
    g_fd, K_fd, e = np.zeros_like(f), np.zeros_like(K), 1e-6
    for j in range(18):
        Hp, Hm = _perturbed(H, j, e), _perturbed(H, j, -e)
        g_fd[:, j] = (T3.energy(Hp, None, ref) - T3.energy(Hm, None, ref)) / (2 * e)
        K_fd[:, :, j] = (T3.evaluate(Hp, None, ref, False)[0] - T3.evaluate(Hm, None, ref, False)[0]) / (2 * e)
    assert rel_err(f, g_fd) < 1e-8
    assert rel_err(K, K_fd) < 1e-7
    # the geometric part is not negligible here: without it the check fails
    assert np.abs(f).max() > 1.0


def test_reference_is_stress_free_and_invariant_under_rigid_motion(rng):
    P0, ref, H = _elements(rng)
    f0, _, s0 = T3.evaluate(P0, None, ref, False)
    assert np.abs(f0).max() < 1e-11 and np.abs(s0.sigma).max() < 1e-11
    f, K, s = T3.evaluate(H, None, ref, True)
    G = random_pose(rng, angle=2.5, scale=3.0)
    f2, K2, s2 = T3.evaluate(G @ H, None, ref, True)
    # body-frame forces and tangent do not see a rigid motion of all nodes
    assert rel_err(f2, f) < 1e-12 and rel_err(K2, K) < 1e-12 and rel_err(s2.sigma, s.sigma) < 1e-12


def test_helix_is_constant_strain_exactly():
    """Nodes on a helix (curvature and twist): the Gauss-point strains and the interpolated
    poses are those of the helix to round-off, with 0.3 turns (1.9 rad) per element."""
    R, pitch, length = 0.3, 0.5, 0.6
    P = geometry.helix(radius=R, pitch=pitch, length=length, n_elements=8)    # 4 three-node elements
    P0 = np.stack([P[2 * i:2 * i + 3] for i in range(4)])
    ref = T3.reference(P0, np.broadcast_to(SEC.C, (4, 6, 6)))
    h = se3.log(se3.relative(P[0], P[2]))
    exact = h / np.linalg.norm(h[:3])                      # the helix' constant strain per arc length
    assert np.abs(ref.data["eps0"] - exact).max() < 1e-13
    fine = geometry.helix(radius=R, pitch=pitch, length=length, n_elements=32)
    xi = np.arange(8) / 8.0
    pts = T3.interpolate(P0, np.repeat(np.arange(4), 8), np.tile(xi, 4))
    assert np.abs(pts - fine[:-1]).max() < 1e-13


def test_roll_up_is_exact_with_two_elements():
    """A cantilever under an end moment rolls up onto a circle: exact with two 3-node elements."""
    EI, L = SEC.C[5, 5], 2.0
    m = bs.Model()
    b = m.add_beam(geometry.straight((0, 0, 0), (L, 0, 0), 4), SEC, element="se3-3")
    m.clamp(b.first)
    moment = 1.5 * np.pi * EI / L               # turns the tip by 1.5 pi
    m.add_load(b.last, moment=(0.0, 0.0, moment))
    sol = bs.solve(m, steps=6)
    k = moment / EI
    exact = np.array([np.sin(k * L) / k, (1.0 - np.cos(k * L)) / k, 0.0])
    assert np.abs(sol.position(b.last) - exact).max() < 1e-12 * L
    np.testing.assert_allclose(sol.section_forces[-1][:, 5], moment, rtol=1e-12)


def _cantilever_tip(n_elements, element):
    """Tip position of a clamped straight cantilever under a dead tip force (large deflection)."""
    m = bs.Model()
    k = elements.get(element).n_nodes - 1
    b = m.add_beam(geometry.straight((0, 0, 0), (1.0, 0, 0), k * n_elements), SEC, element=element)
    m.clamp(b.first)
    m.add_load(b.last, force=(0.0, 60.0, 40.0), moment=(2.0, 0.0, 0.0))
    sol = bs.solve(m, steps=4, rtol=1e-12)
    return sol.position(b.last)


@pytest.fixture(scope="module")
def cantilever():
    ns = [1, 2, 4, 8]
    tips3 = {n: _cantilever_tip(n, "se3-3") for n in ns}
    tips2 = {n: _cantilever_tip(n, "se3-2") for n in (32, 64)}
    return ns, tips3, tips2


def test_cantilever_converges_to_the_two_node_answer(cantilever):
    """Under refinement both elements reach the same tip; the 3-node error falls as h^4
    (measured rate in ``benchmarks/element_convergence.py``)."""
    ns, tips3, tips2 = cantilever
    # the two-node element converges as h^2: Richardson from 32 and 64 elements
    ref = tips2[64] + (tips2[64] - tips2[32]) / 3.0
    err3 = np.array([np.linalg.norm(tips3[n] - ref) for n in ns])
    assert err3[-1] < 1e-6, err3
    rate = -np.polyfit(np.log(ns), np.log(err3), 1)[0]
    assert rate > 3.5, (rate, err3)          # measured 3.9: h^4
    # at equal unknowns (8 three-node vs 16 two-node elements) the three-node element is closer
    assert err3[-1] < np.linalg.norm(_cantilever_tip(16, "se3-2") - ref)


def test_newton_is_quadratic():
    m = bs.Model()
    b = m.add_beam(geometry.arc(radius=1.0, angle=1.2, n_elements=6), SEC, element="se3-3")
    m.clamp(b.first)
    m.add_load(b.last, force=(3.0, -5.0, 7.0), moment=(1.0, 2.0, -4.0))
    res = []
    bs.solve(m, steps=1, rtol=1e-13, callback=lambda i: res.append(i["residual"]))
    r = np.array([x for x in res if x > 0])
    pairs = [(a, c) for a, c in zip(r[:-1], r[1:]) if 1e-11 < c and a < 1e-2]
    assert pairs, r
    assert all(c < 50.0 * a**2 + 1e-12 for a, c in pairs), r


def _mixed_model():
    """A two-node and a three-node beam joined at an angle, with a partial fix (transformed unknowns)."""
    m = bs.Model()
    b1 = m.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), 3), SEC)
    b2 = m.add_beam(geometry.arc(radius=0.8, angle=1.0, n_elements=4, origin=(1, 0, 0)), SEC, element="se3-3")
    b3 = m.add_beam(geometry.straight((1, 0, 0), (1.2, 0.8, 0.5), 2), SEC)
    m.join(b1.last, b2.first)
    m.join(b1.last, b3.first)
    m.clamp(b1.first)
    m.fix(b2.last, ("uz", "rx"))
    m.add_load(b2.last, force=(1.0, -2.0, 3.0), moment=(0.3, 0.2, -0.1))
    m.add_load(b2.nodes[1], force=(0.0, 0.0, -2.0), follower=True)
    m.add_load(b3.last, force=(0.5, 0.0, 1.0))
    return m, b1, b2, b3


def test_mixed_model_assembled_tangent_is_the_residual_derivative():
    from helpers import check_tangent as _check_tangent
    m, b1, b2, b3 = _mixed_model()
    system, K, fd = _check_tangent(m, seed=4)
    assert [g.element_type.name for g in system.groups] == ["se3-2", "se3-3"]
    assert system.group_edofs[1].shape == (2, 18)
    np.testing.assert_array_equal(system.groups[1].elements, b2.elements)


def test_mixed_model_solves_and_draws(tmp_path):
    m, b1, b2, b3 = _mixed_model()
    sol = bs.solve(m, steps=2, output=tmp_path)
    assert sol.section_forces[-1].shape == (m.n_elements, 6)
    d = sol.description
    assert d["beam_element"].tolist() == ["se3-2", "se3-3", "se3-2"]
    from beamsolver.io.lines import LineLayout
    lay = LineLayout(d, refine=4)
    P = lay.poses(sol.poses[-1])
    # points of the 3-node beam are its own interpolation; its nodes are among them
    for node in b2.nodes:
        assert np.abs(P[:, :3, 3] - sol.position(node)).sum(axis=1).min() < 1e-12
    # node fields run piecewise linear through all nodes of an element: the mid node's value at xi = 1/2
    F = lay.node_field(np.arange(m.n_nodes, dtype=float)[:, None] ** 2)
    at = lay.point_index[(lay.point_el == b2.elements[1]) & (lay.point_xi == 0.5)]
    assert F[at, 0].tolist() == [float(b2.nodes[3]) ** 2]
    loaded = bs.load(tmp_path)
    np.testing.assert_array_equal(LineLayout(loaded.description, refine=4).poses(loaded.poses[-1]), P)


def test_model_input_errors():
    m = bs.Model()
    with pytest.raises(InputError, match="se3-3.*2 m \\+ 1 node poses.*got 4"):
        m.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), 3), SEC, element="se3-3")
    with pytest.raises(InputError, match="element must be one of"):
        m.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), 2), SEC, element="quadratic")
    b = m.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), 2), SEC, element="se3-3")
    c = m.add_beam(geometry.straight((0, 0.2, 0), (1, 0.2, 0), 2), SEC)
    with pytest.raises(InputError, match="two-node elements only"):
        m.add_contact(b, c)


def test_rotation_limit_of_the_type_stops_the_solver():
    """One 3-node element asked to roll up by more than MAX_ELEMENT_ROTATION is refused."""
    m = bs.Model()
    b = m.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), 2), SEC, element="se3-3")
    m.clamp(b.first)
    m.add_load(b.last, moment=(0.0, 0.0, 1.2 * np.pi * SEC.C[5, 5]))
    with pytest.raises(bs.ConvergenceError, match="MAX_ELEMENT_ROTATION"):
        bs.solve(m, steps=4, min_step_ratio=2.0**-4)


def test_a_step_through_pi_of_the_mid_pair_is_refused():
    """The continuity check reads every logarithm pair of the type: a 3-node element whose
    mid node turns from 0.7 pi to 1.3 pi within one step is refused, naming the element."""
    from beamsolver import driver as solver
    from beamsolver.failures import RotationLimit
    m = bs.Model()
    bs_ = [m.add_beam(geometry.straight((0, y, 0), (1, y, 0), 2), SEC, element="se3-3") for y in (0.0, 1.0)]
    for b in bs_:
        m.clamp(b.first)
    from beamsolver.nonlinear.problem import Problem
    newton = solver.Newton(Problem.from_model(m), solver.Convergence(), True, None)

    def poses(angle):
        H = m.poses0.copy()
        H[4, :3, :3] = se3.exp_so3([0.0, 0.0, angle])        # mid node of the second element
        return H
    assert len(newton.sys.rotation_pairs) == 4
    newton.check_continuity(poses(0.7 * np.pi), poses(0.75 * np.pi))
    with pytest.raises(RotationLimit, match="element 1 .*may have passed pi"):
        newton.check_continuity(poses(0.7 * np.pi), poses(1.3 * np.pi))
