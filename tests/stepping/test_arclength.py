"""Arc-length path following (``solve(..., path="arc-length")``): limit points against closed forms
and published values, the bordering's pseudo-time rate, the root choice, Newton's rate, constraints,
contact, options and the consumers of non-monotonic times."""
import sys
import warnings

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.stepping import arclength
from beamsolver.stepping.arclength import next_arc_length, rate, sphere_root
from beamsolver.nonlinear.problem import Problem

import crossing_beams
from limit_points import (P_CR_DADEPPO, RISE, deep_arch, first_peak, heights, lee_frame, peak,
                          truss, truss_limit, truss_load)
from helpers import assert_quadratic


# ------------------------------------------------------------------ the shallow two-bar truss
@pytest.fixture(scope="module")
def truss_path():
    P_lim, _ = truss_limit()
    m, apex = truss(P_lim)
    sol = bs.solve(m, steps=10, t_end=1.5, path="arc-length", verbose=False)
    return sol, apex, P_lim


def test_truss_snap_through_follows_the_closed_form(truss_path):
    """Every converged point lies on ``P(y)`` (closed form); the path passes the limit, goes down
    to negative loads (the apex below the supports pulls) and back up to exactly ``t_end``."""
    sol, apex, P_lim = truss_path
    t, y = sol.times, heights(sol, apex)
    assert sol.converged and sol.message.startswith("step ") and "unstable" in sol.message   # said (issue 28)
    np.testing.assert_allclose(t * P_lim, truss_load(y), atol=1e-5 * P_lim)
    assert t[-1] == 1.5
    assert t.min() < -0.9                  # the unstable branch down to the lower limit -P_lim
    assert y[-1] < -RISE                   # snapped through: the inverted truss carrying 1.5 P_lim
    assert np.any(np.diff(t) < 0) and np.all(np.diff(y) < 0)   # t goes down and up, y only down
    steps = [s["arc_length"] for s in sol.stats[1:]]
    assert all(np.isfinite(steps)) and all(s > 0 for s in steps)
    np.testing.assert_allclose([s["t"] for s in sol.stats[1:]], t[1:])


def test_truss_limit_load_within_one_percent(truss_path):
    sol, apex, P_lim = truss_path
    t, y = sol.times, heights(sol, apex)
    P_top, y_top = truss_limit()
    k = first_peak(t)
    assert abs(t[k] * P_lim / P_top - 1.0) < 1e-2          # the sampled peak
    assert abs(peak(t, y) * P_lim / P_top - 1.0) < 1e-3    # refined through its neighbours
    assert abs(y[k] - y_top) < 0.1 * RISE


def test_cylindrical_constraint_traces_the_same_curve():
    """``psi=0`` (Crisfield's cylindrical constraint: displacements only) through the same snap."""
    P_lim, _ = truss_limit()
    m, apex = truss(P_lim)
    sol = bs.solve(m, steps=10, t_end=1.5, path="arc-length", arc_length=dict(psi=0.0), verbose=False)
    t, y = sol.times, heights(sol, apex)
    assert sol.converged and t[-1] == 1.5 and t.min() < -0.9
    np.testing.assert_allclose(t * P_lim, truss_load(y), atol=1e-5 * P_lim)
    assert all(s["psi"] == 0.0 for s in sol.stats[1:])


def test_load_control_snaps_past_the_truss_limit_onto_the_inverted_truss(truss_path):
    """Load control cannot follow the path past the limit point (the reason for arc length): the
    step past it lands, by the undamped Newton after the damped one stalls (issue 31), on the only
    equilibrium at that load, the inverted truss -- stable, and the one arc length reaches at
    ``t_end`` -- with no state recorded between the limit and the snap."""
    arc, apex, P_lim = truss_path
    m, _ = truss(P_lim)
    sol = bs.solve(m, steps=10, t_end=1.5, verbose=False, check_stability=True)
    y = heights(sol, apex)
    assert all(s["stable"] for s in sol.stats[1:]) and np.all(np.diff(sol.times) > 0)
    assert y[-1] < -RISE and not np.any((y > -RISE) & (y < truss_limit()[1]))
    np.testing.assert_allclose(y[-1], heights(arc, apex)[-1], atol=1e-9 * RISE)


# ------------------------------------------------------------------ DaDeppo & Schmidt's deep arch
@pytest.mark.slow
def test_deep_arch_limit_load_within_one_percent_of_dadeppo_schmidt():
    """DaDeppo & Schmidt (1975), J. Appl. Mech. 42, 894-896: the clamped-hinged 215-degree arch's
    limit load ``8.97 EI / R^2`` (``examples/limit_points.deep_arch``); 40 elements."""
    m, crown = deep_arch()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = bs.solve(m, steps=40, t_end=1.0, path="arc-length", arc_length=dict(max_steps=230), verbose=False)
    assert not sol.converged and "not reached" in sol.message            # stopped on max_steps, said so
    assert any("not reached" in str(w.message) for w in caught)
    t, v = sol.times, heights(sol, crown)
    k = first_peak(t)
    assert 0 < k < sol.n_steps - 10                                       # traced past the limit ...
    assert t[-1] < t[k] - 0.05                                            # ... and down after it
    assert abs(peak(t, v) * 1000.0 / P_CR_DADEPPO - 1.0) < 0.01


def test_lee_frame_snap_back_is_traced():
    """Lee's frame snaps back: past the limit both the load and the deflection of the loaded point
    decrease for a while, then the path climbs again to ``t_end`` (reached exactly)."""
    m, node = lee_frame()
    sol = bs.solve(m, steps=20, path="arc-length", verbose=False)
    assert sol.converged and sol.times[-1] == 1.0
    t, v = sol.times, -(heights(sol, node) - heights(sol, node)[0])     # downward deflection
    dt, dv = np.diff(t), np.diff(v)
    assert np.any((dt < 0) & (dv < 0))              # snap-back: load and deflection both fall
    assert np.any((dt < 0) & (dv > 0))              # snap-through part before it
    assert 18.0 < 20.0 * peak(t, v) * 120.0**2 / (720.0 * 2.0) < 19.5     # P L^2 / EI at the limit, about 18.5


def test_long_arcs_use_the_linearised_constraint_and_still_trace_lee_frame():
    """Arcs three times longer than needed: some iterations find no real root (the linearised
    constraint is taken, the next arc halved); the run still ends on the same state at ``t_end``."""
    m, node = lee_frame()
    fine = bs.solve(m, steps=20, t_end=0.3, path="arc-length", verbose=False)
    m, node = lee_frame()
    coarse = bs.solve(m, steps=20, t_end=0.3, path="arc-length", arc_length=dict(initial=1.0, max=1.0),
                      verbose=False)
    assert coarse.converged and coarse.times[-1] == 0.3
    assert sum(s["linearised"] for s in coarse.stats[1:]) > 0
    np.testing.assert_allclose(coarse.poses[-1], fine.poses[-1], atol=1e-7 * 120.0)


def test_modes_along_the_arc_length_path(truss_path):
    """``modes=1`` records the lowest mode per step; on the unstable branch its eigenvalue is negative."""
    P_lim = truss_path[2]
    m, apex = truss(P_lim)
    with pytest.warns(bs.StabilityWarning):
        sol = bs.solve(m, steps=10, t_end=1.5, path="arc-length", modes=1, verbose=False)
    lowest = np.array([s["mode_eigenvalues"][0] for s in sol.stats[1:]])
    neg = np.array([s["negative_eigenvalues"] for s in sol.stats[1:]])
    assert np.all((lowest < 0) == (neg > 0)) and neg.any() and not neg.all()


def test_stability_check_sees_the_unstable_branch(truss_path):
    """With ``check_stability`` the tangent has one negative eigenvalue exactly between the two
    limit points of the truss (``dP/dy > 0`` there) and none outside."""
    P_lim = truss_path[2]
    m, apex = truss(P_lim)
    with pytest.warns(bs.StabilityWarning, match="unstable"):
        sol = bs.solve(m, steps=10, t_end=1.5, path="arc-length", check_stability=True, verbose=False)
    y = heights(sol, apex)
    y_top = truss_limit()[1]
    neg = np.array([s["negative_eigenvalues"] for s in sol.stats[1:]])
    inside = np.abs(y[1:]) < 0.98 * y_top
    outside = np.abs(y[1:]) > 1.02 * y_top
    assert np.all(neg[inside] == 1) and np.all(neg[outside] == 0) and inside.any() and outside.any()


# ------------------------------------------------------------------ Newton's rate
def test_newton_inside_an_arc_length_step_is_quadratic():
    P_lim, _ = truss_limit()
    m, _ = truss(P_lim)
    sol = bs.solve(m, steps=3, t_end=0.9, path="arc-length", rtol=1e-13, verbose=False)
    histories = [s["residuals"] for s in sol.stats[1:] if s["iterations"] >= 3]
    assert histories
    for r in histories:
        assert_quadratic(r)


def test_a_wrong_pseudo_time_rate_would_fail_the_quadratic_check(monkeypatch):
    """The check can fail: a rate off by 20 % makes the bordered Newton converge linearly."""
    P_lim, _ = truss_limit()
    m, _ = truss(P_lim)
    true_rate = arclength.rate
    monkeypatch.setattr(arclength, "rate", lambda *a: 0.8 * true_rate(*a))
    with pytest.warns(RuntimeWarning, match="not reached"):
        sol = bs.solve(m, steps=3, t_end=0.9, path="arc-length", rtol=1e-13, arc_length=dict(max_steps=4),
                       verbose=False)
    failed = 0
    for s in sol.stats[1:]:
        try:
            assert_quadratic(s["residuals"])
        except AssertionError:
            failed += 1
    assert failed


# ------------------------------------------------------------------ dr/dt
def _driven_frame():
    """Two beams joined at a corner (``join``), one end clamped, the other prescribed (translation
    and rotation), a dead load with a non-linear scale and a ``fix(values=)`` node."""
    sec = bs.Section.circular(radius=0.01, E=2e9, nu=0.3)
    m = bs.Model()
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), sec)
    b = m.add_beam(bs.geometry.straight((1, 0, 0), (1, 1, 0), 4), sec)
    c = m.add_beam(bs.geometry.straight((0, 0, 0.5), (1, 0, 0.5), 3), sec)
    m.join(a.last, b.first)
    m.clamp(a.first)
    m.prescribe(b.last, bs.motion.compose(bs.motion.translation(lambda t: (0.05 * t, 0.0, 0.02 * t * t)),
                                          bs.motion.rotation((0, 0, 1), lambda t: 0.3 * t, center=(1, 1, 0))))
    m.add_load(a.nodes[2], force=(0, 0, -2.0), moment=(0.1, 0, 0), scale=lambda t: np.sin(t))
    m.add_load(b.nodes[2], force=(1.0, 0, 0), follower=True, scale=lambda t: t * t)
    m.clamp(c.first)
    m.fix(c.last, dofs=("ux", "uy", "uz"), values={"uz": lambda t: 0.03 * t, "ux": lambda t: -0.01 * t * t})
    return m


@pytest.mark.slow
def test_rate_matches_the_finite_difference_of_the_residual():
    """``dr_f/dt`` of ``rate`` (analytic in the load factors, ``K_fc dz_c/dt`` for the constrained
    nodes) against a central difference of the residual at fixed free unknowns, the constrained
    nodes moved onto their targets at ``t +- h``."""
    m = _driven_frame()
    sol = bs.solve(m, steps=4, t_end=0.6, verbose=False)     # a deformed equilibrium to test at
    problem = Problem.from_model(m)
    system = problem.system
    H, t = sol.poses[-1], float(sol.times[-1])
    got = rate(problem, H, t, problem.evaluate(H, t), 1e-6, 0.0)

    def residual(tt):
        Hs = H.copy()
        Hs[system.prescribed_nodes] = system.prescribed_poses(tt)
        system.enforce_fixed_values(Hs, tt)
        system.sync_members(Hs)
        return problem.evaluate(Hs, tt, tangent=False).r[system.free_dofs]

    h = 1e-5
    want = (residual(t + h) - residual(t - h)) / (2 * h)
    assert np.abs(want).max() > 1.0                          # every source contributes
    np.testing.assert_allclose(got, want, atol=1e-6 * np.abs(want).max())


def test_joins_prescribed_motion_and_fixed_values_reach_the_load_path_answer():
    """A stable driven scene: the arc-length run ends at ``t_end`` on the load-controlled answer."""
    m = _driven_frame()
    ref = bs.solve(m, steps=6, t_end=1.0, verbose=False)
    sol = bs.solve(m, steps=6, t_end=1.0, path="arc-length", verbose=False)
    assert sol.converged and sol.times[-1] == 1.0 and np.all(np.diff(sol.times) > 0)
    scale = np.abs(ref.displacement()).max()
    np.testing.assert_allclose(sol.displacement(), ref.displacement(), atol=1e-7 * scale)
    np.testing.assert_allclose(sol.reactions[-1], ref.reactions[-1], atol=1e-6 * np.abs(ref.reactions[-1]).max())


def test_a_fast_prescribed_rotation_shortens_the_arc_as_it_shortens_a_load_step():
    """Two turns of twist prescribed over the run in two steps: each arc-length step is shortened so
    the motion turns by less than ``MAX_MOTION_ROTATION`` (a whole turn per step would look like
    none); the end state is the load path's."""
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 16), bs.Section.circular(radius=0.01, E=2e9))
    m.clamp(b.first)
    m.prescribe(b.last, bs.motion.rotation((1, 0, 0), lambda t: 4 * np.pi * t))
    ref = bs.solve(m, steps=2, verbose=False)
    sol = bs.solve(m, steps=2, path="arc-length", verbose=False)
    assert sol.converged and sol.times[-1] == 1.0 and sol.n_steps >= 7        # 4 pi in steps below 0.6 pi
    assert all(s["arc_length"] > 0 for s in sol.stats[1:])
    np.testing.assert_allclose(sol.poses[-1], ref.poses[-1], atol=1e-9)
    rot = [bs.se3.rotation_angle(bs.se3.log(bs.se3.relative(a[b.last], c[b.last]))[None, 3:])[0]
           for a, c in zip(sol.poses[:-1], sol.poses[1:])]
    assert max(rot) < 0.6 * np.pi + 1e-9                       # per step, as the load path's steps


# ------------------------------------------------------------------ root choice and arc-length rule
def test_sphere_root_keeps_the_direction_and_lands_on_the_sphere():
    rng = np.random.default_rng(3)
    w, dw_r, dw_t = rng.normal(size=5), 0.05 * rng.normal(size=5), rng.normal(size=5)
    psi, tau = 0.7, 0.2
    ds = np.sqrt(w @ w + psi**2 * tau**2)
    dt, lin = sphere_root(w, tau, dw_r, dw_t, psi, ds)
    assert not lin
    new = w + dw_r + dt * dw_t
    np.testing.assert_allclose(new @ new + psi**2 * (tau + dt) ** 2, ds**2, rtol=1e-12)
    other = -(2 * ((w + dw_r) @ dw_t + psi**2 * tau)) / (dw_t @ dw_t + psi**2) - dt   # sum of the roots
    back = w + dw_r + other * dw_t
    assert new @ w + psi**2 * tau * (tau + dt) > back @ w + psi**2 * tau * (tau + other)


def test_sphere_root_without_real_roots_takes_the_linearised_constraint():
    w, tau = np.array([1.0, 0.0]), 0.0
    dw_r, dw_t = np.array([0.0, 3.0]), np.array([1.0, 0.0])       # far off the sphere: no real root
    dt, lin = sphere_root(w, tau, dw_r, dw_t, 0.0, 1.0)
    assert lin
    p = w + dw_r
    np.testing.assert_allclose(dt, -(p @ p - 1.0) / (2 * p @ dw_t))


def test_next_arc_length_follows_the_iterations():
    assert next_arc_length(1.0, 5, 5, False, False) == 1.0
    assert next_arc_length(1.0, 1, 5, False, False) == 2.0
    assert next_arc_length(1.0, 20, 5, False, False) == 0.5
    assert next_arc_length(1.0, 2, 5, True, False) == 1.0
    assert next_arc_length(1.0, 2, 5, False, True) == 0.5


# ------------------------------------------------------------------ ends of a run
def test_max_steps_never_reports_converged():
    P_lim, _ = truss_limit()
    m, _ = truss(P_lim)
    with pytest.warns(RuntimeWarning, match="not reached"):
        sol = bs.solve(m, steps=10, t_end=1.5, path="arc-length", arc_length=dict(max_steps=5), verbose=False)
    assert sol.n_steps == 5 and not sol.converged and "t_end = 1.5 not reached after 5 steps" in sol.message


def test_a_step_that_cannot_converge_is_cut_back_then_stops_with_the_solution():
    P_lim, _ = truss_limit()
    m, _ = truss(P_lim)
    with pytest.raises(bs.ConvergenceError, match="arc-length could not advance") as e:
        bs.solve(m, steps=10, t_end=1.5, path="arc-length", max_iter=1, verbose=False,
                 arc_length=dict(initial=2.0, min=0.5, max=2.0))
    failed = e.value.solution
    assert failed is not None and not failed.converged and failed.n_steps == 0
    assert "arc length 0.5" in str(e.value)          # halved from 2 down to min, then stopped


def test_contact_scene_runs_with_arc_length():
    """Contact makes the path non-smooth where points open or close (docs/theory.md): on a scene
    whose contact state does not change, the arc-length run reaches the load-controlled answer."""
    model, slave, master = crossing_beams.build(load=50.0, n_elements=8, tolerance=1e-6)
    sol = bs.solve(model, steps=2, path="arc-length", verbose=False)
    assert sol.converged and sol.times[-1] == 1.0
    c = sol.contact()
    np.testing.assert_allclose(c["normal_force"].sum(), 50.0, rtol=1e-6)
    assert -c["gap"].min() < 1e-6


def test_contact_that_closes_during_the_run_reaches_the_load_path_answer():
    """A clamped beam pushed onto a crossing one: the contact closes within the first step (a kink in
    the path, then a stiffer branch with longer steps in ``t``); the end state is the load-controlled one."""
    r = 0.05
    sec = bs.Section.circular(radius=r, E=1e7, nu=0.3)
    m = bs.Model()
    master = m.add_beam(bs.geometry.straight((0, -1, 0), (0, 1, 0), 8), sec)
    slave = m.add_beam(bs.geometry.straight((-1, 0, 2 * r + 0.02), (1, 0, 2 * r + 0.02), 8), sec)
    for node in (master.first, master.last, slave.first, slave.last):
        m.clamp(node)
    mid = slave.nodes[4]
    m.add_load(mid, force=(0, 0, -400.0))
    m.add_contact(slave, master)
    ref = bs.solve(m, steps=8, verbose=False)
    sol = bs.solve(m, steps=8, path="arc-length", verbose=False)
    assert sol.converged and sol.times[-1] == 1.0
    assert len(sol.contacts[0].get("gap", ())) == 0 or not np.any(sol.contacts[0]["normal_force"] > 0)
    np.testing.assert_allclose(sol.position(mid), ref.position(mid), atol=1e-9)
    np.testing.assert_allclose(sol.contact()["normal_force"].sum(), ref.contact()["normal_force"].sum(), rtol=1e-6)


# ------------------------------------------------------------------ input
@pytest.mark.parametrize("kw, match", [
    (dict(path="arclength"), "path must be 'load' or 'arc-length'"),
    (dict(arc_length=dict(initial=0.1)), "need path='arc-length'"),
    (dict(path="arc-length", arc_length=dict(start=0.1)), "unknown arc_length option"),
    (dict(path="arc-length", arc_length=dict(initial=-1.0)), "initial must be a finite number > 0"),
    (dict(path="arc-length", arc_length=dict(max_steps=0)), "max_steps must be a positive integer"),
    (dict(path="arc-length", arc_length=dict(min=2.0, max=1.0)), "min 2.0 exceeds max 1.0"),
    (dict(path="arc-length", arc_length=dict(psi=float("nan"))), "psi must be a finite number >= 0"),
    (dict(path="arc-length", arc_length=[1.0]), "arc_length must be a dict"),
    (dict(path="arc-length", arc_length=dict(initial=10.0, max=1.0)), "min <= initial <= max"),
    (dict(path="arc-length", branch_switching="auto"), "branch_switching='auto' is not supported"),
    (dict(path=["arc-length"]), "path must be 'load' or 'arc-length'"),
    (dict(path="arc-length", stabilize=True), "stabilize=True is not supported"),
])
def test_bad_arc_length_input_is_refused(kw, match):
    m, _ = truss(1.0)
    with pytest.raises(bs.InputError, match=match):
        bs.solve(m, steps=2, verbose=False, **kw)


def test_options_object_and_dict_are_the_same():
    P_lim, _ = truss_limit()
    runs = []
    for opts in (dict(initial=0.05, target_iterations=3), bs.ArcLength(initial=0.05, target_iterations=3)):
        m, _ = truss(P_lim)
        runs.append(bs.solve(m, steps=10, t_end=0.5, path="arc-length", arc_length=opts, verbose=False))
    np.testing.assert_array_equal(runs[0].times, runs[1].times)
    assert runs[0].stats[1]["arc_length"] == 0.05


def test_a_load_scale_giving_nan_on_the_path_is_named():
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), bs.Section.circular(radius=0.01, E=2e11))
    m.clamp(b.first)
    m.add_load(b.last, force=(0, 0, 100.0), scale=lambda t: float("nan") if 0.4 < t < 0.6 else t)
    with pytest.raises(bs.InputError, match="scale") as e:
        bs.solve(m, steps=10, path="arc-length", verbose=False)
    assert e.value.solution.n_steps >= 3          # the steps before 0.4 stand


def test_restart_is_refused_with_arc_length(truss_path):
    sol, _, _ = truss_path
    with pytest.raises(bs.InputError, match="restart is not supported"):
        bs.solve(sol.model, steps=2, t_end=2.0, path="arc-length", restart=sol, verbose=False)


# ------------------------------------------------------------------ consumers of non-monotonic times
def test_output_and_archive_keep_the_path_order(tmp_path):
    P_lim, _ = truss_limit()
    m, apex = truss(P_lim)
    sol = bs.solve(m, steps=10, t_end=1.5, path="arc-length", output=tmp_path / "out", verbose=False)
    assert np.any(np.diff(sol.times) < 0)
    pvd = (tmp_path / "out" / "beams.pvd").read_text()
    stamps = [float(s.split('"')[1]) for s in pvd.split("timestep=")[1:]]
    assert stamps == list(range(sol.n_steps + 1))      # step numbers: ParaView keeps the path order
    back = bs.load(tmp_path / "out")
    np.testing.assert_array_equal(back.times, sol.times)
    assert back.converged and back.resume["path"] == "arc-length"


@pytest.mark.slow
def test_history_plot_and_info_of_an_arc_length_run(tmp_path):
    """``viz.plot_history`` draws the path in step order (t back and forth); ``beamsolver info``
    reports the finished run as converged."""
    import subprocess
    pytest.importorskip("matplotlib")
    from beamsolver import viz
    P_lim, _ = truss_limit()
    m, apex = truss(P_lim)
    sol = bs.solve(m, steps=10, t_end=1.5, path="arc-length", output=tmp_path / "out", verbose=False)
    fig = viz.plot_history(sol, "position", node=apex, component="y", path=tmp_path / "h.png")
    x, _ = fig.axes[0].lines[0].get_data()
    np.testing.assert_array_equal(x, sol.times)
    out = subprocess.run([sys.executable, "-m", "beamsolver.app.cli", "info", str(tmp_path / "out")],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and "; converged" in out.stdout, out.stderr
