"""The element contract (``beamsolver.elements``): every registered type keeps it, and the two-node
type is today's element, bit for bit."""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver import elements, geometry, se3
from beamsolver.elements import element
from beamsolver.assembly.system import System
from beamsolver.errors import InputError

from helpers import spd_matrix

TYPES = sorted(elements.TYPES)


def _batch(etype, rng, n=3):
    """Reference poses ``(n, k, 4, 4)`` on a helix, a full ``C``, the reference and a deformed state."""
    k = etype.n_nodes
    P = geometry.helix(0.4, 1.5, 3.0, 16)[:(k - 1) * n + 1]
    P0 = P[etype.connectivity(n)]
    C = np.stack([spd_matrix(rng) for _ in range(n)])
    ref = etype.reference(P0, C)
    H = P0 @ se3.exp(0.1 * rng.standard_normal((n, k, 6)))
    return P0, ref, H


@pytest.mark.parametrize("name", TYPES)
def test_shapes_and_node_table(name, rng):
    etype = elements.get(name)
    k, n = etype.n_nodes, 3
    P0, ref, H = _batch(etype, rng, n)
    assert ref.L.shape == (n,) and ref.eps0.shape == (n, 6) and ref.C.shape == (n, 6, 6)
    f, K, state = etype.evaluate(H, None, ref, True)
    assert f.shape == (n, 6 * k) and K.shape == (n, 6 * k, 6 * k)
    assert all(x.shape == (n, 6) for x in state)
    # the same elements read through a node table from a shuffled pose array
    perm = rng.permutation(n * k)
    Hg = np.empty((n * k, 4, 4))
    Hg[perm] = H.reshape(n * k, 4, 4)
    nodes = perm.reshape(n, k)
    f2, K2, s2 = etype.evaluate(Hg, nodes, ref, True)
    np.testing.assert_array_equal(f2, f)
    np.testing.assert_array_equal(K2, K)
    out = np.full((n, 6 * k, 6 * k), np.nan)
    assert etype.evaluate(H, None, ref, True, out=out)[1] is out and np.array_equal(out, K)
    assert etype.evaluate(H, None, ref, False)[1] is None


@pytest.mark.parametrize("name", TYPES)
def test_energy_is_the_potential_of_the_forces(name, rng):
    """``energy`` is zero at the reference and its derivative along body increments ``H exp(s q)``
    is ``f . q`` (central differences; the contract stabilisation relies on)."""
    etype = elements.get(name)
    P0, ref, H = _batch(etype, rng)
    n, k = H.shape[:2]
    assert etype.energy(P0, None, ref).shape == (n,) and np.abs(etype.energy(P0, None, ref)).max() < 1e-20
    f, _, _ = etype.evaluate(H, None, ref, False)
    q = rng.standard_normal((n, k, 6))
    s = 1e-6
    dE = (etype.energy(H @ se3.exp(s * q), None, ref) - etype.energy(H @ se3.exp(-s * q), None, ref)) / (2 * s)
    np.testing.assert_allclose(dE, np.einsum("ni,ni->n", f, q.reshape(n, 6 * k)), rtol=1e-6)


@pytest.mark.parametrize("name", TYPES)
def test_reference_state_and_interpolation(name, rng):
    etype = elements.get(name)
    P0, ref, H = _batch(etype, rng)
    f, _, state = etype.evaluate(P0, None, ref, False)
    assert np.abs(f).max() < 1e-10 and np.abs(state.sigma).max() < 1e-10
    np.testing.assert_allclose(state.strain, ref.eps0, atol=1e-13)
    # interpolation passes through the end nodes (xi = 0, 1)
    n = len(H)
    e = np.repeat(np.arange(n), 2)
    pts = etype.interpolate(H, e, np.tile([0.0, 1.0], n))
    np.testing.assert_allclose(pts.reshape(n, 2, 4, 4), H[:, [0, -1]], atol=1e-13)
    assert etype.rotation_angles(H).shape == (n, len(etype.rotation_pairs))
    assert 0.0 < etype.max_rotation < np.pi


def test_se3_2_is_the_two_node_element_bit_for_bit(rng):
    etype = elements.get("se3-2")
    P0, ref, H = _batch(etype, rng, n=5)
    L, eps0 = element.reference_strain(P0[:, 0], P0[:, 1])
    np.testing.assert_array_equal(ref.L, L)
    np.testing.assert_array_equal(ref.eps0, eps0)
    f, K, s = etype.evaluate(H, None, ref, True)
    f1, K1, s1 = element.internal_forces_and_tangent(H[:, 0], H[:, 1], L, eps0, ref.C)
    np.testing.assert_array_equal(f, f1)
    np.testing.assert_array_equal(K, K1)
    for a, b in zip(s, s1):
        np.testing.assert_array_equal(a, b)


def test_assembly_uses_one_group_and_the_end_nodes_for_two_node_models():
    m = bs.Model()
    b = m.add_beam(geometry.arc(radius=1.0, angle=1.2, n_elements=4), bs.Section.circular(radius=0.01, E=1e9))
    m.clamp(b.first)
    system = System(m)
    assert len(system.groups) == 1 and system.groups[0].element_type is elements.get()
    np.testing.assert_array_equal(system.enodes, np.stack([b.nodes[:-1], b.nodes[1:]], axis=1))
    np.testing.assert_array_equal(system.rotation_pairs, system.enodes)
    assert system.group_edofs[0].shape == (4, 12)


def test_registry():
    assert elements.get() is elements.get("se3-2")
    t = elements.get("se3-3")
    assert elements.get(t) is t
    with pytest.raises(InputError, match="element must be one of"):
        elements.get(3)
