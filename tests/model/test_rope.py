"""Rope builder (``cables.build_rope``): counts, lay lengths, the double helix, no overlap at the start."""
import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.spatial import cKDTree

import beamsolver as bs
from beamsolver.model.geometry import double_helix_points as double_helix

L = bs.cables.Layer
WIRE_CORE = [L(0.55e-3), L(0.5e-3, 6, lay_length=0.04)]           # a 1+6 wire strand core
STRAND = [L(0.5e-3), L(0.45e-3, 6, lay_length=0.03, direction="left")]
ROPE_LAY = 0.06


@pytest.fixture(scope="module")
def rope():
    """A 6 x 7 rope around a 1+6 wire strand core, one rope lay long."""
    return bs.cables.build_rope(STRAND, length=ROPE_LAY, E=2e11, lay_length=ROPE_LAY, core=WIRE_CORE)


def _centre(beam, model):
    return model.poses0[beam.nodes, :3, 3]


def _dense(x, per=8):
    """Points along the chords of the polyline ``x`` (n, 3), ``per`` per element."""
    t = np.linspace(0.0, 1.0, per, endpoint=False)
    return np.concatenate([(x[:-1, None] * (1 - t)[:, None] + x[1:, None] * t[:, None]).reshape(-1, 3), x[-1:]])


def test_counts_and_contacts(rope):
    assert len(rope.core) == 2 and [len(layer) for layer in rope.core] == [1, 6]
    assert len(rope.strands) == 6 and all([len(layer) for layer in s] == [1, 6] for s in rope.strands)
    assert len(rope.all_wires) == 7 + 6 * 7
    assert len({b.name for b in rope.all_wires}) == 49
    # a strand's lay along z is 0.03 cos(alpha) < the rope lay: 24 elements per that lay
    n_outer = len(rope.strands[0][1][0].nodes) - 1
    assert n_outer == int(np.ceil(24 * ROPE_LAY / (0.03 * np.cos(rope.lay_angle))))
    assert len(rope.strands[0][0][0].nodes) - 1 == 24           # centre wire: the rope lay
    assert all(len(w.nodes) - 1 >= n_outer for layer in rope.core for w in layer)
    # the strands sit on the core: envelope radii add up
    assert rope.pitch_radius == pytest.approx(rope.core_envelope + rope.envelope, rel=1e-12)
    assert rope.envelope == pytest.approx(0.5e-3 + 0.45e-3 + 0.45e-3)
    assert rope.core_envelope == pytest.approx(0.55e-3 + 0.5e-3 + 0.5e-3)
    # the core strand's (layer on core, 6 touching neighbours), per strand the same, strands on the core;
    # neighbouring strands keep a clearance above touch_tol: no declaration between them
    assert len(rope.core_strand.contacts) == 7
    assert rope.clearance > 0.05 * 2 * 0.45e-3
    assert len(rope.contacts) == 7 + 6 * 7 + 1
    on_core = rope.contacts[-1]
    assert {b.name for b in on_core.slave} == {w.name for s in rope.strands for w in s[1]}
    assert {b.name for b in on_core.master} == {w.name for w in rope.core[1]}


def test_lay_lengths(rope):
    """The strands' centre wires turn once about the axis per rope lay; an outer wire turns once
    about its strand's centre line per strand lay (measured along that line)."""
    m = rope.model
    for j, s in enumerate(rope.strands):
        x = _centre(s[0][0], m)
        ang = np.unwrap(np.arctan2(x[:, 1], x[:, 0]))
        assert np.exp(1j * ang[0]) == pytest.approx(np.exp(2j * np.pi * j / 6))
        assert ang[-1] - ang[0] == pytest.approx(2 * np.pi, rel=1e-12)       # one rope lay, right lay
        np.testing.assert_allclose(np.hypot(x[:, 0], x[:, 1]), rope.pitch_radius, rtol=1e-12)
    # wire 0 of strand 0's outer layer: distance r_1 from the strand's centre line in its normal
    # plane, at the angle phi = phi_0 - 2 pi s / 0.03 (left lay), s the arc length along that line
    R_s, P = rope.pitch_radius, rope.lay_length
    c = P / (2 * np.pi)
    Ls = np.hypot(R_s, c)
    r1 = rope.strand_geometry[1][0]
    x = _centre(rope.strands[0][1][0], m)
    assert x[0, 2] == 0.0 and x[-1, 2] == ROPE_LAY                     # ends on the end planes

    def frame(th):
        C = np.array([R_s * np.cos(th), R_s * np.sin(th), c * th])
        T = np.array([-R_s * np.sin(th), R_s * np.cos(th), c]) / Ls
        N = np.array([-np.cos(th), -np.sin(th), 0.0])
        return C, T, N, np.cross(T, N)
    phi, s = [], []
    for p in x:
        th = brentq(lambda t: np.dot(p - frame(t)[0], frame(t)[1]), p[2] / c - 0.5, p[2] / c + 0.5, xtol=1e-15)
        C, T, N, B = frame(th)
        d = p - C
        assert np.linalg.norm(d) == pytest.approx(r1, rel=1e-10)
        phi.append(np.arctan2(d @ B, d @ N))
        s.append(Ls * th)
    phi, s = np.unwrap(phi), np.array(s)
    np.testing.assert_allclose(phi - phi[0], -2 * np.pi * (s - s[0]) / 0.03, atol=1e-10)


def test_double_helix_tangent():
    """The exact tangent against central differences of the points."""
    z = np.linspace(0.0, 0.05, 7)
    x, t = double_helix(3e-3, 0.06 / (2 * np.pi), 1e-3, 0.3, -2 * np.pi / 0.02, z)
    h = 1e-7
    d = (double_helix(3e-3, 0.06 / (2 * np.pi), 1e-3, 0.3, -2 * np.pi / 0.02, z + h)[0]
         - double_helix(3e-3, 0.06 / (2 * np.pi), 1e-3, 0.3, -2 * np.pi / 0.02, z - h)[0]) / (2 * h)
    np.testing.assert_allclose(t, d / np.linalg.norm(d, axis=1, keepdims=True), atol=1e-8)


def test_no_overlap_at_the_start(rope):
    """Every pair of wires of different strands, and strands against the core: centre lines at least
    the sum of the radii apart (chords sampled, within 1e-4 of a wire radius); the strands' outer
    wires touch the core's (within 2 % of a radius), and neighbouring strands keep the clearance
    of their envelopes."""
    m = rope.model
    groups = [[w for layer in rope.core for w in layer]] + [[w for layer in s for w in layer] for s in rope.strands]
    pts = [[_dense(_centre(w, m)) for w in g] for g in groups]
    radius = {b.name: R for b, R in zip(rope.all_wires, _radii(rope))}
    least = np.full(2, np.inf)              # strands on the core, strands on each other
    for a in range(len(groups)):
        for b in range(a + 1, len(groups)):
            for wa, xa in zip(groups[a], pts[a]):
                tree = cKDTree(xa)
                for wb, xb in zip(groups[b], pts[b]):
                    d = tree.query(xb)[0].min() - radius[wa.name] - radius[wb.name]
                    assert d >= -1e-4 * 0.45e-3, (wa.name, wb.name, d)
                    least[int(a > 0)] = min(least[int(a > 0)], d)
    assert least[0] < 0.02 * 0.45e-3                   # the strands sit on the core
    assert least[1] >= rope.clearance - 1e-4 * 0.45e-3  # and keep their envelopes' clearance


def _radii(rope):
    out = []
    for layer in rope.core_strand.layers:
        out += [layer.wire_radius] * layer.n_wires
    for _ in rope.strands:
        for layer in rope.strand_layers:
            out += [layer.wire_radius] * layer.n_wires
    return out


def test_fibre_core_and_closing_strands():
    """A thin fibre core: the strands close on each other (not on the core), the envelopes touch."""
    core = bs.Section.circular(radius=0.5e-3, E=1e9)
    r = bs.cables.build_rope(STRAND, length=0.02, E=2e11, lay_length=ROPE_LAY, core=core)
    assert len(r.all_wires) == 1 + 42
    assert r.pitch_radius > r.core_envelope + r.envelope
    assert r.clearance == pytest.approx(0.0, abs=1e-12)
    assert r.core[0][0].name == "core"


def test_bad_input():
    with pytest.raises(bs.InputError, match="pitch_radius 0.002"):
        bs.cables.build_rope(STRAND, length=0.02, E=2e11, lay_length=ROPE_LAY, core=WIRE_CORE, pitch_radius=0.002)
    with pytest.raises(bs.InputError, match="core must be"):
        bs.cables.build_rope(STRAND, length=0.02, E=2e11, lay_length=ROPE_LAY, core=None)
    with pytest.raises(bs.InputError, match="exactly one of lay_length, lay_angle"):
        bs.cables.build_rope(STRAND, length=0.02, E=2e11, core=WIRE_CORE)
    with pytest.raises(bs.InputError, match="n_strands"):
        bs.cables.build_rope(STRAND, length=0.02, E=2e11, lay_length=ROPE_LAY, core=WIRE_CORE, n_strands=1)


def test_double_helix_poses():
    """``geometry.double_helix``: orthonormal frames, ``e1`` along the chords to second order, the strand
    phase a rotation about ``e_z``; a zero pitch refused."""
    P0 = bs.geometry.double_helix(3e-3, 0.06, 1e-3, -0.02, 0.04, 64, phase=0.3)
    P1 = bs.geometry.double_helix(3e-3, 0.06, 1e-3, -0.02, 0.04, 64, phase=0.3, strand_phase=1.0)
    R = P0[:, :3, :3]
    np.testing.assert_allclose(np.einsum("nji,njk->nik", R, R), np.broadcast_to(np.eye(3), R.shape), atol=1e-13)
    chord = np.diff(P0[:, :3, 3], axis=0)
    chord /= np.linalg.norm(chord, axis=1, keepdims=True)
    mid = P0[:-1, :3, 0] + P0[1:, :3, 0]
    mid /= np.linalg.norm(mid, axis=1, keepdims=True)
    assert np.max(np.linalg.norm(chord - mid, axis=1)) < 1e-3
    rot = np.array([[np.cos(1.0), -np.sin(1.0), 0], [np.sin(1.0), np.cos(1.0), 0], [0, 0, 1]])
    np.testing.assert_allclose(P1[:, :3, 3], P0[:, :3, 3] @ rot.T, atol=1e-15)
    with pytest.raises(bs.InputError, match="pitch must be finite and non-zero"):
        bs.geometry.double_helix(3e-3, 0.06, 1e-3, 0.0, 0.04, 64)
