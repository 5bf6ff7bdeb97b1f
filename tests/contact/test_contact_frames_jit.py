"""``contact.frames_jit.material_frames``: the bits of ``frames.material_frames`` (numpy)."""
import numpy as np

from beamsolver.contact import frames, frames_jit
from beamsolver.lie import se3

from helpers import assert_same_bits as _same


def _pairs(rng, m, scale):
    H = se3.exp(rng.standard_normal((4 * m, 6)) * scale)
    nodes = rng.permutation(4 * m).reshape(m, 4)
    h1 = se3.log(se3.relative(H[nodes[:, 0]], H[nodes[:, 1]]))
    h2 = se3.log(se3.relative(H[nodes[:, 2]], H[nodes[:, 3]]))
    xi1, xi2 = rng.uniform(-1, 1, m), rng.uniform(-1, 1, m)
    return H, nodes, h1, h2, xi1, xi2, rng.uniform(0.1, 1, m), rng.uniform(0.1, 1, m)


def test_material_frames_give_the_bits_of_the_numpy_frames():
    rng = np.random.default_rng(0)
    for scale in (1e-3, 0.3, 1.5):
        H, nodes, h1, h2, xi1, xi2, R1, R2 = _pairs(rng, 400, scale)
        ref = frames.material_frames(H[nodes], np.zeros(len(nodes), int), xi1, xi2, R1, R2, h1, h2)
        out = frames_jit.material_frames(H, nodes, xi1, xi2, R1, R2, h1, h2)
        for r, o in zip(ref, out):
            assert np.isfinite(o).all()
            _same(o, r)


def test_material_frames_without_a_normal_are_nan_as_numpy():
    """Centre lines through one point: no normal, NaN frames in both (the caller drops them)."""
    rng = np.random.default_rng(1)
    H, nodes, h1, h2, xi1, xi2, R1, R2 = _pairs(rng, 3, 0.3)
    H[nodes[0, 2]] = H[nodes[0, 0]]           # master element = slave element: sections coincide
    H[nodes[0, 3]] = H[nodes[0, 1]]
    h2[0] = h1[0]
    xi2[0] = xi1[0]
    ref = frames.material_frames(H[nodes], np.zeros(3, int), xi1, xi2, R1, R2, h1, h2)
    out = frames_jit.material_frames(H, nodes, xi1, xi2, R1, R2, h1, h2)
    assert np.isnan(out[2][0]).any() and np.isfinite(out[2][1:]).all()
    for r, o in zip(ref, out):
        _same(o, r)
