"""Exactly touching point contact does not depend on round-off (issue 28 item 11).

A slave beam lies across a clamped-clamped master, centre lines exactly ``R1 + R2`` apart, held
only by the contact in the vertical (its ends fixed in the other five directions) and pushed
down by a ramped load.  The first iterate of step 1 starts from gap zero: the sharp normal law
counts a touching point active (stiffness, no force) at a gap of exactly 0, but the gap of a
translated scene is ``dist - R1 - R2`` with the round-off of its coordinates (1e-13 at 1e3):
slightly positive, the point was open, the slave free and the tangent singular ("could not
advance from t = 0").  Failed before: translated by (1e3, -5e2, 3e2) or (0, 0, 1e3), a 1e-15
gap, and radii 0.099 / 0.001 in one declaration order of two (``dist - R1 - R2`` rounds
differently).  A gap within ``frames.touch_tolerance`` (32 eps (extent + R1 + R2)) is now
touching.
"""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver.contact import frames, kernel_jit, reference
from beamsolver.nonlinear.problem import Problem

SHIFTS = {"origin": (0.0, 0.0, 0.0), "far": (1e3, -5e2, 3e2), "high": (0.0, 0.0, 1e3)}


def _held(shift=(0.0, 0.0, 0.0), gap=0.0, r_slave=0.05, r_master=0.05, swap=False, E=1e7, half=1.0, load=10.0):
    """Master along y (length ``2 half``, 8 elements), slave along x (``0.6 half``, 2 elements) on top."""
    s = np.asarray(shift, dtype=float)
    m = bs.Model()
    master = m.add_beam(bs.geometry.straight(s + (0, -half, 0), s + (0, half, 0), 8),
                        bs.Section.circular(radius=r_master, E=E, nu=0.3), name="master")
    h = r_slave + r_master + gap
    slave = m.add_beam(bs.geometry.straight(s + (-0.3 * half, 0, h), s + (0.3 * half, 0, h), 2),
                       bs.Section.circular(radius=r_slave, E=E, nu=0.3), name="slave")
    m.clamp(master.first)
    m.clamp(master.last)
    m.fix(slave.first, dofs=("ux", "uy", "rx", "ry", "rz"))
    m.fix(slave.last, dofs=("uy", "rx", "ry", "rz"))
    m.add_load(slave.nodes[1], force=(0.0, 0.0, -load))
    if swap:
        m.add_contact(master, slave)
    else:
        m.add_contact(slave, master)
    return m, slave, master


def _drop(sol, slave):
    return sol.poses[-1][slave.nodes, 2, 3] - sol.poses[0][slave.nodes, 2, 3]


@pytest.fixture(scope="module")
def at_origin():
    """The slave's drop at the origin, per declaration order (the penetration depends on which
    side is the slave: point weights of the slave's element)."""
    out = {}
    for swap in (False, True):
        m, slave, _ = _held(swap=swap)
        out[swap] = _drop(bs.solve(m, steps=2), slave)
    return out


@pytest.mark.parametrize("swap", [False, True])
@pytest.mark.parametrize("where", list(SHIFTS))
def test_translated_scene_gives_the_same_answer(where, swap, at_origin):
    m, slave, _ = _held(SHIFTS[where], swap=swap)
    sol = bs.solve(m, steps=2)
    assert sol.converged
    assert sol.contact()["normal_force"].sum() == pytest.approx(10.0, rel=1e-6)
    drop = at_origin[swap]
    assert np.all(drop < 0)
    np.testing.assert_allclose(_drop(sol, slave), drop, rtol=1e-6)


def test_a_round_off_gap_touches(at_origin):
    m, slave, _ = _held(gap=1e-15)
    sol = bs.solve(m, steps=2)
    assert sol.converged and sol.contact()["normal_force"].sum() == pytest.approx(10.0, rel=1e-6)
    np.testing.assert_allclose(_drop(sol, slave), at_origin[False], rtol=1e-6)


@pytest.mark.parametrize("swap", [False, True])
@pytest.mark.parametrize("radii", [(0.099, 0.001), (0.001, 0.099)])
def test_either_declaration_order_of_unequal_radii(radii, swap):
    """Steel, a 0.4 m master, 1 N: the thin beam carries it.  Before, (0.099 slave, 0.001 master)
    failed as declared and (0.001, 0.099) swapped."""
    m, slave, _ = _held(r_slave=radii[0], r_master=radii[1], swap=swap, E=2e11, half=0.2, load=1.0)
    sol = bs.solve(m, steps=2)
    assert sol.converged and sol.contact()["normal_force"].sum() == pytest.approx(1.0, rel=1e-6)


def test_a_gap_beyond_the_tolerance_stays_open():
    """A real gap (1e-9, far above the touching tolerance 8e-15 here) is no contact: the slave
    hangs free in z and the solve refuses (singular), as before."""
    m, _, _ = _held(gap=1e-9)
    with pytest.raises(bs.ConvergenceError, match="singular"):
        bs.solve(m, steps=1, min_step_ratio=0.5)


def test_touch_tolerance_scales_with_the_scene_and_the_radii():
    eps = np.finfo(float).eps
    assert frames.touch_tolerance(0.0, 0.05, 0.05) == frames.TOUCH_ROUNDOFF * eps * 0.1
    assert frames.touch_tolerance(1e3, 0.05, 0.05) == pytest.approx(frames.TOUCH_ROUNDOFF * eps * 1000.1, rel=1e-15)
    g = np.array([-1e-14, 0.0, 1e-15, 7e-15, 1e-14])
    np.testing.assert_array_equal(reference.touching_gap(g, 8e-15), [-1e-14, 0.0, 0.0, 0.0, 1e-14])
    gc = reference.touching_gap(g + 1e-20j, 8e-15)                    # complex step: the variation is kept
    np.testing.assert_array_equal(gc.imag, np.full(5, 1e-20))


def _inputs(**kw):
    m = _held(**kw)[0]
    problem = Problem.from_model(m)
    H = problem.system.poses0
    problem.contact.begin_step(H, 0.0)
    return problem.contact.kernel_inputs(H)


@pytest.mark.parametrize("where", ["origin-gap", "far"])
def test_kernel_counts_a_round_off_gap_touching_as_the_oracle(where):
    """At the given poses (gap 1e-15 at the origin; round-off at 1e3): the compiled kernel and the
    numpy oracle agree (forces, tangent), the point is active without force, its stiffness that of
    the penalty along the normal; with ``touch`` 0 the same point is open."""
    X, p = _inputs(gap=1e-15) if where == "origin-gap" else _inputs(shift=SHIFTS["far"])
    f1, K1, o1 = kernel_jit.kernel_and_tangent(X, p, False)
    f0, K0, o0 = reference.kernel_and_tangent(X, p, False)
    assert np.all(o1["active"]) and np.all(o0["active"]) and np.all(o1["lam_n"] == 0.0)
    assert np.all(np.abs(o1["gap"]) <= p["touch"])
    np.testing.assert_allclose(f1, f0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(K1, K0, rtol=1e-9, atol=1e-9 * np.abs(K0).max())
    assert np.abs(K1).max() > 0.1 * p["penalty"].max() * p["weight"].max()
    if np.any(o1["gap"] > 0):
        _, K2, o2 = kernel_jit.kernel_and_tangent(X, dict(p, touch=0.0), False)
        assert not np.all(o2["active"]) and np.abs(K2[o1["gap"] > 0]).max() == 0.0


def test_line_contact_smoothing_already_covers_round_off_gaps():
    """Parallel touching wires (line contact, default smoothing 1e-6 (R1 + R2) >> the touching
    tolerance): no touching band is added, so their results do not move; with ``smoothing=0`` it is."""
    def inputs(**options):
        m = bs.Model()
        sec = bs.Section.circular(radius=0.05, E=1e7, nu=0.3)
        a = m.add_beam(bs.geometry.straight((0, -1, 0), (0, 1, 0), 4), sec)
        b = m.add_beam(bs.geometry.straight((0, -1, 0.1), (0, 1, 0.1), 4), sec)
        for w in (a, b):
            m.clamp(w.first)
            m.clamp(w.last)
        m.add_contact(b, a, **options)
        problem = Problem.from_model(m)
        H = problem.system.poses0
        problem.contact.begin_step(H, 0.0)
        return problem.contact.kernel_inputs(H)[1]
    p = inputs()
    assert np.all(p["kind"] == frames.LINE) and np.all(p["smoothing"] > 0) and np.all(p["touch"] == 0.0)
    p = inputs(smoothing=0.0)
    np.testing.assert_allclose(p["touch"], frames.touch_tolerance(1.0, 0.05, 0.05), rtol=1e-15)
