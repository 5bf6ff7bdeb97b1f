"""The shortcuts that make small models fast give what the general paths give.

Each shortcut (benchmarks/peers/peers.py measures the speed) is checked against the
path it replaces: the CSC tangent built without scipy's constructor, the pattern's
unique keys by a dense table, the rigid-mode check of anchored beams, the dead-load
and node-block fast paths of ``System.evaluate``, the rotation check's bound, and
the bend of the peers table still converging in its 6 Newton iterations.
"""
import sys

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import beamsolver as bs
from beamsolver import geometry
from beamsolver.assembly import system as assembly
from beamsolver.assembly.system import System
from beamsolver.errors import InputError
from beamsolver.failures import RotationLimit
from beamsolver.nonlinear.problem import Problem
from beamsolver.nonlinear.newton import Convergence, Newton

import bend45

SEC = bs.Section.circular(radius=0.01, E=210e9, nu=0.3)


def _cantilever(n=6, follower=False):
    m = bs.Model()
    b = m.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), n), SEC)
    m.clamp(b.first)
    m.add_load(b.last, force=(0.0, 30.0, 50.0), moment=(1.0, 0.0, 2.0))
    if follower:
        m.add_load(b.last, force=(0.0, 0.0, 0.0), follower=True)      # zero: the same physics
    return m, b


def _scenes():
    out = {"bend45": bend45.build(8)[0], "cantilever": _cantilever()[0]}
    m = bs.Model()
    b1 = m.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), 4), SEC)
    b2 = m.add_beam(geometry.straight((1, 0, 0), (1, 1, 0), 4), SEC, element="se3-3")
    m.join(b1.last, b2.first)
    m.clamp(b1.first)
    m.add_load(b2.last, force=(0, 0, 20.0))
    out["join, two element types"] = m
    m = bs.Model()
    b = m.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), 5), SEC)
    m.clamp(b.first)
    m.fix(b.last, ("uy", "uz"))
    m.add_load(b.last, force=(-100.0, 0, 0))
    m.add_load(2, force=(0, 0, 1.0))
    out["partial fix"] = m
    return out


def _state(problem, H):
    return problem.evaluate(H, 1.0)


@pytest.mark.parametrize("name", list(_scenes()))
def test_tangent_csc_is_what_scipy_builds(name):
    """``System.matrix`` (``canonical_csc``) equals the CSC of scipy's constructor on the same
    arrays: entries, canonical flags, arithmetic and the factorisation's solution."""
    problem = Problem.from_model(_scenes()[name])
    s = problem.system
    H = s.poses0.copy()
    H[:, :3, 3] += 1e-3 * np.sin(np.arange(3 * len(H))).reshape(-1, 3)     # a strained state
    K = problem.tangent(problem.evaluate(H, 1.0))
    ref = sp.csc_matrix((K.data.copy(), K.indices.copy(), K.indptr.copy()), shape=K.shape)
    assert type(K) is type(ref) and K.shape == ref.shape and K.format == "csc"
    assert np.array_equal(K.toarray(), ref.toarray())
    ref.has_canonical_format  # noqa: B018 - scipy computes the flag on first use
    assert K.has_canonical_format and ref.has_canonical_format
    x = np.cos(np.arange(K.shape[0]))
    assert np.array_equal(K @ x, ref @ x) and np.array_equal((K + K.T).toarray(), (ref + ref.T).toarray())
    b = np.sin(np.arange(K.shape[0]))
    assert np.array_equal(spla.splu(K, permc_spec="MMD_AT_PLUS_A").solve(b),
                          spla.splu(ref, permc_spec="MMD_AT_PLUS_A").solve(b))
    direct = assembly.canonical_csc(K.data, K.indices, K.indptr, K.shape[0])
    assert np.array_equal(direct.toarray(), ref.toarray()) and repr(direct) == repr(ref)


@pytest.mark.parametrize("n, bound", [(0, 1), (1, 1), (7, 10), (500, 1000), (3000, 4 * 10**6)])
def test_unique_inverse_equals_numpy(n, bound):
    """The pattern's unique keys (dense table below ``DENSE_KEYS``, else a sort) are ``np.unique``'s."""
    key = np.random.default_rng(n).integers(0, bound, n).astype(np.int64)
    u, inv = assembly.unique_inverse(key, bound)
    u0, inv0 = np.unique(key, return_inverse=True)
    assert np.array_equal(u, u0) and np.array_equal(inv, inv0)
    assert u.dtype == u0.dtype and inv.dtype == inv0.dtype and inv.shape == inv0.shape


def test_rigid_mode_shortcut_only_for_anchored_beams(monkeypatch):
    """The shortcut accepts beams that each hold a clamped node and nothing else; every other
    scene takes the general check, which still finds the free modes."""
    m, b = _cantilever()
    assert assembly.beams_anchored(m, System(m).kind)
    m2 = bs.Model()
    m2.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), 3), SEC)
    c = m2.add_beam(geometry.straight((0, 1, 0), (1, 1, 0), 3), SEC)
    m2.clamp(c.first)
    assert not assembly.beams_anchored(m2, System(m2, check_rigid_modes=False).kind)
    with pytest.raises(InputError, match=r"beam\(s\) \[0\]: 6 rigid-body mode\(s\)"):
        System(m2)
    m3, b3 = _cantilever()
    m3.fix(m3.add_node((2.0, 0.0, 0.0)), ("ux",))
    assert not assembly.beams_anchored(m3, System(m3, check_rigid_modes=False).kind)
    with pytest.raises(InputError, match=r"5 rigid-body mode\(s\)"):
        System(m3)
    m4, b4 = _cantilever()
    c4 = m4.add_beam(geometry.straight((1, 0, 0), (1, 1, 0), 3), SEC)
    m4.join(b4.last, c4.first)
    assert not assembly.beams_anchored(m4, System(m4).kind)          # joined: the general check passes it
    m5 = bs.Model()
    b5 = m5.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), 3), SEC)
    m5.fix(b5.first, ("ux", "uy", "uz", "rx", "ry"))                    # partial fixes: global-type nodes
    m5.fix(b5.last, ("uy",))
    assert not assembly.beams_anchored(m5, System(m5).kind)            # the general check passes it
    # where the shortcut applies, the general check agrees
    monkeypatch.setattr(assembly, "beams_anchored", lambda model, kind: False)
    System(m)


def test_dead_load_fast_paths_equal_the_general_path():
    """Dead loads only (``fext`` straight from the kernel, node blocks added in order) give the
    residual, force levels and tangent values of the general path (a zero follower load added,
    node blocks placed by index)."""
    H = None
    out = []
    for follower, in_order in ((False, True), (True, True), (False, False)):
        s = System(_cantilever(follower=follower)[0])
        if not in_order:
            s.dead_blocks_in_order = False
        H = s.poses0.copy() if H is None else H
        H[-1, :3, :3] = bs.se3.exp_so3(np.array([0.1, -0.2, 0.3])) @ s.poses0[-1, :3, :3]
        r, kvals, info = s.evaluate(H, s.load_factors(0.7))
        out.append((r, kvals, info["f_level"], info["m_level"]))
    s = System(_cantilever()[0])
    assert s.dead_blocks_in_order and len(s.dead) == len(s.load_nodes)
    for r, kvals, fl, ml in out[1:]:
        assert np.array_equal(r, out[0][0]) and np.array_equal(kvals, out[0][1])
        assert (fl, ml) == (out[0][2], out[0][3])


def test_rotation_check_bound_never_hides_a_turn():
    """The check skips the angles only when ``sqrt(3) |w|_inf`` is below every element's limit:
    an element turned just past the limit is refused, one just below accepted, about any axis."""
    m = bs.Model()
    b = m.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), 4), SEC)
    m.clamp(b.first)
    problem = Problem.from_model(m)
    newton = Newton(problem, Convergence())
    limit = problem.system.rotation_limit.min()
    for axis in (np.array([1.0, 0.0, 0.0]), np.ones(3) / np.sqrt(3.0)):
        for factor, refused in ((1.0 + 1e-7, True), (1.0 - 1e-7, False), (0.5, False), (0.1, False)):
            H = problem.system.poses0.copy()
            R = bs.se3.exp_so3(factor * limit * axis)
            H[3:, :3, :3] = R @ H[3:, :3, :3]           # element 2 (nodes 2-3) turns by factor * limit
            H[3:, :3, 3] = H[2, :3, 3] + (H[3:, :3, 3] - H[2, :3, 3]) @ R.T
            if refused:
                with pytest.raises(RotationLimit, match="MAX_ELEMENT_ROTATION"):
                    newton.evaluate(H, 1.0)
            else:
                newton.evaluate(H, 1.0)


def test_bend45_single_step_keeps_six_newton_iterations():
    """The peers table's bend (8 elements, one load step): 6 Newton iterations, as before the
    speed-up (docs/benchmarks.md)."""
    model, beam = bend45.build(8)
    sol = bs.solve(model, steps=1, verbose=False)
    assert int(sol.iterations[1:].sum()) == 6 and sol.n_steps == 1


@pytest.mark.parametrize("bad", [None, "nan_first", "nan_last"])
def test_scaled_dead_loads_kernel_equals_numpy(bad):
    """``assembly_jit.scaled_dead_loads`` gives ``dead_loads`` of the numpy-scaled loads and
    numpy's ``max(|F lf|)``, ``max(|M lf|)`` (a NaN anywhere gives NaN, as numpy's max)."""
    from beamsolver.assembly import compiled as assembly_jit
    rng = np.random.default_rng(3)
    k = 4
    H = np.stack([np.eye(4)] * 6)
    H[:, :3, :3] = bs.se3.exp_so3(rng.normal(size=(6, 3)))
    nodes = np.array([5, 1, 1, 3])
    F, M, lf = rng.normal(size=(k, 3)), rng.normal(size=(k, 3)), rng.normal(size=k)
    if bad:
        F[0 if bad == "nan_first" else -1, 1] = np.nan
    fb, kb = np.empty((k, 6)), np.empty((k, 6, 6))
    fl, ml = assembly_jit.scaled_dead_loads(H, nodes, F, M, lf, fb, kb)
    Fs, Ms = F * lf[:, None], M * lf[:, None]
    fb0, kb0 = np.empty((k, 6)), np.empty((k, 6, 6))
    assembly_jit.dead_loads(H, nodes, Fs, Ms, fb0, kb0)
    assert np.array_equal(fb, fb0, equal_nan=True) and np.array_equal(kb, kb0, equal_nan=True)
    assert np.array_equal([fl, ml], [np.abs(Fs).max(initial=0.0), np.abs(Ms).max(initial=0.0)], equal_nan=True)


def test_element_groups_reuse_add_beams_reference_only_while_it_holds():
    """A beam alone in its element type reuses the ``Reference`` ``add_beam`` computed: the same
    numbers as computing it again; a section replaced or changed afterwards is taken instead."""
    model, beam = bend45.build(8)
    g = model.element_groups()[0]
    P = model.poses0[g.nodes]
    fresh = g.element_type.reference(P, np.broadcast_to(beam.section.C, (beam.n_elements, 6, 6)))
    for name in ("L", "eps0", "C", "diagonal"):
        assert np.array_equal(getattr(g.ref, name), getattr(fresh, name))
    assert g.ref.data.keys() == fresh.data.keys()
    tip = bs.solve(model, steps=1, verbose=False).position(beam.last)
    stiffer = bs.Section(EA=2e7, GA2=1e7, GA3=1e7, GJ=2e7 / 12, EI2=2e7 / 12, EI3=2e7 / 12, radius=0.5)
    other, b2 = bend45.build(8)
    other.beams[0].section = stiffer                          # replaced after add_beam
    expected = bs.Model()
    b3 = expected.add_beam(geometry.arc(radius=100.0, angle=np.pi / 4.0, n_elements=8), stiffer)
    expected.clamp(b3.first)
    expected.add_load(b3.last, force=(0.0, 0.0, 600.0))
    tip2 = bs.solve(other, steps=1, verbose=False).position(b2.last)
    assert np.array_equal(tip2, bs.solve(expected, steps=1, verbose=False).position(b3.last))
    assert not np.allclose(tip2, tip)
    changed, b4 = bend45.build(8)
    changed.beams[0].section.C *= 2.0                         # changed in place after add_beam
    assert np.array_equal(bs.solve(changed, steps=1, verbose=False).position(b4.last), tip2)


def test_continuity_shortcut_bound_holds():
    """``check_continuity`` skips its test when every element's ``a0 + a1 < pi - CONTINUITY_MARGIN``
    (angles of the relative rotations before and after the step): then the change ``angle(R0^T R1)
    <= a0 + a1`` can never reach ``(pi - a0) + (pi - a1) - 1e-9``, checked on random rotations, and
    a turn through pi within a step is still refused."""
    from beamsolver.nonlinear.rotations import CONTINUITY_MARGIN

    def angle(R):
        return np.arccos(np.clip(0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0), -1.0, 1.0))
    rng = np.random.default_rng(7)
    w0, w1 = rng.normal(size=(2, 20000, 3))
    w0 *= (np.pi * rng.random(20000) / np.linalg.norm(w0, axis=1))[:, None]
    w1 *= (np.pi * rng.random(20000) / np.linalg.norm(w1, axis=1))[:, None]
    R0, R1 = bs.se3.exp_so3(w0), bs.se3.exp_so3(w1)
    a0, a1 = angle(R0), angle(R1)
    skipped = a0 + a1 < np.pi - CONTINUITY_MARGIN
    change = angle(np.swapaxes(R0, 1, 2) @ R1)
    assert skipped.sum() > 5000
    assert not np.any(change[skipped] >= (np.pi - a0[skipped]) + (np.pi - a1[skipped]) - 1e-9)
    m = bs.Model()
    b = m.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), 1), SEC)
    m.clamp(b.first)
    newton = Newton(Problem.from_model(m), Convergence())

    def poses(a):
        H = newton.sys.poses0.copy()
        H[1, :3, :3] = bs.se3.exp_so3(np.array([a, 0.0, 0.0])) @ H[1, :3, :3]
        return H
    newton.check_continuity(poses(0.2), poses(0.3))                   # the shortcut
    with pytest.raises(RotationLimit, match="may have passed pi"):
        newton.check_continuity(poses(0.7 * np.pi), poses(1.3 * np.pi))
