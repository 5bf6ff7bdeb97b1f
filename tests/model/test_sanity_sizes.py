"""Step-0 sanity warnings for implausible sizes (issue 29 item 4): ``bs.GeometryWarning``."""
import warnings

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.model import sanity


def _pair(radius, gap_axis, n=4, length=1.0, radius2=None):
    """Two straight parallel beams along x, ``gap_axis`` apart in y (centre to centre)."""
    m = bs.Model()
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (length, 0, 0), n), bs.Section.circular(radius=radius, E=2e11))
    b = m.add_beam(bs.geometry.straight((0, gap_axis, 0), (length, gap_axis, 0), n),
                   bs.Section.circular(radius=radius if radius2 is None else radius2, E=2e11))
    return m, a, b


def _kinds(model):
    return [k for k, _ in sanity.size_problems(model)]


def test_radius_in_millimetres_in_a_metre_model_warns_with_the_numbers():
    """The issue's unit mistake: wires of R = 0.5 mm, 1 mm apart, radius typed as 0.5 (mm) in a metre model."""
    m, a, b = _pair(0.5, 1e-3)
    problems = sanity.size_problems(m)
    assert [k for k, _ in problems] == ["overlap"]
    text = problems[0][1]
    assert "radius 0.5" in text and "0.001 apart" in text and repr(a) in text and repr(b) in text
    with pytest.warns(bs.GeometryWarning, match=r"radius in another unit.*0\.001 apart"):
        sanity.check_sizes(m)


def test_correct_units_touching_wires_do_not_warn():
    """The same wires with R = 0.5 mm: touching (1 mm = R1 + R2 apart), plausible."""
    m, _, _ = _pair(0.5e-3, 1e-3)
    assert _kinds(m) == []
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sanity.check_sizes(m)


def test_unequal_radii_compare_with_half_the_larger_radius():
    """A rope (0.1) on a post (1.0): touching at 1.1 and a start pressed 0.15 into the post (0.95: the
    capstan's rope pulled onto its post) are plausible; at 0.45 the post's tube holds the rope's centre line
    deep inside."""
    assert _kinds(_pair(1.0, 1.1, radius2=0.1, length=10.0)[0]) == []
    assert _kinds(_pair(1.0, 0.95, radius2=0.1, length=10.0)[0]) == []
    assert _kinds(_pair(1.0, 0.45, radius2=0.1, length=10.0)[0]) == ["overlap"]


def test_radius_larger_than_the_beam_warns():
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (0.2, 0, 0), 2), bs.Section.circular(radius=0.3, E=1e9))
    problems = sanity.size_problems(m)
    assert [k for k, _ in problems] == ["radius"]
    assert "radius 0.3, larger than its length 0.2" in problems[0][1] and repr(b) in problems[0][1]


def test_crossing_between_nodes_is_found():
    """Two one-element beams crossing at mid-span 0.04 apart with R = 0.1: no node is near the other beam
    (a node-only test would miss it), the segments are."""
    m = bs.Model()
    m.add_beam(bs.geometry.straight((-1, 0, 0), (1, 0, 0), 1), bs.Section.circular(radius=0.1, E=1e9))
    m.add_beam(bs.geometry.straight((0, -1, 0.04), (0, 1, 0.04), 1), bs.Section.circular(radius=0.1, E=1e9))
    problems = sanity.size_problems(m)
    assert [k for k, _ in problems] == ["overlap"] and "0.04 apart" in problems[0][1]
    m2 = bs.Model()
    m2.add_beam(bs.geometry.straight((-1, 0, 0), (1, 0, 0), 1), bs.Section.circular(radius=0.1, E=1e9))
    m2.add_beam(bs.geometry.straight((0, -1, 0.2), (0, 1, 0.2), 1), bs.Section.circular(radius=0.1, E=1e9))
    assert _kinds(m2) == []


def test_joined_beams_are_not_compared():
    """A frame corner: two beams meeting at a joined node (their centre lines meet) is no problem."""
    m = bs.Model()
    sec = bs.Section.circular(radius=0.05, E=1e9)
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), sec)
    b = m.add_beam(bs.geometry.straight((1, 0, 0), (1, 1, 0), 4), sec)
    m.join(a.last, b.first)
    assert _kinds(m) == []
    m2 = bs.Model()
    a = m2.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), sec)
    b = m2.add_beam(bs.geometry.straight((1, 0, 0), (1, 1, 0), 4), sec)
    assert _kinds(m2) == ["overlap"]           # the same corner not joined: two beams through one point


def test_joined_through_a_free_node_are_not_compared():
    """Wire ends rigidly linked to a plate node (``add_node``), as the twisted pair's clamps."""
    m = bs.Model()
    sec = bs.Section.circular(radius=0.05, E=1e9)
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), sec)
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (0, 1, 0), 4), sec)
    plate = m.add_node(np.eye(4))
    m.join(a.first, plate, rigid=True)
    m.join(b.first, plate, rigid=True)
    assert _kinds(m) == []


@pytest.mark.slow
def test_segment_distances_against_sampling():
    rng = np.random.default_rng(3)
    a0, a1, b0, b1 = (rng.standard_normal((200, 3)) for _ in range(4))
    b1[:20] = b0[:20] + 1e-3 * (a1[:20] - a0[:20])          # nearly parallel
    b1[20:30] = b0[20:30]                                   # a point
    d = sanity.segment_distances(a0, a1, b0, b1)
    s = np.linspace(0, 1, 401)
    P = a0[:, None] + s[None, :, None] * (a1 - a0)[:, None]
    Q = b0[:, None] + s[None, :, None] * (b1 - b0)[:, None]
    brute = np.min(np.linalg.norm(P[:, :, None] - Q[:, None, :], axis=-1), axis=(1, 2))
    assert np.all(d <= brute + 1e-12)
    np.testing.assert_allclose(d, brute, atol=2e-2)       # sampling at 1/400 of the segments' lengths


def test_solve_warns_at_step_zero():
    """``solve`` says it before the first step (no contact declared: nothing else stops the run)."""
    m, a, b = _pair(0.5, 1e-3, n=2)
    for beam in (a, b):
        m.clamp(beam.first)
        m.add_load(beam.last, force=(0, 0, -1.0))
    with pytest.warns(bs.GeometryWarning, match="0.001 apart"):
        sol = bs.solve(m, steps=1, verbose=False)
    assert sol.n_steps == 1
