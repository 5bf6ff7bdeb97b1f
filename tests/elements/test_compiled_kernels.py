"""Compiled kernels (numba) against their numpy oracles: element, scatter, pose update, chains.

Results must agree to round-off for straight, curved and twisted elements, at
zero, tiny, large and near-pi relative rotations, with diagonal and full C.
The same tests run with ``NUMBA_DISABLE_JIT=1`` (plain Python) in a
subprocess, and a second process must load the compiled code from the cache.
"""
import json
import os
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

import beamsolver as bs
from beamsolver import geometry, se3
from beamsolver.assembly import compiled as assembly_jit
from beamsolver.elements import element, reference
from beamsolver.assembly.system import System

from helpers import random_pose, random_rotation_vector, spd_matrix

ROOT = Path(__file__).resolve().parents[2]
DIAG = np.diag([1e3, 4e2, 5e2, 20.0, 30.0, 40.0])
ANGLES = (None, 0.0, 1e-12, 1e-7, 1e-3, 0.74, 0.76, 1.4, 2.0, 2.6, np.pi - 1e-6, np.pi - 1e-9)
ROUND_OFF = 1e-12        # relative to the largest entry of the element's force / tangent


def _batch(rng, full_C, n=4):
    """Elements (straight, arc, helix references) deformed to every angle of ``ANGLES``."""
    refs = [geometry.straight((0, 0, 0), (0.7, 0.2, -0.1), 1), geometry.arc(1.3, 0.9, 1),
            geometry.helix(0.4, 1.5, 0.8, 2)[:2]]          # one element turning by 1.7 rad
    HA, HB, L, eps0, C = [], [], [], [], []
    for P in refs:
        l, e0 = element.reference_strain(P[:1], P[1:])
        h0 = e0[0] * l[0]
        for rot in ANGLES:
            for _ in range(n):
                h = h0 + 0.2 * np.abs(h0).max() * rng.standard_normal(6)
                if rot is not None:
                    h[3:] = random_rotation_vector(rng, rot)
                A = random_pose(rng, angle=3.0)
                HA.append(A)
                HB.append(A @ se3.exp(h))
                L.append(l[0])
                eps0.append(e0[0])
                C.append(spd_matrix(rng) if full_C else DIAG)
    return np.array(HA), np.array(HB), np.array(L), np.array(eps0), np.array(C)


def _per_element_error(a, b):
    a, b = a.reshape(len(a), -1), b.reshape(len(b), -1)
    return np.abs(a - b).max(axis=1) / np.maximum(np.abs(b).max(axis=1), 1e-300)


@pytest.mark.parametrize("full_C", [False, True])
def test_element_kernel_equals_numpy_oracle(full_C):
    rng = np.random.default_rng(zlib.crc32(repr(("jit", full_C)).encode()))
    args = _batch(rng, full_C)
    f, K, s = element.internal_forces_and_tangent(*args)
    f0, K0, s0 = reference.internal_forces_and_tangent_numpy(*args)
    assert np.isfinite(K).all() and np.isfinite(f).all()
    assert _per_element_error(f, f0).max() < ROUND_OFF
    assert _per_element_error(K, K0).max() < ROUND_OFF
    assert _per_element_error(s.h, s0.h).max() < ROUND_OFF
    assert _per_element_error(s.sigma, s0.sigma).max() < 1e-10    # C (h/L - eps0): cancellation
    f1, s1 = element.internal_forces(*args)
    f2, _ = reference.internal_forces_numpy(*args)
    assert np.array_equal(f1, f) and np.array_equal(s1.h, s.h)
    assert _per_element_error(f1, f2).max() < ROUND_OFF


def test_element_kernel_writes_into_out_and_checks_its_shape():
    rng = np.random.default_rng(3)
    args = _batch(rng, False, n=1)
    n = len(args[2])
    out = np.full((n, 12, 12), np.nan)
    _, K, _ = element.internal_forces_and_tangent(*args, out=out)
    assert np.shares_memory(K, out) and np.isfinite(out).all()
    with pytest.raises(ValueError, match="out must have shape"):
        element.internal_forces_and_tangent(*args, out=np.empty((n + 1, 12, 12)))


def test_reference_strain_equals_se3_log():
    P = geometry.helix(0.4, 1.5, 3.0, 9)
    L, eps0 = element.reference_strain(P[:-1], P[1:])
    h = se3.log(se3.relative(P[:-1], P[1:]))
    np.testing.assert_allclose(eps0 * L[:, None], h, rtol=0, atol=1e-14 * np.abs(h).max())


def test_scatter_equals_bincount():
    rng = np.random.default_rng(1)
    pos = rng.integers(0, 50, 1000)
    vals = rng.standard_normal(1000)
    data = np.full(51, np.nan)
    assembly_jit.scatter(pos, vals, data)
    np.testing.assert_allclose(data, np.bincount(pos, weights=vals, minlength=51), rtol=1e-13, atol=1e-13)


def _hat_numpy(v):
    """``assembly.System._global_node_terms``' former ``hat`` of real 3-vectors ``(k, 3)``: one stack."""
    z = np.zeros(len(v))
    x, y, w = v[:, 0], v[:, 1], v[:, 2]
    return np.stack([z, -w, y, w, z, -x, -y, x, z], axis=1).reshape(-1, 3, 3)


def test_global_node_values_give_the_bits_of_the_numpy_form():
    rng = np.random.default_rng(3)
    r = rng.standard_normal(6 * 9)
    r[6 * 4:6 * 5] = [0.0, -0.0, 1.0, -2.0, 0.0, -0.0]            # signed zeros
    g = np.array([1, 4, 7])
    rg = r.reshape(-1, 6)[g]
    want = -np.concatenate([_hat_numpy(rg[:, :3]), _hat_numpy(rg[:, 3:])], axis=1)
    got = np.empty((3, 6, 3))
    assembly_jit.global_node_values(r, g, got)
    assert np.array_equal(got.view(np.int64), want.view(np.int64))     # bit for bit, the signs of zeros too


def test_compose_exp_equals_se3():
    rng = np.random.default_rng(2)
    H = random_pose(rng, angle=3.0, shape=(6,))
    dz = np.concatenate([rng.standard_normal((6, 3)), random_rotation_vector(rng, [0, 1e-9, 0.3, 1.0, 3.0, 3.1])],
                        axis=1)
    dz[3] = 0.0                                    # skipped: the pose stays bit for bit
    nodes = np.array([0, 2, 3, 4, 5])
    H1 = H.copy()
    assembly_jit.compose_exp(H1, dz, nodes)
    np.testing.assert_allclose(H1[nodes], se3.compose(H[nodes], se3.exp(dz[nodes])), atol=1e-14 * 4)
    assert np.array_equal(H1[1], H[1]) and np.array_equal(H1[3], H[3])


@pytest.mark.parametrize("reverse", [False, True])
def test_chain_update_equals_numpy_oracle(reverse):
    """Strain-space update of a cantilever (anchored at either end), compiled vs ``System.rechain_numpy``."""
    m = bs.Model()
    beam = m.add_beam(geometry.helix(0.4, 1.5, 3.0, 12), bs.Section.circular(radius=0.01, E=1e9))
    m.clamp(beam.last if reverse else beam.first)
    system = System(m)
    assert len(system.chains) == 1
    rng = np.random.default_rng(4)
    H = system.update(system.poses0, 1e-2 * rng.standard_normal((system.n_nodes, 6)), chains=False)
    dz = 0.3 * rng.standard_normal((system.n_nodes, 6))
    dz[system.chains[0][0][0]] = 0.0                       # the anchor
    H_jit = system.update(H, dz)
    H_np = H.copy()
    body = system.body_nodes
    H_np[body] = se3.compose(H[body], se3.exp(dz[body]))
    system.rechain_numpy(H, H_np, dz)
    np.testing.assert_allclose(H_jit, H_np, rtol=0, atol=1e-13)


def _run(code, **env):
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600,
                         env={**os.environ, "PYTHONPATH": str(ROOT), **env}, cwd=ROOT)
    assert out.returncode == 0, out.stderr[-3000:]
    return out.stdout


@pytest.mark.slow
def test_kernel_tests_pass_without_jit():
    """``NUMBA_DISABLE_JIT=1`` (plain Python, for debugging and coverage) runs the same checks."""
    out = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", __file__,
                          "-k", "not without_jit and not cache"], capture_output=True, text=True, timeout=900,
                         env={**os.environ, "PYTHONPATH": str(ROOT), "NUMBA_DISABLE_JIT": "1"}, cwd=ROOT / "tests")
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-2000:]
    assert " passed" in out.stdout


@pytest.mark.slow
def test_second_process_loads_the_cache():
    """Compiled once per machine: a later process loads every kernel from numba's cache."""
    code = """
import json, numpy as np
from beamsolver import geometry
from beamsolver.assembly import compiled as assembly_jit
from beamsolver.elements import element
from beamsolver.elements import element_jit
P = geometry.helix(0.4, 1.5, 3.0, 4 * 2)[:5]
L, e0 = element.reference_strain(P[:-1], P[1:])
C = np.broadcast_to(np.diag([1e3, 4e2, 5e2, 20.0, 30.0, 40.0]), (4, 6, 6))
element.internal_forces_and_tangent(P[:-1], P[1:], L, e0, C)
element.internal_forces(P[:-1], P[1:], L, e0, np.broadcast_to(np.eye(6) + 0.1, (4, 6, 6)))
d = np.zeros(8)
assembly_jit.scatter(np.arange(4), np.ones(4), d)
H = P.copy()
assembly_jit.compose_exp(H, np.zeros((5, 6)), np.arange(5))
assembly_jit.rechain(P, H, np.zeros((5, 6)), np.arange(5), np.array([0, 5]))
misses = {f.__name__: sum(f.stats.cache_misses.values()) for f in
          (element_jit.evaluate, element_jit.relative_twists, assembly_jit.scatter, assembly_jit.compose_exp,
           assembly_jit.rechain)}
print(json.dumps(misses))
"""
    _run(code)                                   # compiles whatever is not cached yet
    misses = json.loads(_run(code).strip().splitlines()[-1])
    assert all(v == 0 for v in misses.values()), misses


def test_dead_loads_equal_numpy():
    rng = np.random.default_rng(5)
    H = random_pose(rng, angle=3.0, shape=(5,))
    nodes = np.array([4, 1, 1])
    F, M = rng.standard_normal((3, 3)), rng.standard_normal((3, 3))
    fb, kb = np.empty((3, 6)), np.full((3, 6, 6), np.nan)
    assembly_jit.dead_loads(H, nodes, F, M, fb, kb)
    Rt = np.swapaxes(H[nodes, :3, :3], 1, 2)
    fu, fw = np.einsum("nij,nj->ni", Rt, F), np.einsum("nij,nj->ni", Rt, M)
    np.testing.assert_allclose(fb, np.concatenate([fu, fw], axis=1), atol=1e-14)
    expected = np.zeros((3, 6, 6))
    expected[:, :3, 3:], expected[:, 3:, 3:] = -se3.skew(fu), -se3.skew(fw)
    np.testing.assert_allclose(kb, expected, atol=1e-14)
