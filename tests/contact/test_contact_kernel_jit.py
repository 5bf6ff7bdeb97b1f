"""The compiled contact kernel (contact/kernel_jit.py) against its complex-step numpy oracle (contact/reference.py).

Random pairs of all three kinds (line, orthogonal, point), near-parallel and
crossing, stick and slip, with and without friction history, smoothing and
multipliers: forces, the exact tangent (to 1e-8 relative, measured ~1e-14) and
every point field the contact system reads.
"""
import os
import sys

import numpy as np
import pytest

import beamsolver as bs
from beamsolver import se3
from beamsolver.contact import frames, kernel_jit, reference
from helpers import TESTS, kernel_element as _element, kernel_pairs as _pairs, kernel_scene as _scene

FIELDS = ("gap", "lam_n", "active", "lam_t", "stick", "slip", "n", "t1", "t2", "xC", "xF", "xi1", "xi2",
          "F_slave", "HL", "HK", "HC", "HF")


CASES = [(f, s, m, h, e) for f in (False, True) for s in (0.0, 0.02) for m in (0.0, 3.0) for h in (False, True)
         for e in (0.005, 0.5)]


@pytest.mark.slow
@pytest.mark.parametrize("friction, smoothing, multiplier, history, elastic_slip", CASES)
def test_forces_tangent_and_fields_equal_the_oracle(friction, smoothing, multiplier, history, elastic_slip):
    seed = CASES.index((friction, smoothing, multiplier, history, elastic_slip))
    X, p = _scene(seed, friction, smoothing, multiplier, history, elastic_slip)
    f0, K0, o0 = reference.kernel_and_tangent(X, p, friction)
    f1, K1, o1 = kernel_jit.kernel_and_tangent(X, p, friction)
    assert np.abs(f1 - f0).max() <= 1e-8 * np.abs(f0).max()
    assert np.abs(K1 - K0).max() <= 1e-8 * np.abs(K0).max()
    for k in FIELDS:
        if k in o0:
            a, b = np.asarray(o0[k], float), np.asarray(o1[k], float)
            assert np.abs(b - a).max() <= 1e-8 * max(1.0, np.abs(a).max()), k
    assert set(o0) <= set(o1)
    f2, o2 = kernel_jit.contact_kernel(X, p, friction)
    assert np.array_equal(f2, f1) and np.array_equal(o2["gap"], o1["gap"])


def test_cases_cover_stick_slip_inactive_and_every_kind():
    seen = set()
    for case in CASES:
        if not case[0]:
            continue
        X, p = _scene(CASES.index(case), *case)
        _, _, o = kernel_jit.kernel_and_tangent(X, p, True)
        act = o["active"]
        seen |= {("stick", bool(s)) for s in o["stick"][act]} | {("active", bool(a)) for a in act}
        seen |= {("kind", int(k)) for k in p["kind"][act]}
    assert seen >= {("stick", True), ("stick", False), ("active", True), ("active", False),
                    ("kind", 0), ("kind", 1), ("kind", 2)}


def test_slip_is_the_se3_slip_increment_of_the_material_frames():
    X, p = _scene(7, True, 0.0, 0.0, True, 0.005)
    _, _, o = kernel_jit.kernel_and_tangent(X, p, True)
    h1 = se3.log(se3.relative(X[:, 0], X[:, 1]))
    h2 = se3.log(se3.relative(X[:, 2], X[:, 3]))
    HL = se3.compose(se3.interpolate(X[:, 0], h1, p["xi1_prev"]), p["H_CL"])
    HK = se3.compose(se3.interpolate(X[:, 2], h2, p["xi2_prev"]), p["H_FK"])
    expected = bs.contact.slip_increment(p["H_LK_prev"], se3.relative(HL, HK))
    assert np.abs(o["slip"] - expected).max() <= 1e-12 * np.abs(expected).max()
    assert np.abs(expected).max() > 1e-4


def test_tangent_is_the_derivative_of_the_forces_on_the_group():
    """Central differences of the compiled forces under body increments of each node."""
    X, p = _scene(3, True, 0.02, 0.0, True, 0.5, angles=np.array([0.1, 0.6, 1.2]))
    f, K, _ = kernel_jit.kernel_and_tangent(X, p, True)
    eps = 1e-6
    for col in (0, 4, 9, 15, 23):
        dq = np.zeros(6)
        dq[col % 6] = eps
        Xp, Xm = X.copy(), X.copy()
        Xp[:, col // 6] = X[:, col // 6] @ se3.exp(dq)
        Xm[:, col // 6] = X[:, col // 6] @ se3.exp(-dq)
        fd = (kernel_jit.contact_kernel(Xp, p)[0] - kernel_jit.contact_kernel(Xm, p)[0]).reshape(-1, 24) / (2 * eps)
        assert np.abs(fd - K[:, :, col]).max() <= 1e-5 * np.abs(K).max()


def _solve_both(build, steps):
    """Newton iterations per step and final poses with the compiled kernel and with the oracle."""
    from beamsolver.contact.system import use_numpy_kernel
    out = []
    for numpy_kernel in (False, True):
        previous = use_numpy_kernel(numpy_kernel)
        try:
            model = build()
            sol = bs.solve(model, steps=steps)
        finally:
            use_numpy_kernel(previous)
        out.append(([s.get("iterations") for s in sol.stats], sol.poses[-1]))
    return out


def test_the_kernel_is_each_contact_system_s_own():
    """``ContactSystem(system, kernel=reference)`` evaluates with the oracle while the system next to
    it keeps the compiled kernel (same blocks to round-off, no tangent buffer on the numpy path);
    ``use_numpy_kernel`` sets the kernel of systems made afterwards only."""
    import rolling
    from beamsolver.contact.system import ContactSystem, use_numpy_kernel
    from beamsolver.nonlinear.problem import Problem
    model, slave, _ = rolling.build(mu=0.5, n_elements=3)
    sol = bs.solve(model, steps=2)
    H = sol.poses[-1].copy()
    H[slave.nodes, 0, 3] += 1e-4                   # sliding a little: friction forces
    state = {k[len("contact/"):]: v for k, v in sol.contact_state.items()}
    compiled = Problem.from_model(model).contact
    oracle = ContactSystem(compiled.sys, kernel=reference)
    assert compiled.kernel is kernel_jit and oracle.kernel is reference
    blocks = []
    for c in (compiled, oracle):
        c.set_state(state)
        c.begin_step(sol.poses[-1], 1.0)
        blocks.append(c.evaluate(H, tangent=True)[0])
    (a, info), b = (blocks[0], None), blocks[1]
    assert len(a.f) and np.abs(a.f).max() > 0
    np.testing.assert_array_equal(a.nodes, b.nodes)
    assert np.abs(a.f - b.f).max() <= 1e-10 * np.abs(a.f).max()
    assert np.abs(a.K - b.K).max() <= 1e-8 * np.abs(a.K).max()
    assert len(compiled._tangent_pool.buffers) == 1 and not oracle._tangent_pool.buffers
    previous = use_numpy_kernel(True)
    try:
        made_after = Problem.from_model(model).contact
    finally:
        use_numpy_kernel(previous)
    assert made_after.kernel is reference and compiled.kernel is kernel_jit
    assert Problem.from_model(model).contact.kernel is kernel_jit


@pytest.mark.parametrize("name", ["rolling_friction", "crossing_frictionless"])
def test_solves_take_the_same_newton_iterations_as_with_the_oracle(name):
    import crossing_beams
    import rolling
    build = {"rolling_friction": lambda: rolling.build(mu=0.5, theta=0.3, n_elements=4)[0],
             "crossing_frictionless": lambda: crossing_beams.build(n_elements=4)[0]}[name]
    (it_jit, H_jit), (it_np, H_np) = _solve_both(build, steps=3)
    assert it_jit == it_np
    assert np.abs(H_jit - H_np).max() <= 1e-8


def test_runs_as_plain_python_without_jit():
    """``NUMBA_DISABLE_JIT=1`` (debugging, coverage): the same kernel as plain Python, equal to the oracle."""
    import subprocess
    script = ("import numpy as np, numba; assert numba.config.DISABLE_JIT; "
              "from helpers import kernel_scene as _scene; from beamsolver.contact import kernel_jit, reference; "
              "X, p = _scene(5, True, 0.02, 3.0, True, 0.005, angles=np.array([0.1, 0.6, 1.2])); "
              "f0, K0, _ = reference.kernel_and_tangent(X, p); f1, K1, _ = kernel_jit.kernel_and_tangent(X, p); "
              "print(np.abs(K1 - K0).max() / np.abs(K0).max(), np.abs(f1 - f0).max() / np.abs(f0).max())")
    env = dict(os.environ, NUMBA_DISABLE_JIT="1", PYTHONPATH=os.pathsep.join([str(TESTS)] + sys.path))
    out = subprocess.run([sys.executable, "-c", script], env=env,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    eK, ef = map(float, out.stdout.split())
    assert eK <= 1e-8 and ef <= 1e-8


@pytest.mark.slow
def test_compiled_projection_equals_the_numpy_projection():
    """``kernel_jit.project`` (a drop-in for the search's ``frames.project``) on all kinds, 8 iterations."""
    rng = np.random.default_rng(11)
    X, kinds, _, _ = _pairs(rng, 12, np.tile([1e-3, 0.1, 0.5, 0.7, 1.2, np.pi / 2], 2))
    h1 = se3.log(se3.relative(X[:, 0], X[:, 1]))
    h2 = se3.log(se3.relative(X[:, 2], X[:, 3]))
    xi1, xi2 = rng.uniform(0.2, 0.8, 12), rng.uniform(0.2, 0.8, 12)
    a0, b0 = frames.project(kinds, X[:, 0], h1, xi1, X[:, 2], h2, xi2, iterations=8)
    a1, b1 = kernel_jit.project(kinds, X[:, 0], h1, xi1, X[:, 2], h2, xi2, iterations=8)
    assert np.abs(a1 - a0).max() <= 1e-12 and np.abs(b1 - b0).max() <= 1e-12


def test_projection_stopping_at_a_fixed_point_gives_every_iteration_s_result():
    """``project`` with ``n`` iterations (which stops early at an exact fixed point and computes a fixed
    slave section once) equals ``n`` single iterations chained, bit for bit, on all kinds, from far and
    from converged starts."""
    rng = np.random.default_rng(12)
    X, kinds, xi1c, xi2c = _pairs(rng, 36, np.tile([1e-3, 0.1, 0.5, 0.7, 1.2, np.pi / 2], 6))
    h1 = se3.log(se3.relative(X[:, 0], X[:, 1]))
    h2 = se3.log(se3.relative(X[:, 2], X[:, 3]))
    for xi1, xi2 in ((rng.uniform(0.0, 1.0, 36), rng.uniform(0.0, 1.0, 36)), (xi1c, xi2c)):
        a, b = xi1, xi2
        for n in range(1, 13):
            a, b = kernel_jit.project(kinds, X[:, 0], h1, a, X[:, 2], h2, b, iterations=1)
            a_n, b_n = kernel_jit.project(kinds, X[:, 0], h1, xi1, X[:, 2], h2, xi2, iterations=n)
            np.testing.assert_array_equal(a_n, a)
            np.testing.assert_array_equal(b_n, b)


def test_tangent_written_to_a_given_array_equals_a_fresh_one_and_checks_the_array():
    X, p = _scene(5, True, 0.0, 0.0, True, 0.005)
    f0, K0, o0 = kernel_jit.kernel_and_tangent(X, p)
    K = np.full((len(X), 24, 24), np.nan)
    f1, K1, o1 = kernel_jit.kernel_and_tangent(X, p, K=K)
    assert K1 is K
    np.testing.assert_array_equal(K, K0)
    np.testing.assert_array_equal(f1, f0)
    with pytest.raises(bs.InputError, match="K must be"):
        kernel_jit.kernel_and_tangent(X, p, K=np.empty((len(X) + 1, 24, 24)))
    with pytest.raises(bs.InputError, match="K must be"):
        kernel_jit.kernel_and_tangent(X, p, K=np.empty((24, 24, len(X))).T)


def test_points_sharing_elements_equal_each_point_alone_and_the_oracle():
    """Consecutive points on the same elements (Gauss points of one slave element against one master
    element, as in a bundle) reuse the elements' twists and operators (``kernel_jit._element_side``): the
    results are those of each point evaluated alone, bit for bit, and those of the oracle."""
    rng = np.random.default_rng(21)
    A1, B1 = _element(rng, [0, 0, 0], 0.0, 0.4)
    masters = [_element(rng, [0.0, -0.02, 0.19], 0.05, 0.4), _element(rng, [0.3, 0.2, 0.19], 0.6, 0.4)]
    P = 12
    X = np.array([[A1, B1, *masters[q // 6]] for q in range(P)])
    X[9:, 0, 0, 3] += 1e-9                                   # a slave element that moved: recomputed
    kinds = np.where(np.arange(P) < 6, frames.LINE, frames.ORTHOGONAL)
    h1 = se3.log(se3.relative(X[:, 0], X[:, 1]))
    h2 = se3.log(se3.relative(X[:, 2], X[:, 3]))
    xi1, xi2 = frames.project(kinds, X[:, 0], h1, np.tile(np.linspace(0.1, 0.9, 6), 2), X[:, 2], h2,
                              np.full(P, 0.5), iterations=30)
    p = dict(kind=kinds, xi1=xi1, xi2=xi2, R1=np.full(P, 0.25), R2=np.full(P, 0.25), weight=np.full(P, 0.2),
             penalty=np.full(P, 100.0), multiplier=np.zeros(P), mu=np.full(P, 0.3), penalty_t=np.full(P, np.nan),
             elastic_slip=np.full(P, 0.005))
    Xo = X.copy()
    for j in range(4):
        Xo[:, j] = se3.compose(X[:, j], se3.exp(rng.normal(size=(P, 6)) * 0.003))
    H_CL, H_FK, H_LK = frames.material_frames(Xo, kinds, xi1, xi2, p["R1"], p["R2"])
    p.update(H_CL=H_CL, H_FK=H_FK, H_LK_prev=H_LK, xi1_prev=xi1, xi2_prev=xi2 - 0.01,
             lam_t_prev=rng.normal(size=(P, 3)) * 0.5, has_history=np.full(P, True))
    f, K, o = kernel_jit.kernel_and_tangent(X, p)
    for q in range(P):
        fq, Kq, oq = kernel_jit.kernel_and_tangent(X[q:q + 1], {k: v[q:q + 1] for k, v in p.items()})
        np.testing.assert_array_equal(fq[0], f[q])
        np.testing.assert_array_equal(Kq[0], K[q])
        for k in FIELDS:
            np.testing.assert_array_equal(oq[k][0], o[k][q])
    f0, K0, _ = reference.kernel_and_tangent(X, p)
    assert np.abs(f - f0).max() <= 1e-8 * np.abs(f0).max()
    assert np.abs(K - K0).max() <= 1e-8 * np.abs(K0).max()
    assert o["active"].sum() >= P // 2 and not o["stick"][o["active"]].all()      # forces, friction, slip
