"""The Problem interface: contributions as local blocks through the generic assembler.

A linear spring between the positions of two nodes, written as 2-node blocks
(``blocks.Contribution``), is assembled by ``System.assemble_blocks`` through
joins and global-type (partially fixed) nodes; its reduced tangent is checked
against central differences of the Problem's residual.  The generic assembler is
checked equal to the element path of ``System.evaluate`` (same transforms), and
the solver's modules are checked to know nothing of contact.
"""
import io
import tokenize
from pathlib import Path

import numpy as np
import pytest

import beamsolver as bs
from beamsolver import geometry
from beamsolver.elements import element
from beamsolver.assembly.system import System
from beamsolver.blocks import Blocks, Contribution
from beamsolver.nonlinear.problem import Problem
from beamsolver.se3 import skew

from helpers import rel_err

PACKAGE = Path(__file__).resolve().parents[2] / "beamsolver"


class Spring(Contribution):
    """``k (x_a - x_b - d0)`` between the positions of node pairs ``(a, b)``, as blocks in the
    nodes' body increments (``x <- x + R u``, ``R <- R exp(hat(w))``)."""
    name = "spring"

    def __init__(self, pairs, k, d0):
        self.pairs, self.k, self.d0 = np.asarray(pairs), float(k), np.asarray(d0, dtype=float)
        self.begun, self.committed, self.repeats = [], [], 0

    def evaluate(self, H, tangent=True):
        a, b = self.pairs[:, 0], self.pairs[:, 1]
        Ra, Rb = H[a, :3, :3], H[b, :3, :3]
        g = self.k * (H[a, :3, 3] - H[b, :3, 3] - self.d0)
        ga, gb = np.einsum("nji,nj->ni", Ra, g), np.einsum("nji,nj->ni", Rb, g)
        m = len(a)
        f = np.zeros((m, 12))
        f[:, 0:3], f[:, 6:9] = ga, -gb
        K = None
        if tangent:
            K = np.zeros((m, 12, 12))
            RaT, RbT = np.swapaxes(Ra, 1, 2), np.swapaxes(Rb, 1, 2)
            K[:, 0:3, 0:3] = self.k * RaT @ Ra
            K[:, 0:3, 6:9] = -self.k * RaT @ Rb
            K[:, 6:9, 0:3] = -self.k * RbT @ Ra
            K[:, 6:9, 6:9] = self.k * RbT @ Rb
            K[:, 0:3, 3:6] = skew(ga)            # d(R^T g)/dw = hat(R^T g)
            K[:, 6:9, 9:12] = -skew(gb)
        return Blocks(self.pairs, f, K), dict(n=m)

    def begin_step(self, H, t):
        self.begun.append(t)

    def repeat_step(self, H):
        self.repeats += 1
        return self.repeats == 1           # one outer iteration, then accept

    def commit(self, H):
        self.committed.append(H.copy())

    def results(self, H):
        return dict(spring_force=self.evaluate(H, False)[0].f[:, :3].copy())


def _section():
    return bs.Section(EA=1e3, GA2=4e2, GA3=5e2, GJ=20.0, EI2=30.0, EI3=40.0, radius=0.05)


def _model():
    """Beam 1 clamped; beam 2 with a partial fix (a global-type node) at its first node, joined
    rigidly at its end to an extra node (a transformed member); springs between the beams."""
    m = bs.Model()
    b1 = m.add_beam(geometry.arc(radius=1.0, angle=1.0, n_elements=3), _section())
    b2 = m.add_beam(geometry.straight((0.2, 0.5, 0.3), (1.2, 0.6, 0.1), 3), _section())
    m.clamp(b1.first)
    m.fix(b2.first, ("ux", "uy", "rz"))
    extra = m.add_beam(geometry.straight((1.2, 0.6, 0.1), (1.5, 0.9, 0.1), 1), _section())
    m.join(b2.last, extra.first)
    return m, b1, b2, extra


def _state(system, seed=0, size=0.1):
    rng = np.random.default_rng(seed)
    dz = size * rng.standard_normal((system.n_nodes, 6))
    return system.update(system.poses0, dz)


def _problem(k=7.0):
    m, b1, b2, extra = _model()
    system = System(m, check_rigid_modes=False)
    pairs = [(b1.last, extra.first), (b1.nodes[1], b2.first), (b1.nodes[2], extra.last)]
    spring = Spring(pairs, k, d0=(0.05, -0.02, 0.01))
    return Problem(system, [spring]), spring


def test_spring_blocks_tangent_matches_finite_differences_through_joins_and_global_nodes():
    problem, _ = _problem()
    system = problem.system
    assert system.kind[system.global_nodes].size and system.members.size   # both transforms occur
    H = _state(system)
    ev = problem.evaluate(H, 1.0)
    K = problem.tangent(ev).toarray()
    free = system.free_dofs
    Kf = problem.full_tangent(ev).toarray()[np.ix_(free, free)]
    assert np.abs(K - Kf).max() <= 1e-14 * np.abs(K).max()
    fd = np.zeros_like(K)
    eps = 1e-6
    for j, dof in enumerate(free):
        dz = np.zeros(6 * system.n_nodes)
        dz[dof] = eps
        rp = problem.evaluate(problem.update(H, dz.reshape(-1, 6)), 1.0, tangent=False).r
        rm = problem.evaluate(problem.update(H, -dz.reshape(-1, 6)), 1.0, tangent=False).r
        fd[:, j] = (rp[free] - rm[free]) / (2 * eps)
    assert rel_err(K, fd) < 1e-6, rel_err(K, fd)
    # the spring matters: without it the tangent misses a part the differences see
    K0 = Problem(system, []).tangent(Problem(system, []).evaluate(H, 1.0)).toarray()
    assert rel_err(K0, fd) > 1e-4


def test_generic_assembler_equals_the_element_path():
    """Element blocks (``k = 2``) through ``assemble_blocks`` give the residual and tangent of
    ``System.evaluate``'s own element transforms and scatter (no loads)."""
    m, *_ = _model()
    system = System(m, check_rigid_modes=False)
    H = _state(system, seed=3)
    r, kvals, info = system.evaluate(H, np.zeros(0))
    f, K, _ = element.evaluate(H[system.enodes[:, 0]], H[system.enodes[:, 1]], system.L, system.eps0,
                                  system.C, True)
    rb, coo, fl, ml = system.assemble_blocks(H, Blocks(system.enodes, f, K))
    np.testing.assert_allclose(rb, r, rtol=0, atol=1e-13 * np.abs(r).max())
    # both carry the global-node term -hat(r) of the elements' residual (assembly module docstring)
    import scipy.sparse as sp
    n = 6 * system.n_nodes
    Kb = sp.coo_matrix((coo[2], (np.ravel(coo[0]), np.ravel(coo[1]))), shape=(n, n)).toarray()
    Ke = system.full_matrix(kvals).toarray()
    free = system.free_dofs
    assert np.abs(Kb - Ke)[np.ix_(free, free)].max() <= 1e-12 * np.abs(Ke).max()
    assert fl > 0 and ml > 0


def test_blocks_of_any_size_and_bad_shapes():
    m, b1, b2, extra = _model()
    system = System(m, check_rigid_modes=False)
    H = system.poses0
    nodes = np.array([[b1.last, b2.first, extra.last]])          # k = 3: an 18 x 18 block
    f = np.arange(18.0)[None]
    r, coo, _, _ = system.assemble_blocks(H, Blocks(nodes, f, np.eye(18)[None]))
    assert len(coo[2]) == 324 + 18 and np.isfinite(r).all()     # + the global node's 6 x 3 term
    with pytest.raises(ValueError, match="Blocks"):
        Blocks(nodes, np.zeros((1, 12)))


def test_life_cycle_outer_iteration_commit_and_globalisation():
    """``solve`` drives a contribution only through the Problem: begin, the outer iteration
    (one re-solve), commit with the step's record; a smooth contribution keeps the damped Newton."""
    problem, spring = _problem(k=50.0)
    assert problem.smooth and problem.conservative
    assert Problem(problem.system, []).get_state() == {} and problem.timing_names == ("contact", "spring")
    from beamsolver.driver import Convergence, Newton
    from beamsolver.stepping.steps import Run
    newton = Newton(problem, Convergence(), True, None)
    grid = np.linspace(0.0, 1.0, 3)
    run = Run(problem, newton, None, grid, 1e-3, False, dict(advice=lambda *a: ""))
    run.start(None, None)
    run.loop()
    sol = run.finish()
    assert spring.begun == [0.5, 1.0] and len(spring.committed) == 2
    assert sol.stats[1]["augmentations"] == 1 and "spring" in sol.stats[1]["timings"]
    # the record of the step is the contribution's results; equilibrium holds with the spring in
    assert sol.contacts[-1]["spring_force"].shape == (3, 3)
    ev = problem.evaluate(sol.poses[-1], 1.0)
    assert np.abs(ev.r[problem.system.free_dofs]).max() <= 1e-8 * max(ev.f_level, ev.m_level)


def test_outer_iterations_are_bounded():
    """A contribution that always asks to re-solve the step: a typed failure after MAX_OUTER."""
    from beamsolver import failures
    from beamsolver.stepping import steps as stepping
    from beamsolver.errors import ConvergenceError
    from beamsolver.driver import Convergence, Newton
    problem, spring = _problem(k=50.0)
    spring.repeat_step = lambda H: True
    run = stepping.Run(problem, Newton(problem, Convergence(), True, None), None, np.linspace(0.0, 1.0, 2),
                       1e-3, False, dict(advice=lambda *a: ""))
    run.start(None, None)
    with pytest.raises(ConvergenceError) as err:
        run.loop()
    assert isinstance(err.value.failure, failures.AugmentationFailed) and "MAX_OUTER" in str(err.value)


def _names(path):
    toks = tokenize.generate_tokens(io.StringIO(path.read_text()).readline)
    return {t.string for t in toks if t.type == tokenize.NAME}


@pytest.mark.parametrize("module", ["driver.py", "nonlinear/newton.py", "nonlinear/convergence.py", "nonlinear/rotations.py",
                                    "stepping/steps.py"])
def test_solver_knows_nothing_of_contact(module):
    """No import of, and no name containing, contact (``Solution.contact_state`` is the Solution's field,
    the history of any contribution)."""
    names = _names(PACKAGE / module) - {"contact_state"}
    assert not [n for n in names if "contact" in n.lower()]
    src = (PACKAGE / module).read_text()
    assert "from .contact" not in src and "beamsolver.contact" not in src


def _pair_on_a_plate(n=3, R=0.5e-3, L=4e-3, depth=0.1):
    """Two touching wires, ``a`` joined at its top to a plate node with a partial fix (global-type),
    ``b`` clamped at both ends: the contact pairs of the top elements load the plate; the wires
    pressed together by ``depth R`` at their interior nodes."""
    sec = bs.Section.circular(radius=R, E=200e9)
    m = bs.Model()
    a = m.add_beam(geometry.straight((R, 0, 0), (R, 0, L), n), sec)
    b = m.add_beam(geometry.straight((-R, 0, 0), (-R, 0, L), n), sec)
    m.clamp(a.first)
    m.clamp(b.first)
    plate = m.add_node((0.0, 0.0, L))
    m.join(plate, a.last, rigid=True)
    m.clamp(b.last)
    m.fix(plate, ("ux", "uy", "rx"))
    m.add_contact(a, b)
    problem = Problem.from_model(m)
    system = problem.system
    dz = np.zeros((system.n_nodes, 6))
    dz[a.nodes[1:-1], 0], dz[b.nodes[1:-1], 0] = -depth * R, depth * R
    dz[plate, 5] = 0.05                                      # and the plate turned a little
    H = system.update(system.poses0, dz)
    problem.begin_step(H, 0.0)
    return problem, H, plate


def test_contact_tangent_at_a_global_type_node_matches_finite_differences(monkeypatch):
    """The contact blocks' global-node term (docs/theory.md eq. 10.3): without it the columns of the
    plate's rotation miss the contact forces carried by the plate (the path before the Problem)."""
    problem, H, plate = _pair_on_a_plate()
    system = problem.system
    ev = problem.evaluate(H, 0.0)
    assert ev.details["contact"]["n_active"] > 0
    free = system.free_dofs
    cols = np.flatnonzero(free // 6 == plate)                 # the plate's free unknowns
    eps = 1e-7
    fd = np.zeros((len(free), len(cols)))
    for j, c in enumerate(cols):
        dz = np.zeros(6 * system.n_nodes)
        dz[free[c]] = eps * (1e-3 if free[c] % 6 < 3 else 1.0)
        rp = problem.evaluate(problem.update(H, dz.reshape(-1, 6)), 0.0, tangent=False).r
        rm = problem.evaluate(problem.update(H, -dz.reshape(-1, 6)), 0.0, tangent=False).r
        fd[:, j] = (rp[free] - rm[free]) / (2 * dz[free[c]])
    K = problem.tangent(ev).toarray()[:, cols]
    assert rel_err(K, fd) < 1e-5, rel_err(K, fd)
    monkeypatch.setattr(System, "_global_node_terms", staticmethod(lambda r, g: (np.zeros(0, int),) * 2
                                                                   + (np.zeros(0),)))
    K_without = problem.tangent(problem.evaluate(H, 0.0)).toarray()[:, cols]
    assert rel_err(K_without, fd) > 10 * rel_err(K, fd), (rel_err(K_without, fd), rel_err(K, fd))


def test_problem_owns_the_contact_contribution():
    """``System`` knows elements, loads and constraints only; ``Problem.from_model`` builds contact and
    shows it read-only as ``Problem.contact`` (``None`` without contact)."""
    from beamsolver.contact.system import ContactSystem
    m, b1, b2, extra = _model()
    assert Problem.from_model(m, check_rigid_modes=False).contact is None
    m.add_contact(b2, b1)
    problem = Problem.from_model(m, check_rigid_modes=False)
    assert isinstance(problem.contact, ContactSystem) and problem.contributions == [problem.contact]
    assert problem.contact.sys is problem.system and not hasattr(problem.system, "contact")
    with pytest.raises(AttributeError):
        problem.contact = None
    assert Problem(problem.system).contributions == []
    assert "contact" not in _names(PACKAGE / "assembly" / "system.py") - {"contacts", "in_contact"}


class _Counter(Contribution):
    """No forces; a committed count under the key ``n`` (the same key in every instance)."""

    def __init__(self, name):
        self.name, self.n = name, 0

    def evaluate(self, H, tangent=True):
        return Blocks.empty(1, tangent), {}

    def commit(self, H):
        self.n += 1

    def get_state(self):
        return dict(n=np.array(self.n))

    def set_state(self, state):
        self.n = int(state["n"])


def test_state_of_contributions_with_equal_keys_is_kept_apart():
    m, *_ = _model()
    system = System(m, check_rigid_modes=False)
    a, b = _Counter("a"), _Counter("b")
    problem = Problem(system, [a, b])
    problem.commit(system.poses0)
    a.commit(system.poses0)
    state = problem.get_state()
    assert set(state) == {"a/n", "b/n"} and (int(state["a/n"]), int(state["b/n"])) == (2, 1)
    a2, b2 = _Counter("a"), _Counter("b")
    Problem(system, [a2, b2]).set_state(state)
    assert (a2.n, b2.n) == (2, 1)
