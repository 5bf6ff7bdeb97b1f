"""The contact search's work per slave point stays bounded as the elements get finer (issue 30, item 2),
and the cull that bounds it (``projection.gauss_projections(window=)``) only drops rows the ownership
would reject.  Counts, not times (``benchmarks/search_scaling.py`` times it)."""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver import se3
from beamsolver.contact import pairs, projection, rules
from beamsolver.contact import system as contact_system
from beamsolver.nonlinear.problem import Problem

R = 0.5e-3             # wire radius: the elements of the finest mesh below are ~R / 10 long
PITCH = 30e-3           # two-ply lay: ply angle atan(2 pi R / PITCH) = 6 deg, the wires 12 deg apart: line contact


def two_ply(n_elements, length=PITCH, **options):
    """Two touching helical wires (a two-ply, centre lines 2 R apart), ``n_elements`` each, in contact
    (``options``: of ``add_contact``)."""
    sec = bs.Section.circular(radius=R, E=200e9)
    m = bs.Model()
    a = m.add_beam(bs.geometry.helix(R, PITCH, length, n_elements), sec)
    b = m.add_beam(bs.geometry.helix(R, PITCH, length, n_elements, phase=np.pi), sec)
    m.clamp(a.first)
    m.clamp(b.first)
    m.add_contact(a, b, mu=0.3, **options)
    return m


def search_counts(model, monkeypatch):
    """Per slave point of one search at the reference poses: Gauss-point projections done, those the
    search would do without the cull, and contact points kept."""
    done, uncut = [], []
    real = contact_system.gauss_projections

    def counted(*args, **kw):
        out = real(*args, **kw)
        done.append(len(out[0]))
        uncut.append(len(real(*args, **dict(kw, window=None))[0]))
        return out

    monkeypatch.setattr(contact_system, "gauss_projections", counted)
    c = Problem.from_model(model, check_rigid_modes=False).contact
    H = c.sys.poses0
    done.clear(), uncut.clear()
    P = c.pairs(H)
    n_points = sum(len(d.slave_el) * d.n_gp for d in c.decls)
    return done[-1] / n_points, uncut[-1] / n_points, len(P) / n_points


@pytest.mark.slow
def test_projections_per_slave_point_bounded_under_refinement(monkeypatch):
    # the point path (Gauss points fixed per slave element, projected one by one)
    rows = {n: search_counts(two_ply(n, integration="points"), monkeypatch) for n in (8, 32, 128, 512)}
    for n, (done, uncut, kept) in rows.items():
        assert kept == 1.0, (n, kept)                 # every slave point finds its owner
        assert 1.0 <= done <= 1.5, (n, done)          # ~1.4: Gauss points near a node project on both elements
    # without the cull the rows within reach grow like 1 + 7 R / L (2 -> 59): the bound is the cull's
    uncut = [rows[n][1] for n in sorted(rows)]
    assert uncut[0] < 3.0 and np.all(np.diff(uncut) > 0) and uncut[-1] > 20.0, rows


def _curved_scene(seed, n=400):
    """Slave elements along ``e_x`` and master elements above them, tilted by up to 0.15 rad, axially
    shifted by up to three element lengths and bent by up to 0.4 rad (a bow of up to ~L / 20)."""
    rng = np.random.default_rng(seed)
    L = 0.2
    slave = np.zeros((n, 6))
    slave[:, 0], slave[:, 3:] = L, rng.uniform(-0.05, 0.05, (n, 3))
    rot = np.zeros((n, 6))
    rot[:, 3:] = rng.uniform(-0.15, 0.15, (n, 3))
    HA2 = se3.exp(rot)
    HA2[:, :3, 3] = np.stack([rng.uniform(-3 * L, 3 * L, n), rng.uniform(-0.05, 0.05, n), np.full(n, 0.19)], 1)
    master = np.zeros((n, 6))
    w = rng.normal(size=(n, 3))
    master[:, 0], master[:, 3:] = L, w / np.linalg.norm(w, axis=1, keepdims=True) * rng.uniform(0.0, 0.4, (n, 1))
    H = np.empty((4 * n, 4, 4))
    H[0::4] = np.eye(4)
    H[1::4] = se3.exp(slave)
    H[2::4] = HA2
    H[3::4] = se3.compose(HA2, se3.exp(master))
    enodes = np.arange(4 * n).reshape(-1, 2)                 # element 2k: slave k, 2k + 1: master k
    return H, enodes, projection.element_twists(H, enodes), L


@pytest.mark.parametrize("seed", range(3))
def test_cull_drops_only_rejected_line_rows(seed):
    H, enodes, h, L = _curved_scene(seed)
    n = len(enodes) // 2
    e, m = 2 * np.arange(n), 2 * np.arange(n) + 1
    xg = 0.5 * np.polynomial.legendre.leggauss(5)[0] + 0.5
    kind = np.full(n, pairs.LINE)
    c2, reach = np.zeros((n, 3)), np.full(n, np.inf)            # no sphere filter
    ov = rules.XI_OVERHANG
    ref = projection.gauss_projections(H, enodes, h, e, m, xg, kind, c2, reach)
    got = projection.gauss_projections(H, enodes, h, e, m, xg, kind, c2, reach, window=ov)
    key_ref, key_got = ref[0] * len(xg) + ref[1], got[0] * len(xg) + got[1]
    kept = np.isin(key_ref, key_got)
    np.testing.assert_array_equal(key_ref[kept], key_got)          # the same rows, in their order
    for a, b in zip(ref[2:], got[2:]):
        np.testing.assert_array_equal(a[kept], b)                   # projected as without the cull
    # the slave section plane's distance to the master point found: a projection (converged), or none
    sl, ms = e[ref[0]], m[ref[0]]
    x1, e1 = projection.section_points(H, enodes[sl, 0], h[sl], xg[ref[1]])
    x2, _ = projection.section_points(H, enodes[ms, 0], h[ms], ref[2])
    converged = np.abs(np.sum((x2 - x1) * e1, axis=1)) < 1e-12 * L
    accepted = (ref[2] >= -ov) & (ref[2] <= 1 + ov) & np.isfinite(ref[3]) & converged
    assert not (accepted & ~kept).any()                             # nothing the owners could take is culled
    assert (~kept).sum() > len(kept) // 2 and accepted.sum() > 200 and converged.mean() > 0.95


def test_cull_bound_covers_the_bow_of_a_bent_master():
    """A master element bent in the plane of its chord and a slave section plane parallel to the chord,
    crossed by the bent line only: kept with the bow's bound, culled by the chord alone."""
    L, turn = 0.2, 0.8
    h = np.array([[L, 0, 0, 0, 0, turn]])                      # bent about e_z by ``turn`` over its length
    HA = np.eye(4)[None]
    H = np.concatenate([HA, se3.compose(HA, se3.exp(h))])
    xi = np.linspace(-0.06, 1.06, 2001)
    x, _ = projection.section_points(H, np.zeros(len(xi), dtype=int), np.repeat(h, len(xi), 0), xi)
    xa, xb = H[0, :3, 3], H[1, :3, 3]
    normal = np.cross(xb - xa, [0.0, 0.0, 1.0])
    normal /= np.linalg.norm(normal)
    side = x @ normal - xa @ normal                              # the line's distance from its chord
    bow = 0.5 * max(0.25, 0.06 * 1.06) * np.linalg.norm(np.cross(h[0, 3:], h[0, :3]))
    assert 0.5 * bow < np.abs(side).max() <= bow                 # the bound is tight within 2x
    for depth in (0.3, 0.9):                                     # planes crossed by the bent line only
        xc = xa + depth * side[np.argmax(np.abs(side))] * normal
        args = tuple(xc), tuple(normal), tuple(xa), tuple(xb), -0.06, 1.06
        assert not projection._misses(*args, bow)
        assert projection._misses(*args, 0.0)
    xc = xa + 1.1 * bow * np.sign(side[np.argmax(np.abs(side))]) * normal
    assert projection._misses(tuple(xc), tuple(normal), tuple(xa), tuple(xb), -0.06, 1.06, bow)
