"""Stability along the path, critical modes and branch switching (issue 15 items 1, 2).

References: the elastica (Timoshenko & Gere, Theory of Elastic Stability, 2nd ed., sec. 2.7):
a clamped-free column of length ``L`` under an axial tip load ``P`` beyond
``P_cr = pi^2 EI / (4 L^2)`` has, with ``k = sin(alpha / 2)`` (``alpha`` the tip rotation),

    sqrt(P / P_cr) = 2 K(k) / pi,   tip deflection f / L = 2 k / K(k),
    tip position along the axis x / L = 2 E(k) / K(k) - 1,

``K``, ``E`` the complete elliptic integrals of modulus ``k``.  A pinned-pinned column of
length ``L`` is two such columns of length ``L / 2`` (``P_cr = pi^2 EI / L^2``): midspan
deflection ``k / K(k) L``, end shortening ``delta / L = 2 - 2 E(k) / K(k)``, end rotation ``alpha``.
"""
import warnings

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

import beamsolver as bs
from beamsolver.stepping import bifurcation
from beamsolver.assembly.system import System
from beamsolver.nonlinear.definiteness import DENSE_MAX
from beamsolver.nonlinear.modes import lowest_modes

from limit_points import argyris_frame

EI = 1.0


def _section(EA=1e6, EI3=EI):
    return bs.Section(EA=EA, GA2=EA, GA3=EA, GJ=1.0, EI2=EI, EI3=EI3, radius=0.01)


def _cantilever_column(ratio, n, EA=1e6, EI3=EI):
    """Clamped-free column, L = 1, tip load ``ratio`` P_cr along -x (straight, no imperfection)."""
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n), _section(EA, EI3))
    m.clamp(b.first)
    m.add_load(b.last, force=(-ratio * np.pi**2 * EI / 4.0, 0.0, 0.0))
    return m, b


def elastica_k(ratio):
    """Modulus ``k = sin(alpha / 2)`` of the elastica at ``P / P_cr = ratio`` (> 1)."""
    return brentq(lambda k: 2.0 * ellipk(k * k) / np.pi - np.sqrt(ratio), 1e-12, 1.0 - 1e-15)


def elastica_tip(ratio):
    """Clamped-free column (L = 1): ``(x, f, alpha)`` of the tip at ``P / P_cr = ratio``."""
    k = elastica_k(ratio)
    K, E = ellipk(k * k), ellipe(k * k)
    return np.array([2.0 * E / K - 1.0, 2.0 * k / K, 2.0 * np.arcsin(k)])


def _tip(sol, node):
    x, R = sol.position(node), sol.rotation(node)
    return np.array([x[0], np.hypot(x[1], x[2]), np.arccos(np.clip(R[0, 0], -1.0, 1.0))])


# ------------------------------------------------------------------ the stability check itself
def test_slender_straight_column_beyond_euler_is_unstable_whatever_the_mesh():
    """A slender column (EA L^2 / EI = 1e8) at 2 P_cr on 32 elements: the scaled eigenvalue of the
    buckling mode is about -7e-11, which a fixed round-off allowance of 1e-10 called 'stable'."""
    m, _ = _cantilever_column(2.0, 32, EA=1e8)
    with pytest.warns(bs.StabilityWarning, match="unstable"):
        sol = bs.solve(m, steps=2, verbose=False, check_stability=True)
    assert sol.stats[2]["stable"] is False and sol.stats[2]["negative_eigenvalues"] == 2


# ------------------------------------------------------------------ modes: the eigenpairs and their node fields
@pytest.mark.parametrize("n", [40, DENSE_MAX + 100])
def test_lowest_modes_are_the_scaled_pencil_eigenpairs(n):
    """Dense (LAPACK) and sparse (shifted Lanczos) paths against ``eigh(K, diag|K|)``, with two small
    negative eigenvalues and diagonal scales spread over six decades."""
    rng = np.random.default_rng(7)
    lap = sp.diags([-np.ones(n - 1), 2.0 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    lam_min = 2.0 - 2.0 * np.cos(np.pi / (n + 1))
    B = lap - sp.identity(n) * (2.0 - 2.0 * np.cos(2.5 * np.pi / (n + 1)))   # two eigenvalues < 0
    assert lam_min < 2.0 - 2.0 * np.cos(2.5 * np.pi / (n + 1))
    S = sp.diags(10.0 ** rng.uniform(0, 6, n))
    K = (S @ B @ S).tocsc()
    lam, phi = lowest_modes(K, 4)
    Kd = K.toarray()
    M = np.diag(np.abs(np.diag(Kd)))
    from scipy.linalg import eigh
    ref = eigh(Kd, M, eigvals_only=True)[:4]
    np.testing.assert_allclose(lam, ref, rtol=1e-8, atol=1e-12)
    assert np.sum(lam < 0) == 2
    np.testing.assert_allclose(Kd @ phi, M @ phi * lam, atol=1e-8 * np.abs(Kd).max())
    np.testing.assert_allclose(phi.T @ M @ phi, np.eye(4), atol=1e-8)


def _joined_model():
    """A clamped beam (a chain), a beam joined to it and a partially fixed node (global increments)."""
    m = bs.Model()
    sec = _section()
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), sec)
    b = m.add_beam(bs.geometry.arc(2.0, 0.5, 4), sec)
    c = m.add_beam(bs.geometry.straight((1, 0, 0), (1, 1, 0), 3), sec)
    m.clamp(a.first)
    m.join(a.last, c.first)
    m.clamp(b.first)
    m.fix(c.last, dofs=("uz",))
    return m


def test_node_twists_are_the_first_order_motion_of_every_node(rng):
    system = System(_joined_model())
    assert system.chains and len(system.members) and len(system.global_nodes)
    H = system.update(system.poses0, bifurcation.full_increments(system, 0.1 * rng.standard_normal(system.n_free)))
    dz = bifurcation.full_increments(system, rng.standard_normal(system.n_free))
    tw = bifurcation.node_twists(system, H, dz)
    eps = 1e-6
    Hp, Hm = system.update(H, eps * dz), system.update(H, -eps * dz)
    du = (Hp[:, :3, 3] - Hm[:, :3, 3]) / (2 * eps)
    dR = (Hp[:, :3, :3] - Hm[:, :3, :3]) / (2 * eps) @ np.swapaxes(H[:, :3, :3], 1, 2)   # skew(omega)
    dw = np.stack([dR[:, 2, 1], dR[:, 0, 2], dR[:, 1, 0]], axis=1)
    np.testing.assert_allclose(tw[:, :3], du, atol=1e-7)
    np.testing.assert_allclose(tw[:, 3:], dw, atol=1e-7)
    assert np.abs(tw[system.members]).max() > 0.1            # joined nodes move with their representative


def test_normalise_gives_unit_size_and_a_reproducible_sign(rng):
    system = System(_joined_model())
    dz = bifurcation.full_increments(system, rng.standard_normal(system.n_free))
    a, b = bifurcation.normalise(system, dz), bifurcation.normalise(system, -3.0 * dz)
    assert bifurcation.size(system, a) == pytest.approx(1.0)
    np.testing.assert_allclose(a, b)


def test_euler_mode_and_the_eigenvalue_crossing():
    """Straight clamped-free column just below / above P_cr: the lowest recorded eigenvalue changes
    sign, and mode 1 is the Euler mode ``1 - cos(pi x / 2L)`` (lateral)."""
    rows = []
    for ratio in (0.97, 1.03):
        m, b = _cantilever_column(ratio, 16, EI3=1.3)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", bs.StabilityWarning)
            sol = bs.solve(m, steps=1, verbose=False, modes=2)
        lam, modes = sol.modes(-1)
        assert modes.shape == (2, m.n_nodes, 6)
        rows.append((lam, modes[0], sol.stats[-1]["negative_eigenvalues"]))
    (lo, mode, neg_lo), (hi, _, neg_hi) = rows
    assert lo[0] > 0 > hi[0] and neg_lo == 0 and neg_hi == 1 and lo[1] > 0 and hi[1] > 0
    x = np.linspace(0, 1, 17)
    w = np.hypot(mode[:, 1], mode[:, 2])
    np.testing.assert_allclose(w / w[-1], 1.0 - np.cos(np.pi * x / 2.0), atol=2e-3)
    assert np.abs(mode[:, 0]).max() < 1e-6                        # no axial part
    assert bifurcation.size(System(m), mode) == pytest.approx(1.0)


# ------------------------------------------------------------------ branch switching vs the elastica
@pytest.mark.parametrize("ratio", [1.5, 2.5, 4.0])
def test_clamped_free_elastica_after_branch_switching(ratio):
    """From the straight column, no imperfection, load in steps: 'auto' switches once, where the
    negative count goes up, and the path ends on the elastica (tip x, deflection, rotation)."""
    m, b = _cantilever_column(ratio, 16)
    with warnings.catch_warnings():
        warnings.simplefilter("error", bs.StabilityWarning)
        sol = bs.solve(m, steps=8, verbose=False, branch_switching="auto")
    switched = [k for k, s in enumerate(sol.stats) if "branch_switch" in s]
    assert len(switched) == 1
    rec = sol.stats[switched[0]]["branch_switch"]
    assert rec["negative_before"] >= 1 and rec["negative_after"] == 0 and rec["mode"] == 1
    assert sol.times[switched[0]] * ratio > 1.0 >= sol.times[switched[0] - 1] * ratio   # the first step past P_cr
    assert all(s["stable"] for s in sol.stats[1:])
    np.testing.assert_allclose(_tip(sol, b.last), elastica_tip(ratio), atol=3e-3)


def test_elastica_error_falls_at_second_order():
    ratio, errors, ns = 2.0, [], (4, 8, 16)
    exact = elastica_tip(ratio)
    for n in ns:
        m, b = _cantilever_column(ratio, n)
        sol = bs.solve(m, steps=2, verbose=False, branch_switching="auto")
        errors.append(np.abs(_tip(sol, b.last) - exact))
    errors = np.array(errors)
    for j, name in enumerate(("x", "alpha")):
        rate = -np.polyfit(np.log(ns), np.log(errors[:, 2 * j]), 1)[0]
        assert 1.8 < rate < 2.3, (name, rate, errors[:, 2 * j])


def _pinned_column(n=16):
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n), _section(EI3=3.0))
    m.fix(b.first, dofs=("ux", "uy", "uz", "rx"))
    return m, b


def _pinned_reference(k):
    """Pinned-pinned elastica (L = 1): ``(P / P_cr, midspan deflection, shortening, end rotation)``."""
    K, E = ellipk(k * k), ellipe(k * k)
    return (2.0 * K / np.pi) ** 2, k / K, 2.0 - 2.0 * E / K, 2.0 * np.arcsin(k)


def _pinned_measures(sol, b):
    mid = b.nodes[len(b.nodes) // 2]
    x, R = sol.position(mid), sol.rotation(b.last)
    return np.hypot(x[1], x[2]), 1.0 - sol.position(b.last)[0], np.arccos(np.clip(R[0, 0], -1.0, 1.0))


def test_pinned_column_under_load_after_branch_switching():
    ratio = 1.8
    m, b = _pinned_column()
    m.fix(b.last, dofs=("uy", "uz"))
    m.add_load(b.last, force=(-ratio * np.pi**2 * EI, 0.0, 0.0))
    sol = bs.solve(m, steps=4, verbose=False, branch_switching="auto")
    _, mid, short, alpha = _pinned_reference(elastica_k(ratio))
    # each half is a clamped-free column on 8 elements, whose discretisation error is about 4e-3
    np.testing.assert_allclose(_pinned_measures(sol, b), (mid, short, alpha), atol=5e-3)
    assert sol.stats[-1]["stable"] is True


def test_pinned_column_under_prescribed_shortening():
    """End shortening delta = 0.1 L: today's straight state gives P = EA delta / L (10^4 times
    P_cr); with branch switching the reaction follows the elastica P(delta)."""
    delta = 0.1
    m, b = _pinned_column()
    m.fix(b.last, dofs=("ux", "uy", "uz"), values={"ux": lambda t: -delta * t})
    with pytest.warns(bs.StabilityWarning):
        straight = bs.solve(m, steps=4, verbose=False, check_stability=True)
    assert straight.stats[-1]["stable"] is False
    assert -straight.reaction(b.last)[0] == pytest.approx(1e6 * delta, rel=1e-3)
    sol = bs.solve(m, steps=4, verbose=False, branch_switching="auto")
    # the first step passes ~30 critical loads: the switch is made between the first two, located
    # by bisection (P_cr = EA delta_c / L in the straight state; the second one is 4 P_cr)
    (k_switch,) = [k for k, s in enumerate(sol.stats) if "branch_switch" in s]
    rec = sol.stats[k_switch]["branch_switch"]
    assert rec["critical_t"] * delta * 1e6 / np.pi**2 == pytest.approx(1.0, rel=1e-2)
    assert rec["critical_t"] < sol.times[k_switch] < 4.0 * rec["critical_t"] and rec["negative_before"] == 1
    k = brentq(lambda k: _pinned_reference(k)[2] - delta, 1e-6, 0.99)
    ratio, mid, _, alpha = _pinned_reference(k)
    assert -sol.reaction(b.last)[0] / (np.pi**2 * EI) == pytest.approx(ratio, rel=5e-3)   # 8 elements per half
    measured = _pinned_measures(sol, b)
    assert measured[0] == pytest.approx(mid, abs=5e-3) and measured[2] == pytest.approx(alpha, abs=5e-3)
    assert all(s["stable"] for s in sol.stats[1:])


# ------------------------------------------------------------------ modes of operation, bookkeeping, refusals
def _lateral_cantilever():
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 8), _section())
    m.clamp(b.first)
    m.add_load(b.last, force=(0.0, 3.0, 1.0))
    return m


def test_stable_path_is_unchanged_by_the_stability_options():
    plain = bs.solve(_lateral_cantilever(), steps=4, verbose=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        checked = bs.solve(_lateral_cantilever(), steps=4, verbose=False, branch_switching="auto", modes=2)
    np.testing.assert_array_equal(checked.poses, plain.poses)
    assert all(s["stable"] and "branch_switch" not in s for s in checked.stats[1:])
    assert all(len(s["mode_eigenvalues"]) == 2 and min(s["mode_eigenvalues"]) > 0 for s in checked.stats[1:])
    assert all(s["stable"] is True and "modes" not in s for s in plain.stats)    # checked by default (issue 28)


def test_true_switches_an_unstable_state_auto_waits_for_a_crossing():
    """Restarted from a straight column already past P_cr: no crossing in the next step, so
    'auto' leaves it (and says it is unstable); True switches it onto the elastica."""
    m, b = _cantilever_column(2.0, 8)
    with pytest.warns(bs.StabilityWarning):
        first = bs.solve(m, steps=2, verbose=False, check_stability=True)
    assert first.stats[-1]["negative_eigenvalues"] == 2
    with pytest.warns(bs.StabilityWarning, match="unstable"):
        auto = bs.solve(m, steps=3, t_end=1.5, verbose=False, restart=first, branch_switching="auto")
    assert auto.stats[-1]["stable"] is False and "branch_switch" not in auto.stats[-1]
    forced = bs.solve(m, steps=3, t_end=1.5, verbose=False, restart=first, branch_switching=True)
    assert forced.stats[-1]["branch_switch"]["negative_after"] == 0 and forced.stats[-1]["stable"] is True
    np.testing.assert_allclose(_tip(forced, b.last), elastica_tip(3.0), atol=1e-2)   # 8 elements


def test_a_switch_that_leaves_negative_eigenvalues_is_not_called_stable(monkeypatch):
    """A descent that does not move (here: replaced) leaves the saddle: warned, recorded unstable."""
    monkeypatch.setattr(bifurcation, "descend", lambda evaluate, factorize, update, size, H, *a: (H, 0))
    m, _ = _cantilever_column(2.0, 8)
    with pytest.warns(bs.StabilityWarning, match="still has 2 negative"):
        sol = bs.solve(m, steps=2, verbose=False, branch_switching="auto")
    s = sol.stats[-1]
    assert s["stable"] is False and s["negative_eigenvalues"] == 2 and s["branch_switch"]["negative_after"] == 2
    assert "still has" in sol.message


def test_a_failed_switch_is_recorded_and_keeps_the_state(monkeypatch):
    monkeypatch.setattr(bifurcation, "DESCENT_MAX", 1)
    m, b = _cantilever_column(2.0, 8)
    with pytest.warns(bs.StabilityWarning, match="branch switching failed"):
        sol = bs.solve(m, steps=2, verbose=False, branch_switching="auto")
    s = sol.stats[-1]
    assert "no stable state within 1" in s["branch_switch"]["failed"] and s["stable"] is False
    assert np.hypot(*sol.position(b.last)[1:]) < 1e-9                  # still straight


def test_non_conservative_problem_is_neither_judged_nor_switched():
    """A follower load: no potential, the symmetric part's definiteness proves nothing: ``stable=None``
    with its reason, and modes or switching, which would do nothing, are refused (issue 28 item 5)."""
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 8), _section())
    m.clamp(b.first)
    m.add_load(b.last, force=(-2.0 * np.pi**2 / 4.0, 0.0, 0.0), follower=True)
    with pytest.raises(bs.InputError, match="follower loads"):
        bs.solve(m, steps=2, verbose=False, branch_switching=True, modes=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol = bs.solve(m, steps=2, verbose=False)
    assert all(s["stable"] is None and "follower loads" in s["stable_note"] for s in sol.stats)


@pytest.mark.parametrize("kw", [dict(modes=-1), dict(modes=1.5), dict(modes=True), dict(modes="2"),
                                dict(branch_switching="always"), dict(branch_switching=1),
                                dict(branch_switching=None)])
def test_bad_stability_options_are_refused(kw):
    name, value = next(iter(kw.items()))
    with pytest.raises(bs.InputError, match=name) as e:
        bs.solve(_lateral_cantilever(), steps=1, verbose=False, **kw)
    assert repr(value) in str(e.value)


def test_modes_reach_the_saved_result_the_vtu_and_info(tmp_path, capsys):
    meshio = pytest.importorskip("meshio")
    from beamsolver.app import cli
    m, b = _cantilever_column(2.0, 8)
    sol = bs.solve(m, steps=4, verbose=False, branch_switching="auto", modes=2, output=tmp_path / "out")
    lam, modes = sol.modes(-1)
    back = bs.load(tmp_path / "out")
    np.testing.assert_array_equal(back.modes(-1)[1], modes)
    np.testing.assert_array_equal(back.modes(-1)[0], lam)
    assert back.modes(0)[1].shape == (0, m.n_nodes, 6)
    mesh = meshio.read(tmp_path / "out" / "beams_0004.vtu")
    tip = np.flatnonzero(np.all(np.isclose(mesh.points, sol.position(b.last)), axis=1))
    assert len(tip) == 1
    for j in (1, 2):
        np.testing.assert_allclose(mesh.point_data[f"mode_{j}_u"][tip[0]], modes[j - 1, b.last, :3])
        np.testing.assert_allclose(mesh.point_data[f"mode_{j}_rotation"][tip[0]], modes[j - 1, b.last, 3:])
    assert cli.main(["info", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert "switched" in out and "mode 1" in out and "neg. eig." in out


def test_argyris_frame_perfect_switches_at_the_published_load_onto_the_imperfect_path():
    """The perfect frame: lateral buckling located at the published F_cr = 1.088 N (Argyris et al.
    1979, as in Simo & Vu-Quoc 1986) within 1 % (10 elements per leg), and at 1.5 N the switched
    state is the one force control reaches with a 1e-4 out-of-plane imperfection (to O(1e-4))."""
    m, b = argyris_frame(1.5, 0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", bs.StabilityWarning)
        sol = bs.solve(m, steps=15, verbose=False, branch_switching="auto")
    (k,) = [k for k, s in enumerate(sol.stats) if "branch_switch" in s]
    rec = sol.stats[k]["branch_switch"]
    assert 1.5 * rec["critical_t"] == pytest.approx(1.088, rel=1e-2)
    assert rec["negative_after"] == 0 and all(s["stable"] for s in sol.stats[1:])
    m2, b2 = argyris_frame(1.5, 1e-4)
    imperfect = bs.solve(m2, steps=15, verbose=False)
    lateral = sol.position(b.last)[2]
    assert abs(lateral) > 50.0                                          # well past buckling
    np.testing.assert_allclose(np.abs(sol.position(b.last)), np.abs(imperfect.position(b2.last)),
                               atol=1e-3 * abs(lateral))


@pytest.mark.parametrize("second, switch_at", [(0.5004, 1.0), (0.8, 0.65)])
def test_locate_switches_between_distinct_crossings_only(monkeypatch, second, switch_at):
    """Counts 0 -> 1 at t = 0.5 and 1 -> 2 at ``second``: a second crossing within CLUSTER of the
    step is the same (a double eigenvalue split by round-off): switch at the step's end; a distinct
    one: switch halfway between them, where only the first mode is unstable."""
    from types import SimpleNamespace
    from beamsolver.stepping import branching

    def state(run, t):
        return (None, None, None, int(t >= 0.5) + int(t >= second), None)
    monkeypatch.setattr(branching, "_state", state)
    t_s, at, t_c = branching.locate(SimpleNamespace(t=0.0), 1.0, state(None, 1.0), 0)
    assert t_c == pytest.approx(0.5, abs=1e-3) and t_s == pytest.approx(switch_at, abs=2e-3)
    assert at[3] == (2 if switch_at == 1.0 else 1)
