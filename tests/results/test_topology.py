"""Twist and writhe (``beamsolver.topology``) against closed forms: a straight twisted ribbon, a helix
(Fuller: ``Wr = n (1 - cos theta)``), planar closed curves, and ``Lk = Tw + Wr`` on a closed
non-planar ribbon (``Lk`` from the Gauss linking integral of its two edges)."""
import numpy as np
import pytest

from beamsolver import InputError, topology as T


def _helix(n_turns, theta, N, r=1.0):
    """A helix of ``n_turns`` with pitch angle ``theta`` (tangent . e_z = cos theta), N segments."""
    rise = 2 * np.pi * r / np.tan(theta)
    phi = np.linspace(0, 2 * np.pi * n_turns, N + 1)
    return np.stack([r * np.cos(phi), r * np.sin(phi), rise * phi / (2 * np.pi)], 1)


@pytest.mark.parametrize("turns", [0.0, 0.4, 2.3, -5.0])
def test_straight_twisted_ribbon(turns):
    z = np.linspace(0, 1, 33)
    axis = np.stack([0 * z, 0 * z, z], 1)
    u = np.stack([np.cos(2 * np.pi * turns * z), np.sin(2 * np.pi * turns * z), 0 * z], 1)
    assert T.twist(axis, u) == pytest.approx(turns, abs=1e-12)
    assert T.writhe_open(axis) == 0.0
    assert T.writhe_fuller(axis) == 0.0


def test_helix_writhe_converges_to_fuller_closed_form():
    n, theta = 3, 0.5
    exact = n * (1 - np.cos(theta))
    err_open, err_fuller = [], []
    for N in (100, 200, 400):
        p = _helix(n, theta, N)
        err_open.append(abs(T.writhe_open(p) - exact))
        err_fuller.append(abs(T.writhe_fuller(p) - exact))
    for err in (err_open, err_fuller):
        assert err[0] > err[1] > err[2]
        assert np.polyfit(np.log([100, 200, 400]), np.log(err), 1)[0] < -1.0
        assert err[-1] < 4e-3 * exact


def test_closure_and_fuller_agree_where_fuller_holds():
    """A curve leaving and reaching the axis along it (as the twisted pair) with a helical bulge."""
    s = np.linspace(0, 1, 801)
    bump = np.sin(np.pi * s) ** 2
    p = np.stack([0.3 * bump * np.cos(6 * np.pi * s), 0.3 * bump * np.sin(6 * np.pi * s), s], 1)
    wf = T.writhe_fuller(p)
    assert abs(wf) > 0.1
    assert T.writhe_open(p) == pytest.approx(wf, abs=2e-3 * abs(wf))
    assert T.writhe_open(p, extension=1e4) == pytest.approx(T.writhe_open(p), abs=1e-6)


def test_fuller_refuses_a_returning_tangent():
    """An arm running back down (a plectoneme's): Fuller's formula does not hold there."""
    p = np.array([[0, 0, 0], [0, 0, 1], [0.01, 0, 0.5], [0.02, 0, 0.0], [0.03, 0, -0.5], [0.05, 0, 1]], float)
    with pytest.raises(InputError, match="Fuller"):
        T.writhe_fuller(p)
    assert np.isfinite(T.writhe_open(p))


@pytest.mark.parametrize("shape", ["ring", "ellipse", "square"])
def test_planar_closed_curves_have_no_writhe(shape):
    phi = np.linspace(0, 2 * np.pi, 65)[:-1]
    if shape == "ring":
        p = np.stack([np.cos(phi), np.sin(phi), 0 * phi], 1)
    elif shape == "ellipse":
        p = np.stack([3 * np.cos(phi), np.sin(phi), 0 * phi], 1)
    else:
        p = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    assert abs(T.writhe_closed(p)) < 1e-12


def test_calugareanu_on_a_closed_nonplanar_ribbon():
    """A (2, 3) torus-knot-like curve (non-planar, writhe not an integer) with a ribbon turning 3
    times in its normal plane: Lk (integer) = Tw + Wr."""
    N = 600
    s = np.linspace(0, 2 * np.pi, N + 1)[:-1]
    x = np.stack([(2 + 0.6 * np.cos(3 * s)) * np.cos(s), (2 + 0.6 * np.cos(3 * s)) * np.sin(s),
                  0.6 * np.sin(3 * s)], 1)
    closed = np.vstack([x, x[:1]])
    t = T.node_tangents(np.vstack([x[-1:], x, x[:1]]))[1:-1]
    ref = np.cross(t, [0.0, 0.0, 1.0])
    ref /= np.linalg.norm(ref, axis=1)[:, None]
    b = np.cross(t, ref)
    u = np.cos(3 * s)[:, None] * ref + np.sin(3 * s)[:, None] * b
    tw = T.twist(closed, np.vstack([u, u[:1]]), tangents=np.vstack([t, t[:1]]))
    wr = T.writhe_closed(x)
    lk = T.linking(x, x + 1e-2 * u)            # exact for polygons: an integer
    assert lk == pytest.approx(3.0, abs=1e-9)
    assert tw + wr == pytest.approx(lk, abs=5e-4)
    assert abs(wr - round(wr)) > 0.05          # a genuine test: the writhe is not an integer
