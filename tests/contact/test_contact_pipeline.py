"""The staged contact pipeline (issue 14): compiled projections equal their numpy oracle, the
evaluation kept for the same poses and state is the one a fresh evaluation gives, and the
public per-stage timings."""
import pytest
import sys

import numpy as np

import beamsolver as bs
from beamsolver import se3
from beamsolver.nonlinear.problem import Problem
from beamsolver.contact import frames, kernel_jit, projection
from beamsolver.contact.system import TIMED
from beamsolver.model.buffers import REUSE_BUFFERS

from helpers import kernel_pairs as _pairs, projection_until_converged

import rolling


def _poses(seed):
    rng = np.random.default_rng(seed)
    X, kinds, _, _ = _pairs(rng, 12, np.tile([1e-3, 0.1, 0.5, 0.7, 1.2, np.pi / 2], 2))
    H = X.reshape(-1, 4, 4)                      # nodes 4 k .. 4 k + 3: A1, B1, A2, B2 of pair k
    A1, A2 = 4 * np.arange(12), 4 * np.arange(12) + 2
    h1 = se3.log(se3.relative(H[A1], H[A1 + 1]))
    h2 = se3.log(se3.relative(H[A2], H[A2 + 1]))
    return rng, H, kinds, A1, A2, h1, h2


def test_element_twists_and_section_points_equal_the_numpy_sections():
    rng, H, _, A1, _, h1, _ = _poses(1)
    enodes = np.stack([A1, A1 + 1], axis=1)
    np.testing.assert_array_equal(projection.element_twists(H, enodes), h1)
    xi = rng.uniform(-0.05, 1.05, len(A1))
    HC, _, _ = frames.section(H[A1], h1, xi)
    x, e1 = projection.section_points(H, A1, h1, xi)
    np.testing.assert_allclose(x, HC[:, :3, 3], rtol=0, atol=1e-14)
    np.testing.assert_allclose(e1, HC[:, :3, 0], rtol=0, atol=1e-14)


def test_closest_points_equal_the_numpy_projection_and_ratio():
    _, H, _, A1, A2, h1, h2 = _poses(2)
    n = len(A1)
    x1, x2 = frames.project(np.full(n, frames.POINT), H[A1], h1, np.full(n, 0.5), H[A2], h2, np.full(n, 0.5), 8)
    H1, x1p, x1pp = frames.section(H[A1], h1, x1)
    H2, x2p, x2pp = frames.section(H[A2], h2, x2)
    d = H2[:, :3, 3] - H1[:, :3, 3]
    h11 = np.sum(x1p * x1p, 1) - np.sum(d * x1pp, 1)
    h22 = np.sum(x2p * x2p, 1) + np.sum(d * x2pp, 1)
    ratio = (h11 - np.sum(x1p * x2p, 1) ** 2 / h22) / np.sum(x1p * x1p, 1)
    y1, y2, r = projection.closest_points(H, A1, h1, A2, h2)
    np.testing.assert_allclose(y1, x1, atol=1e-12)
    np.testing.assert_allclose(y2, x2, atol=1e-12)
    np.testing.assert_allclose(r, ratio, rtol=1e-10, atol=1e-12)


@pytest.mark.slow
def test_gauss_point_projection_equals_the_numpy_projection_from_the_chord():
    rng, H, kinds, A1, A2, h1, h2 = _poses(3)
    kinds = np.where(kinds == frames.POINT, frames.ORTHOGONAL, kinds)
    xi1 = rng.uniform(0.1, 0.9, len(A1))
    xc = frames.section(H[A1], h1, xi1)[0][:, :3, 3]
    xa, xb = H[A2, :3, 3], H[A2 + 1, :3, 3]
    start = np.clip(np.sum((xc - xa) * (xb - xa), 1) / np.sum((xb - xa) ** 2, 1), 0.0, 1.0)
    _, x2 = frames.project(kinds, H[A1], h1, xi1, H[A2], h2, start, 8)
    dist = np.linalg.norm(frames.section(H[A2], h2, x2)[0][:, :3, 3] - xc, axis=1)
    y2, ydist = projection.project_points(H, kinds, A1, h1, xi1, A2, A2 + 1, h2)
    np.testing.assert_allclose(y2, x2, atol=1e-12)
    np.testing.assert_allclose(ydist, dist, rtol=1e-12)


def test_gauss_point_projection_equals_the_compiled_projection_bit_for_bit():
    """``project_points`` hands its slave section to the Newton iterations (``kernel_jit._project_from``):
    the same floats as ``kernel_jit.project`` from the same chord start, stopped at the same iteration
    (the first update within the lanes' tolerance, ``projection_until_converged``)."""
    rng, H, kinds, A1, A2, h1, h2 = _poses(4)
    kinds = np.where(kinds == frames.POINT, frames.ORTHOGONAL, kinds)
    xi1 = rng.uniform(0.1, 0.9, len(A1))
    xc, _ = projection.section_points(H, A1, h1, xi1)
    xa, xb = H[A2, :3, 3], H[A2 + 1, :3, 3]
    rel, chord = xc - xa, xb - xa
    start = np.clip((rel[:, 0] * chord[:, 0] + rel[:, 1] * chord[:, 1] + rel[:, 2] * chord[:, 2])
                    / (chord[:, 0] ** 2 + chord[:, 1] ** 2 + chord[:, 2] ** 2), 0.0, 1.0)
    x2, _, ok = projection_until_converged(kinds, H[A1], h1, xi1, H[A2], h2, start, 8)
    y2, ydist = projection.project_points(H, kinds, A1, h1, xi1, A2, A2 + 1, h2)
    assert ok.all()
    np.testing.assert_array_equal(y2, x2)
    assert np.isfinite(ydist).all()


def _residual(contact, H, tangent):
    blocks, _ = contact.evaluate(H, tangent=tangent)
    return contact.sys.assemble_blocks(H, blocks)


def test_kept_evaluation_equals_a_fresh_one_and_follows_state_changes():
    model, slave, _ = rolling.build(mu=0.5, n_elements=3)
    sol = bs.solve(model, steps=2)
    H = sol.poses[-1].copy()
    H[slave.nodes, 0, 3] += 1e-4
    state = {k[len("contact/"):]: v for k, v in sol.contact_state.items()}     # Problem.get_state: name/key
    c = Problem.from_model(model).contact
    c.set_state(state)
    c.begin_step(sol.poses[-1], 1.0)
    r0, _, _, _ = _residual(c, H, False)               # a line-search trial, residual only
    r1, coo1, _, _ = _residual(c, H, True)              # the tangent at the same poses: kept
    fresh = Problem.from_model(model).contact
    fresh.set_state(state)
    fresh.begin_step(sol.poses[-1], 1.0)
    r2, coo2, _, _ = _residual(fresh, H, True)
    np.testing.assert_array_equal(r0, r2)
    np.testing.assert_array_equal(r1, r2)
    np.testing.assert_array_equal(coo1[2], coo2[2])
    # a new state at the same poses: not the kept evaluation (no history: no friction)
    c.set_state({})
    c.begin_step(sol.poses[-1], 1.0)
    r3, _, _, _ = _residual(c, H, True)
    none = Problem.from_model(model).contact
    none.begin_step(sol.poses[-1], 1.0)
    np.testing.assert_array_equal(r3, _residual(none, H, True)[0])
    assert np.abs(r3 - r2).max() > 1e-6 * np.abs(r2).max()


def test_stage_timings_are_public_and_accumulate():
    model, _, _ = rolling.build(mu=0.5, n_elements=3)
    problem = Problem.from_model(model)
    c = problem.contact
    H = problem.system.poses0.copy()
    c.begin_step(H, 0.0)
    assert set(c.timings) == set(TIMED) and all(v == 0.0 for v in c.timings.values())
    for _ in range(20):
        c.begin_step(H, 0.0)
        c.evaluate(H, tangent=True)
    assert all(c.timings[k] >= 0.0 for k in TIMED) and sum(c.timings.values()) > 0.0


def test_material_frames_from_the_kept_twists_are_bit_identical():
    """``material_frames`` given the element twists of the whole table at the last converged poses
    (``projection.element_twists``, what ``ContactSystem`` keeps per step) gives exactly the frames
    it computes from the pair's own nodes."""
    rng, H, kinds, A1, A2, _, _ = _poses(7)
    enodes = np.stack([np.arange(0, len(H), 2), np.arange(1, len(H), 2)], axis=1)   # element j: 2 j, 2 j + 1
    h = projection.element_twists(H, enodes)
    X = np.stack([H[A1], H[A1 + 1], H[A2], H[A2 + 1]], axis=1)
    xi1, xi2 = rng.uniform(0, 1, 12), rng.uniform(0, 1, 12)
    R = np.full(12, 1e-3)
    pick = rng.permutation(12)[:7]
    own = frames.material_frames(X[pick], kinds[pick], xi1[pick], xi2[pick], R[pick], R[pick])
    kept = frames.material_frames(X[pick], kinds[pick], xi1[pick], xi2[pick], R[pick], R[pick],
                                 h[A1[pick] // 2], h[A2[pick] // 2])
    for a, b in zip(own, kept):
        np.testing.assert_array_equal(a, b)


def test_tangent_buffer_is_reused_only_when_no_earlier_blocks_hold_it():
    """The compiled kernel writes the tangent into a buffer the contact system keeps: blocks still
    referenced (the solver's last evaluation during a line search) are never overwritten, and a
    buffer nobody holds is reused (same memory, same values as a fresh evaluation)."""
    model, slave, _ = rolling.build(mu=0.5, n_elements=3)
    sol = bs.solve(model, steps=2)
    H1 = sol.poses[-1].copy()
    H2 = H1.copy()
    H2[slave.nodes, 0, 3] += 1e-4
    state = {k[len("contact/"):]: v for k, v in sol.contact_state.items()}

    def system():
        c = Problem.from_model(model).contact
        c.set_state(state)
        c.begin_step(sol.poses[-1], 1.0)
        return c

    c = system()
    b1, _ = c.evaluate(H1, tangent=True)
    K1 = b1.K.copy()
    b2, _ = c.evaluate(H2, tangent=True)            # b1 still held: another buffer
    assert not np.shares_memory(b1.K, b2.K)
    np.testing.assert_array_equal(b1.K, K1)
    np.testing.assert_array_equal(b2.K, system().evaluate(H2, tangent=True)[0].K)
    kept = [id(b) for b in c._tangent_pool.buffers]
    assert len(kept) == 2
    del b1, b2
    c.begin_step(sol.poses[-1], 1.0)
    b3, _ = c.evaluate(H1, tangent=True)            # nothing holds the buffers: one is reused
    assert ([id(b) for b in c._tangent_pool.buffers] == kept) == REUSE_BUFFERS
    np.testing.assert_array_equal(b3.K, K1)
