"""A user contribution added with ``Model.add_contribution``, written only against the public protocol.

``GroundSprings`` is a linear spring ``k (x - x_0)`` from each of its nodes to the
node's reference position (a Winkler foundation lumped at nodes).  A spring at the
tip of a cantilever works in parallel with it: the tip deflection under a small
tip force ``P`` is ``P / (k + 1 / (L^3 / 3 EI + L / GA))`` (Timoshenko cantilever).
The assembled tangent is checked against central differences and Newton's rate
on it is quadratic.  Bad contributions are refused at ``solve`` with ``InputError``.
"""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver import geometry
from beamsolver.blocks import Blocks
from beamsolver.nonlinear.problem import Problem
from beamsolver.se3 import skew

from helpers import rel_err
from helpers import assert_quadratic

EI, GA, L = 2.0, 50.0, 1.0


class GroundSprings:
    """Springs ``k (x - x0)`` to the reference positions of ``nodes``; blocks over one node each,
    in its body increments (``x <- x + R u``, ``R <- R exp(hat(w))``)."""
    name = "foundation"

    def __init__(self, model, nodes, k):
        self.nodes = np.atleast_1d(np.asarray(nodes))
        self.x0 = model.poses0[self.nodes, :3, 3].copy()
        self.k = float(k)

    def evaluate(self, H, tangent=True):
        R = H[self.nodes, :3, :3]
        g = np.einsum("nji,nj->ni", R, self.k * (H[self.nodes, :3, 3] - self.x0))    # R^T k (x - x0)
        f = np.zeros((len(self.nodes), 6))
        f[:, :3] = g
        K = None
        if tangent:
            K = np.zeros((len(self.nodes), 6, 6))
            K[:, :3, :3] = self.k * np.eye(3)
            K[:, :3, 3:] = skew(g)                   # d(exp(-hat(w)) R^T g)/dw = hat(R^T g)
        return Blocks(self.nodes[:, None], f, K)


def _cantilever(n=8, P=1e-4, k=5.0):
    sec = bs.Section(EA=1e4, GA2=GA, GA3=GA, GJ=1.5, EI2=EI, EI3=EI, radius=0.01)
    m = bs.Model()
    b = m.add_beam(geometry.straight((0, 0, 0), (L, 0, 0), n), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(0, P, 0))
    return m, b


def test_tip_spring_in_parallel_with_a_cantilever():
    """Same mesh: the tip flexibility ``c`` of the free cantilever gives ``P / (k + 1 / c)`` to
    round-off (linear range, ``P L^2 / EI = 5e-5``); the closed form to the element's O(h^2)
    discretisation error (0.35 % on 8 elements for the free cantilever)."""
    P, k = 1e-4, 5.0
    m, b = _cantilever(P=P, k=k)
    springs = m.add_contribution(GroundSprings(m, [b.last], k))
    assert m.contributions == [springs]
    sol = bs.solve(m, steps=1, rtol=1e-12)
    tip = sol.poses[-1][b.last, 1, 3]
    c = bs.solve(_cantilever(P=P)[0], steps=1, rtol=1e-12).poses[-1][b.last, 1, 3] / P
    assert abs(tip - P / (k + 1.0 / c)) < 1e-6 * tip, (tip, P / (k + 1.0 / c))
    assert abs(tip - P / (k + 1.0 / (L**3 / (3 * EI) + L / GA))) < 5e-3 * tip
    assert abs(tip - P * c) > 0.5 * tip                     # the spring carries most of the load
    assert "foundation" in sol.stats[-1]["timings"]


def test_assembled_tangent_matches_finite_differences_and_newton_is_quadratic():
    m, b = _cantilever(n=6, P=0.5, k=3.0)
    m.add_contribution(GroundSprings(m, b.nodes[2:], 3.0))
    problem = Problem.from_model(m)
    assert [c.name for c in problem.contributions] == ["foundation"]
    system = problem.system
    rng = np.random.default_rng(1)
    H = system.update(system.poses0, 0.2 * rng.standard_normal((system.n_nodes, 6)))
    K = problem.tangent(problem.evaluate(H, 1.0)).toarray()
    free, eps = system.free_dofs, 1e-6
    fd = np.zeros_like(K)
    for j, dof in enumerate(free):
        dz = np.zeros((system.n_nodes, 6))
        dz.flat[dof] = eps
        rp = problem.evaluate(problem.update(H, dz), 1.0, tangent=False).r
        rm = problem.evaluate(problem.update(H, -dz), 1.0, tangent=False).r
        fd[:, j] = (rp[free] - rm[free]) / (2 * eps)
    assert rel_err(K, fd) < 1e-6, rel_err(K, fd)
    # a large load (tip turned by ~0.3 rad): the solver's residual history is quadratic
    sol = bs.solve(m, steps=1, rtol=1e-13)
    assert sol.stats[-1]["cutbacks"] == 0 and len(sol.stats[-1]["residuals"]) >= 4
    assert_quadratic(sol.stats[-1]["residuals"])


class _NoEvaluate:
    nodes = [1]


class _BadNodes:
    nodes = [99]

    def evaluate(self, H, tangent=True):
        return None


class _WrongReturn:
    nodes = [1]

    def evaluate(self, H, tangent=True):
        return np.zeros(6)


class _NoTangent(GroundSprings):
    def evaluate(self, H, tangent=True):
        return Blocks(super().evaluate(H, False).nodes, super().evaluate(H, False).f)


class _OtherNodes(GroundSprings):
    def evaluate(self, H, tangent=True):
        out = super().evaluate(H, tangent)
        return Blocks(out.nodes + 1, out.f, out.K)


@pytest.mark.parametrize("make, match", [
    (lambda m, b: _NoEvaluate(), r"add_contribution no\. 0 \(_NoEvaluate\): has no method evaluate"),
    (lambda m, b: object(), r"\(object\): has no attribute 'nodes'"),
    (lambda m, b: _BadNodes(), r"node 99 is not a node of the model"),
    (lambda m, b: _WrongReturn(), r"evaluate must return blocks\.Blocks.*got ndarray"),
    (lambda m, b: _NoTangent(m, [b.last], 1.0), r"returned blocks without K"),
    (lambda m, b: _OtherNodes(m, [b.nodes[2]], 1.0), r"its blocks use node 3, not one of its nodes"),
])
def test_bad_contributions_are_refused_at_solve(make, match):
    m, b = _cantilever(n=4)
    m.add_contribution(make(m, b))
    with pytest.raises(bs.InputError, match=match):
        bs.solve(m, steps=1)


def test_names_are_made_unique_and_life_cycle_defaults():
    m, b = _cantilever(n=4)
    m.add_contribution(GroundSprings(m, [b.last], 1.0))
    m.add_contribution(GroundSprings(m, [b.nodes[2]], 1.0))
    problem = Problem.from_model(m)
    assert problem.timing_names == ("contact", "foundation", "foundation_2")
    assert problem.smooth and problem.conservative and problem.get_state() == {}
    H = problem.system.poses0
    problem.begin_step(H, 0.0)
    assert not problem.repeat_step(H) and problem.unmet(1.0) is None and problem.commit(H) is None


class _NaNForces(GroundSprings):
    def evaluate(self, H, tangent=True):
        out = super().evaluate(H, tangent)
        out.f[:] = np.nan
        return out


def test_non_finite_forces_of_a_contribution_are_named():
    m, b = _cantilever(n=4)
    m.add_contribution(_NaNForces(m, [b.last], 1.0))
    with pytest.raises(bs.InputError, match=r"forces of contribution 'foundation' are not finite at nodes \[4\]"):
        bs.solve(m, steps=1)
