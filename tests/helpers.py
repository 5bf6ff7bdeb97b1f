"""Shared test helpers (one module, imported as ``helpers``: ``tests/`` is on pytest's ``pythonpath``).

Paths of the repository, random poses and sections, relative errors, the quadratic-convergence
check of Newton's residual histories, and random contact pairs for the contact kernels.
"""
from pathlib import Path

import numpy as np

from beamsolver import se3
from beamsolver.assembly.system import System
from beamsolver.contact import frames

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent
EXAMPLES = ROOT / "examples"
BENCHMARKS = ROOT / "benchmarks"


# ---------------------------------------------------------------- poses, sections, errors
def random_rotation_vector(rng, angle, shape=()):
    """Rotation vectors of norm ``angle`` in uniformly random directions, ``shape + (3,)``."""
    v = rng.standard_normal(shape + (3,))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    return v * np.asarray(angle)[..., None] if np.ndim(angle) else v * angle


def random_pose(rng, angle=1.0, scale=1.0, shape=()):
    """Poses with rotation angle up to ``angle`` and translation of order ``scale``."""
    h = np.concatenate([scale * rng.standard_normal(shape + (3,)),
                        random_rotation_vector(rng, angle * rng.uniform(size=shape))], axis=-1)
    return se3.exp(h)


def spd_matrix(rng, diag=(1e3, 4e2, 5e2, 20.0, 30.0, 40.0), coupling=0.3):
    """A full symmetric positive definite 6x6 matrix with the given diagonal scale."""
    d = np.sqrt(np.asarray(diag, dtype=float))
    A = np.eye(6) + coupling * rng.uniform(-1, 1, (6, 6))
    S = A @ A.T
    s = np.sqrt(np.diag(S))
    return (d / s)[:, None] * S * (d / s)[None, :]


def numpy_matmul_fuses():
    """Whether numpy's ``@`` on 3x3 blocks rounds ``a0 b0 + a1 b1 + a2 b2`` as one fma chain (the BLAS of
    this machine; ``lie.se3_twin`` reproduces that chain)."""
    e = 2.0 ** -30
    A = np.array([[[1.0 + e, 1.0, 1.0], [0.0] * 3, [0.0] * 3]])
    B = np.array([[[1.0 - e, 0, 0], [-0.5, 0, 0], [-0.5, 0, 0]]])
    return (A @ B)[0, 0, 0] == -e * e


def assert_same_bits(a, b):
    """``a`` and ``b`` equal bit for bit (NaN where NaN) where numpy's ``@`` fuses (``numpy_matmul_fuses``),
    else to round-off."""
    if numpy_matmul_fuses():
        assert np.array_equal(a, b, equal_nan=True), f"{np.count_nonzero(a != b)} entries differ"
    else:
        np.testing.assert_allclose(a, b, rtol=1e-13, atol=1e-15)


def rel_err(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


# ---------------------------------------------------------------- assembled tangents
def deformed_state(system, rng, size=0.15):
    """A generic (non-equilibrium) state reached through ``System.update``."""
    dz = size * rng.standard_normal((system.n_nodes, 6))
    dz[:, :3] *= system.length_scale
    return system.update(system.poses0, dz)


def check_tangent(model, seed=0, t=1.0, eps=1e-6):
    """The assembled tangent of ``model`` at a random deformed state against central differences of the
    assembled residual (relative error below 1e-6); returns the system, the tangent and the differences."""
    system = System(model)
    rng = np.random.default_rng(seed)
    H = deformed_state(system, rng)
    lf = system.load_factors(t) if system.load_scales else np.zeros(0)
    r, kvals, _ = system.evaluate(H, lf)
    r2, _, _ = system.evaluate(H, lf, tangent=False)
    assert np.abs(r - r2).max() <= 1e-14 * np.abs(r).max()
    free = system.free_dofs
    K = system.full_matrix(kvals).toarray()[np.ix_(free, free)]
    Kred = system.matrix(kvals).toarray()
    assert np.abs(K - Kred).max() <= 1e-14 * np.abs(K).max()
    fd = np.zeros_like(K)
    for j, dof in enumerate(free):
        node, k = divmod(dof, 6)
        e = eps * (system.length_scale if k < 3 else 1.0)
        dz = np.zeros((system.n_nodes, 6))
        dz[node, k] = e
        rp, _, _ = system.evaluate(system.update(H, dz), lf, tangent=False)
        rm, _, _ = system.evaluate(system.update(H, -dz), lf, tangent=False)
        fd[:, j] = (rp[free] - rm[free]) / (2 * e)
    err = rel_err(K, fd)
    assert err < 1e-6, err
    # the residual at the free unknowns is not zero (the check is not trivial)
    assert np.abs(r[free]).max() > 1e-3 * np.abs(K).max() * 1e-3
    return system, K, fd


# ---------------------------------------------------------------- Newton's rate
ASYMPTOTIC = 1e-2     # r_k below this: near the solution
FLOOR_FACTOR = 10.0   # round-off floor: this times the smallest residual reached (docs/theory.md eq. 5.2)
C_QUAD = 50.0         # r_{k+1} <= C r_k^2 (scaled, dimensionless residuals)


def quadratic_pairs(residuals):
    """Consecutive ``(r_k, r_{k+1})`` near the solution with ``r_{k+1}`` above the round-off floor.

    The floor is where the history stagnates (the last iterations repeat the
    smallest residual to within a few ulps of the force level), so it is
    estimated from the history itself, not fixed: it depends on ``EA / EI``
    and on the mesh.
    """
    r = np.asarray(residuals, dtype=float)
    floor = FLOOR_FACTOR * r.min()
    return [(a, b) for a, b in zip(r[:-1], r[1:]) if a < ASYMPTOTIC and b > floor]


def assert_quadratic(residuals):
    pairs = quadratic_pairs(residuals)
    assert pairs, f"no iteration in the asymptotic range above round-off: {residuals}"
    for a, b in pairs:
        assert b <= C_QUAD * a * a, f"not quadratic: {a:.3e} -> {b:.3e} (history {np.array(residuals)})"
    # the observed order of the last pair, log r_{k+1} / log r_k, is about 2 (or more)
    a, b = pairs[-1]
    assert np.log(b) / np.log(a) > 1.5, (a, b)
    return pairs


# ---------------------------------------------------------------- contact pairs for the kernels
def kernel_element(rng, x0, angle, twist):
    R = se3.exp_so3(np.array([0.0, 0.0, angle])) @ se3.exp_so3(rng.normal(size=3) * 0.05)
    HA = np.eye(4)
    HA[:3, :3], HA[:3, 3] = R, x0
    h = np.concatenate([np.array([1.0, 0, 0]) + rng.normal(size=3) * 0.02, rng.normal(size=3) * twist])
    return HA, HA @ se3.exp(h)


def kernel_pairs(rng, P, angles):
    """Pairs ``(P, 4, 4, 4)`` of a slave along x and a master at ``angles`` above it, kinds by angle."""
    kinds = np.where(angles < 0.35, frames.LINE, np.where(angles < 0.8, frames.ORTHOGONAL, frames.POINT))
    X = []
    for a in angles:
        A1, B1 = kernel_element(rng, [0, 0, 0], 0.0, 0.2)
        A2, B2 = kernel_element(rng, [0.5 - 0.5 * np.cos(a), -0.5 * np.sin(a), 0.19], a, 0.2)
        X.append([A1, B1, A2, B2])
    X = np.array(X)
    h1 = se3.log(se3.relative(X[:, 0], X[:, 1]))
    h2 = se3.log(se3.relative(X[:, 2], X[:, 3]))
    xi1 = np.where(kinds == frames.POINT, 0.5, rng.uniform(0.1, 0.9, P))
    xi1, xi2 = frames.project(kinds, X[:, 0], h1, xi1, X[:, 2], h2, np.full(P, 0.5), iterations=30)
    return X, kinds, xi1, xi2


def projection_until_converged(kind, HA1, h1, xi1, HA2, h2, start, cap=8):
    """The oracle of ``projection``'s lanes: per row the iterate of ``kernel_jit.project`` (from ``start``) at
    the first Newton update within ``projection._step_tol`` (``STEP_TOL (1 + |x_A2| / |u2|)``, the same
    operations), at most ``cap`` iterations.  Returns ``xi2``, the iterations taken and whether it converged."""
    from beamsolver.contact import kernel_jit, projection
    xA, u = HA2[:, :3, 3], h2[:, :3]
    lu = np.sqrt((u[:, 0] * u[:, 0] + u[:, 1] * u[:, 1]) + u[:, 2] * u[:, 2])
    tol = projection.STEP_TOL * (1.0 + np.sqrt((xA[:, 0] * xA[:, 0] + xA[:, 1] * xA[:, 1]) + xA[:, 2] * xA[:, 2]) / lu)
    prev = np.asarray(start, dtype=float)
    xi2, its, done = prev.copy(), np.full(len(prev), cap), np.zeros(len(prev), dtype=bool)
    for k in range(1, cap + 1):
        cur = kernel_jit.project(kind, HA1, h1, xi1, HA2, h2, start, k)[1]
        stop = ~done & (np.abs(cur - prev) <= tol)
        xi2[stop], its[stop] = cur[stop], k
        xi2[~done & ~stop] = cur[~done & ~stop]
        done |= stop
        prev = cur
    return xi2, its, done


def kernel_scene(seed, friction, smoothing, multiplier, history, elastic_slip, angles=None):
    """Node poses ``(P, 4, 4, 4)`` and kernel parameters of ``kernel_pairs`` (12 by default) with the
    given friction, smoothing gap, multiplier, history and elastic slip."""
    rng = np.random.default_rng(seed)
    angles = np.tile([1e-3, 0.1, 0.5, 0.7, 1.2, np.pi / 2], 2) if angles is None else angles
    P = len(angles)
    X, kinds, xi1, xi2 = kernel_pairs(rng, P, angles)
    p = dict(kind=kinds, xi1=xi1, xi2=xi2, R1=np.full(P, 0.1), R2=np.full(P, 0.1),
             weight=rng.uniform(0.1, 0.5, P), penalty=np.full(P, 100.0), multiplier=np.full(P, multiplier),
             mu=np.full(P, 0.3 if friction else 0.0), penalty_t=np.where(np.arange(P) % 2 == 0, np.nan, 50.0),
             elastic_slip=np.full(P, elastic_slip), smoothing=np.full(P, smoothing))
    if friction:
        Xo = X.copy()
        for j in range(4):
            Xo[:, j] = se3.compose(X[:, j], se3.exp(rng.normal(size=(P, 6)) * 0.003))
        H_CL, H_FK, H_LK = frames.material_frames(Xo, kinds, xi1, xi2, p["R1"], p["R2"])
        p.update(H_CL=H_CL, H_FK=H_FK, H_LK_prev=H_LK, xi1_prev=xi1 + 0.01, xi2_prev=xi2 - 0.01,
                 lam_t_prev=rng.normal(size=(P, 3)) * 0.5,
                 has_history=np.full(P, history) | (np.arange(P) % 4 == 0))
    return X, p


def contact_tangent_error(problem, H, eps=1e-7):
    """Largest difference between the assembled tangent and central differences of the residual over the
    free unknowns at poses ``H``, relative to the largest contact tangent entry (the whole tangent's where
    no contact block is active); returns ``(error, evaluation)``."""
    system = problem.system
    ev = problem.evaluate(H, 0.0, tangent=True)
    K = problem.full_tangent(ev).toarray()
    free = system.free_dofs
    n = system.n_nodes
    ext = ev.extra
    Kc = np.zeros_like(K)
    if ext is not None and len(ext[2]):
        np.add.at(Kc, (np.ravel(ext[0]), np.ravel(ext[1])), ext[2])
    scale = np.abs(Kc[np.ix_(free, free)]).max(initial=0.0)
    if scale == 0.0:
        scale = np.abs(K[np.ix_(free, free)]).max()
    worst = 0.0
    for d in free:
        dz = np.zeros(6 * n)
        dz[d] = eps
        rp = problem.evaluate(problem.update(H, dz.reshape(n, 6)), 0.0, tangent=False).r
        rm = problem.evaluate(problem.update(H, -dz.reshape(n, 6)), 0.0, tangent=False).r
        worst = max(worst, np.abs((rp - rm)[free] / (2 * eps) - K[free, d]).max() / scale)
    return worst, ev


def bordered_tangent_error(problem, H, t=0.0, eps=1e-7, dlam=1e-6):
    """Largest difference between the bordered Newton matrix of exact stick (``Problem.bordered``: poses
    and nodal multipliers as unknowns) and central differences of ``[r_free; C]`` at poses ``H`` and the
    contact's trial multipliers, column by column (poses by ``eps``, multipliers by ``dlam``), relative
    to the largest entry of each block row; returns ``(error_q_rows, error_C_rows, evaluation)``."""
    system, c = problem.system, problem.contact
    ev = problem.evaluate(H, t, tangent=True)
    free = system.free_dofs
    nf, n = len(free), system.n_nodes
    A = problem.bordered(ev, problem.tangent(ev), -ev.r[free])[0].toarray()
    keys = ev.mult["key"]
    g = len(keys)

    def res(Hs, step, s):
        c.multiplier_step(keys, step)
        c.multiplier_trial(s)
        e = problem.evaluate(Hs, t, tangent=False)
        assert np.array_equal(e.mult["key"], keys)
        return np.concatenate([e.r[free], e.mult["C"].ravel()])

    fd = np.zeros_like(A)
    zero = np.zeros((g, 3))
    for k, d in enumerate(free):
        dz = np.zeros(6 * n)
        dz[d] = eps
        fd[:, k] = (res(problem.update(H, dz.reshape(n, 6)), zero, 0.0)
                    - res(problem.update(H, -dz.reshape(n, 6)), zero, 0.0)) / (2 * eps)
    for k in range(3 * g):
        step = np.zeros(3 * g)
        step[k] = 1.0
        fd[:, nf + k] = (res(H, step, dlam) - res(H, step, -dlam)) / (2 * dlam)
    c.multiplier_step(keys, zero)
    err = np.abs(fd - A)
    return (err[:nf].max() / np.abs(A[:nf]).max(), err[nf:].max() / np.abs(A[nf:]).max(), ev)


def crossing_at_nodes(r=0.05, n=8, **contact_options):
    """Two clamped beams of ``n`` elements crossing at right angles exactly at their middle nodes, touching
    (radius ``r``), the upper one pushed down there by 50; ``contact_options`` go to ``add_contact``.
    Returns ``(model, upper, lower, section)``."""
    import beamsolver as bs
    sec = bs.Section.circular(radius=r, E=1e7, nu=0.3)
    m = bs.Model()
    lower = m.add_beam(bs.geometry.straight((0, -1, 0), (0, 1, 0), n), sec)
    upper = m.add_beam(bs.geometry.straight((-1, 0, 2 * r), (1, 0, 2 * r), n), sec)
    for node in (lower.first, lower.last, upper.first, upper.last):
        m.clamp(node)
    m.add_load(upper.nodes[n // 2], force=(0.0, 0.0, -50.0))
    m.add_contact(upper, lower, **contact_options)
    return m, upper, lower, sec


def placed_crossing(G=np.eye(4), lam=1.0, steps=2, swap=False):
    """Two crossing beams (crossing inside elements), all ends clamped, the upper one pushed down
    by 50 N at its node 3; contact declared upper-on-lower, or the other way with ``swap``; the scene
    placed by the pose ``G`` and scaled by ``lam``.  Returns the solution, the upper middle node and the lower
    first node."""
    import beamsolver as bs
    r = 0.05 * lam
    sec = bs.Section.circular(radius=r, E=1e7 / lam**2, nu=0.3)
    m = bs.Model()
    lower = m.add_beam(G @ bs.geometry.straight((0, -lam, 0), (0, lam, 0), 7), sec)
    upper = m.add_beam(G @ bs.geometry.straight((-lam, 0, 2 * r), (lam, 0, 2 * r), 7), sec)
    for node in (lower.first, lower.last, upper.first, upper.last):
        m.clamp(node)
    m.add_load(upper.nodes[3], force=G[:3, :3] @ np.array([0.0, 0.0, -50.0]))
    m.add_contact(*((lower, upper) if swap else (upper, lower)))
    return bs.solve(m, steps=steps, verbose=False), upper.nodes[3], lower.first
