"""Issue 12 (input side): aliased reference geometry, non-rigid poses, the unit- and
origin-invariant rigid-mode check, and wrongly typed arguments all give an ``InputError``
naming the argument and the value (never a raw TypeError/ValueError/OverflowError/MemoryError
and never a silently wrong model)."""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver import InputError, cables, geometry


def _sec(scale=1.0):
    """A steel-like rod section in units of ``scale`` metres (forces in N)."""
    return bs.Section.circular(radius=0.01 * scale, E=2e11 / scale**2)


def _cantilever(scale=1.0, origin=(0.0, 0.0, 0.0), n=4):
    m = bs.Model()
    o = np.asarray(origin, dtype=float)
    b = m.add_beam(geometry.straight(o, o + (scale, 0.0, 0.0), n), _sec(scale))
    m.clamp(b.first)
    m.add_load(b.last, force=(0.0, 0.0, 10.0))
    return m, b


def _crossing():
    m = bs.Model()
    a = m.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), 4), _sec())
    b = m.add_beam(geometry.straight((0.5, -0.5, 0.02), (0.5, 0.5, 0.02), 4), _sec())
    return m, a, b


# ---------------------------------------------------------------- item 2: reference aliasing
def test_arc_refuses_elements_turning_past_the_limit_and_names_the_count():
    with pytest.raises(InputError, match=r"geometry.arc: .*4.189 rad per element.*n_elements >= 2"):
        geometry.arc(1.0, 4 * np.pi / 3, n_elements=1)
    with pytest.raises(InputError, match=r"n_elements >= 6"):
        geometry.arc(1.0, -4 * np.pi, n_elements=5)     # two full turns in 5 elements
    P = geometry.arc(1.0, 4 * np.pi / 3, n_elements=2)    # 2.09 rad each: representable
    assert bs.Model().add_beam(P, _sec()).n_elements == 2


def test_helix_refuses_one_element_per_turn():
    with pytest.raises(InputError, match=r"geometry.helix: .*6.283 rad per element.*n_elements >= 3"):
        geometry.helix(radius=0.1, pitch=1.0, length=1.0, n_elements=1)
    with pytest.raises(InputError, match=r"n_elements >= 27"):
        geometry.helix(radius=0.1, pitch=-0.1, length=1.0, n_elements=20)   # 10 turns
    geometry.helix(radius=0.1, pitch=1.0, length=1.0, n_elements=3)        # 2.09 rad each


def test_helix_element_rotation_is_two_pi_per_turn():
    """The limit the generator applies is the element's true rotation (Darboux vector)."""
    from beamsolver.elements.element import reference_strain
    P = geometry.helix(radius=0.3, pitch=0.7, length=0.7, n_elements=4)
    L, eps0 = reference_strain(P[:-1], P[1:])
    np.testing.assert_allclose(np.linalg.norm(eps0[:, 3:] * L[:, None], axis=1), 2 * np.pi / 4, rtol=1e-12)


@pytest.mark.parametrize("points", [
    [[0, 0, 0], [1, 0, 0], [0.5, 0, 0.01]],                # folds back
    [[0, 0, 0], [1, 0, 0], [0.5, 0, 0]],                   # reverses exactly
    [[0, 0, 0], [1, 0, 0], [0.1, 0.3, 0], [0.1, 1.0, 0]],    # a 160-degree corner
])
def test_polyline_refuses_folding_back(points):
    with pytest.raises(InputError, match=r"geometry.polyline: .*turns by .* rad \(limit 0.75 pi = 2.356"):
        geometry.polyline(points)


def test_polyline_accepts_a_coarse_but_representable_circle():
    phi = np.linspace(0.0, 1.5 * np.pi, 4)        # 0.5 pi per segment
    P = geometry.polyline(np.stack([np.sin(phi), 1 - np.cos(phi), 0 * phi], axis=1))
    assert bs.Model().add_beam(P, _sec()).n_elements == 3


# ---------------------------------------------------------------- item 3: non-rigid poses
def test_prescribed_motion_that_scales_is_refused_at_the_time_it_happens():
    m, b = _cantilever()
    m.loads.clear()
    m.prescribe(b.last, lambda t: np.diag([1 + t, 1 + t, 1 + t, 1.0]))   # fine at t = 0
    with pytest.raises(InputError, match=rf"prescribe\({b.last}\): motion\(t = 0.5\) is not a rigid motion"):
        bs.solve(m, steps=2, verbose=False)


def test_prescribed_motion_with_a_bad_last_row_is_refused():
    m, b = _cantilever()

    def motion(t):
        G = np.eye(4)
        G[3, 0] = t
        return G
    m.prescribe(b.last, motion)
    with pytest.raises(InputError, match=r"motion\(t = 1\) .*last row"):
        bs.solve(m, steps=1, verbose=False)
    with pytest.raises(InputError, match=r"prescribe\(0\): motion\(t = 0\) is not a rigid motion.*det"):
        _cantilever()[0].prescribe(0, lambda t: np.diag([1.0, 1.0, -1.0, 1.0]))


def test_initial_poses_and_add_node_are_checked():
    m, b = _cantilever()
    H = m.poses0.copy()
    H[2, :3, :3] *= 1.01
    with pytest.raises(InputError, match=r"solve: initial_poses\[2\] is not a rigid motion"):
        bs.solve(m, steps=1, initial_poses=H, verbose=False)
    H = m.poses0.copy()
    H[3, 3, 1] = 0.5
    with pytest.raises(InputError, match=r"initial_poses\[3\].*last row"):
        bs.solve(m, steps=1, initial_poses=H, verbose=False)
    with pytest.raises(InputError, match=r"add_node\(plate\): pose .*last row"):
        m.add_node(np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [1, 0, 0, 1.0]]), name="plate")
    with pytest.raises(InputError, match=r"add_node\(plate\): pose is not a rigid motion"):
        m.add_node(np.diag([2.0, 1.0, 1.0, 1.0]), name="plate")


# ---------------------------------------------------------------- item 11: rigid modes
@pytest.mark.parametrize("origin", [(1e6, 0, 0), (1e5, -2e5, 3e5), (-1e7, 1e7, 0)])
def test_rigid_mode_check_far_from_origin_in_millimetres(origin):
    """The same clamped cantilever solves in metres and in millimetres far from the origin."""
    m_m, b_m = _cantilever(1.0, np.asarray(origin) / 1e3)
    m_mm, b_mm = _cantilever(1e3, origin)
    s_m = bs.solve(m_m, steps=1, verbose=False)
    s_mm = bs.solve(m_mm, steps=1, verbose=False)
    u_m = s_m.position(b_m.last) - m_m.poses0[b_m.last, :3, 3]
    u_mm = s_mm.position(b_mm.last) - m_mm.poses0[b_mm.last, :3, 3]
    np.testing.assert_allclose(u_mm, 1e3 * u_m, rtol=1e-6, atol=1e-6 * abs(u_mm).max())


@pytest.mark.parametrize("scale,origin", [(1.0, (0, 0, 0)), (1e3, (1e6, 2e6, 0)), (1e-3, (-5e3, 0, 1e3))])
def test_rigid_mode_check_still_counts_free_modes_far_away(scale, origin):
    m, b = _cantilever(scale, origin)
    m.constraints.clear()
    m.fix(b.first, ("ux", "uy", "uz"))
    m.fix(b.last, ("uy", "uz"))
    with pytest.raises(InputError, match=r"1 rigid-body mode\(s\) are not constrained"):   # twist about x
        bs.solve(m, steps=1, verbose=False)
    m.constraints.clear()
    m.fix(b.first, ("ux", "uy", "uz"))
    with pytest.raises(InputError, match=r"3 rigid-body mode\(s\) are not constrained"):
        bs.solve(m, steps=1, verbose=False)


# ---------------------------------------------------------------- item 12: wrongly typed arguments
def _strand(n_wires):
    return cables.build_strand([cables.Layer(1e-3), cables.Layer(1e-3, n_wires=n_wires, lay_angle=0.2)],
                               0.05, 2e11)


def _solve(**kw):
    return lambda: bs.solve(_cantilever()[0], verbose=False, **kw)


def _with_scale(scale, steps=1):
    m, b = _cantilever()
    m.loads.clear()
    m.add_load(b.last, force=(0, 0, 1.0), scale=scale)
    return lambda: bs.solve(m, steps=steps, verbose=False)


def _contact(**kw):
    m, a, b = _crossing()
    return lambda: m.add_contact(a, b, **kw)


def _contact_with(slave):
    m, a, b = _crossing()
    m.add_contact(slave, b)


def _restart_before_saved_time():
    m, _ = _cantilever()
    sol = bs.solve(m, steps=2, t_end=1.0, verbose=False)
    bs.solve(m, steps=2, t_end=0.5, restart=sol, verbose=False)


CASES = {
    "Section EA str": (lambda: bs.Section(EA="abc", GA2=1, GA3=1, GJ=1, EI2=1, EI3=1, radius=1),
                       r"Section: EA must be positive, got 'abc'"),
    "Section radius None": (lambda: bs.Section.circular(radius=None, E=1.0), r"radius .*got None"),
    "n_elements nan": (lambda: geometry.straight(n_elements=float("nan")), r"straight: n_elements .*got nan"),
    "n_elements inf": (lambda: geometry.arc(1.0, 1.0, n_elements=float("inf")), r"arc: n_elements .*got inf"),
    "n_elements None": (lambda: geometry.helix(0.1, 1.0, 1.0, n_elements=None), r"helix: n_elements .*None"),
    "n_elements 1e9": (lambda: geometry.straight(n_elements=10**9),
                       r"straight: n_elements must be at most 1000000, got 1000000000"),
    "n_elements bool": (lambda: geometry.polyline([[0, 0, 0], [1, 0, 0]], n_elements=True),
                        r"polyline: n_elements .*True"),
    "arc angle str": (lambda: geometry.arc("1", 1.0, 4), r"geometry.arc: radius .*'1'"),
    "steps nan": (_solve(steps=float("nan")), r"solve: steps must be a positive integer, got nan"),
    "steps None": (_solve(steps=None), r"solve: steps .*got None"),
    "steps 1e9": (_solve(steps=10**9), r"solve: steps must be at most 1000000, got 1000000000"),
    "t_end str": (_solve(t_end="1"), r"solve: t_end must be a finite number, got '1'"),
    "t_start nan": (_solve(t_start=float("nan")), r"solve: t_start .*nan"),
    "rtol negative": (_solve(rtol=-1e-8), r"solve: rtol must be positive, got -1e-08"),
    "dtol str": (_solve(dtol="small"), r"solve: dtol .*'small'"),
    "max_iter float": (_solve(max_iter=2.5), r"solve: max_iter .*2.5"),
    "min_step_ratio 2": (_solve(min_step_ratio=2.0), r"solve: min_step_ratio .*2.0"),
    "checkpoint negative": (_solve(checkpoint=-1), r"solve: checkpoint .*-1"),
    "initial_poses shape": (_solve(initial_poses=np.eye(4)), r"solve: initial_poses must have shape \(5, 4, 4\)"),
    "initial_poses nan": (_solve(initial_poses=np.full((5, 4, 4), np.nan)), r"initial_poses\[0\] .*finite"),
    "restart before": (_restart_before_saved_time,
                       r"solve: t_end = 0.5 is before the end of the restart solution \(t = 1\)"),
    "scale str": (_with_scale(lambda t: "x"), r"add_load\(4\): scale\(0\) must return a finite number, got 'x'"),
    "scale array": (_with_scale(lambda t: np.array([t, t])), r"add_load\(4\): scale\(0\) .*array"),
    "scale str later": (_with_scale(lambda t: "x" if 0.2 < t < 0.9 else t, steps=4),
                        r"add_load\(4\): scale\(0.25\) must return a finite number, got 'x'"),
    "scale nan later": (_with_scale(lambda t: np.nan if 0.2 < t < 0.9 else t, steps=4),
                        r"add_load\(4\): scale\(0.25\) must return a finite number, got nan"),
    "scale not callable": (lambda: _cantilever()[0].add_load(4, force=(1, 0, 0), scale=2.0),
                           r"add_load\(4\): scale must be callable"),
    "fix values str": (lambda: _fix_values_str(), r"fix\(4\): values\['uz'\]\(0\) must return a finite number"),
    "fix values array later": (lambda: _fix_values_array_later(),
                               r"fix\(4\): values\['uz'\]\(0.25\) must return .*array of shape \(2,\)"),
    "fix None": (lambda: _cantilever()[0].fix(4, None), r"fix\(4\): dofs .*None"),
    "clamp True": (lambda: _cantilever()[0].clamp(True), r"clamp: node id must be an integer, got True"),
    "node float": (lambda: _cantilever()[0].clamp(1.5), r"clamp: .*1.5"),
    "mu str": (_contact(mu="0.3"), r"add_contact: mu must be a number >= 0, got '0.3'"),
    "penalty str": (_contact(penalty="big"), r"add_contact: penalty .*'big'"),
    "margin negative": (_contact(margin=-1), r"add_contact: margin must be a number >= 0, got -1"),
    "line_angle nan": (_contact(line_angle=float("nan")), r"add_contact: line_angle .*nan"),
    "line_angle big": (_contact(line_angle=2.0), r"add_contact: line_angle .*\[0, pi/2\].*2.0"),
    "point_ratio": (_contact(point_ratio=-0.1), r"add_contact: point_ratio .*-0.1"),
    "gauss_points str": (_contact(gauss_points="x"), r"add_contact: gauss_points must be a positive integer, got 'x'"),
    "gauss_points 0": (_contact(gauss_points=0), r"add_contact: gauss_points .*got 0"),
    "smoothing str": (_contact(smoothing="a"), r"add_contact: smoothing .*'a'"),
    "tolerance 0": (_contact(tolerance=0.0), r"add_contact: tolerance .*0.0"),
    "unknown option": (_contact(gausspoints=3), r"add_contact: unknown options \['gausspoints'\]"),
    "e2 str": (lambda: geometry.straight(e2="abc"), r"geometry.straight: e2 must be an array of numbers, got 'abc'"),
    "poses str": (lambda: bs.Model().add_beam("abc", _sec()), r"Beam 0: poses must be an array of numbers"),
    "force str": (lambda: _cantilever()[0].add_load(4, force="up"), r"add_load\(4\): force must be an array"),
    "contact slave None": (lambda: _contact_with(None),
                           r"add_contact: slave must be a Beam or a list of Beams, got None"),
    "output int": (_solve(steps=1, output=3), r"solve: output must be a folder .*got 3"),
    "restart float": (_solve(steps=1, restart=1.5), r"solve: restart must be a Solution or the path .*got 1.5"),
    "load None": (lambda: bs.load(None), r"load: path must be a file or folder name .*got None"),
    "n_wires 2.5": (lambda: _strand(2.5), r"build_strand: layer 1 n_wires must be a positive integer, got 2.5"),
    "wire_radius str": (lambda: cables.build_strand([cables.Layer("1e-3")], 0.05, 2e11),
                        r"build_strand: layer 0 wire_radius .*'1e-3'"),
    "strand length str": (lambda: cables.build_strand([cables.Layer(1e-3)], "0.05", 2e11),
                          r"build_strand: length .*'0.05'"),
}


def _fix_values_array_later():
    m, b = _cantilever()
    m.fix(b.last, ("uz",), values={"uz": lambda t: np.array([t, t]) if 0.2 < t < 0.9 else 0.1 * t})
    return bs.solve(m, steps=4, verbose=False)


def _fix_values_str():
    m, b = _cantilever()
    m.fix(b.last, ("uz",), values={"uz": lambda t: "up"})
    return bs.solve(m, steps=1, verbose=False)


@pytest.mark.parametrize("name", list(CASES))
def test_wrongly_typed_argument_gives_input_error(name):
    call, pattern = CASES[name]
    with pytest.raises(InputError, match=pattern):
        call()


@pytest.mark.parametrize("unit", [1.0, 1e-3, 1e3])
def test_join_tolerance_is_relative_to_the_model_size_in_any_unit(unit):
    """Nodes 1e-8 model sizes apart are not coincident, in metres, kilometres or millimetres."""
    m = bs.Model()
    a = m.add_beam(geometry.straight((0, 0, 0), (unit, 0, 0), 2), _sec(unit))
    b = m.add_beam(geometry.straight((unit * (1 + 1e-8), 0, 0), (2 * unit, 0, 0), 2), _sec(unit))
    with pytest.raises(InputError, match=r"join\(2, 3\): nodes are .* apart"):
        m.join(a.last, b.first)
    c = m.add_beam(geometry.straight((unit * (1 + 1e-11), 0, 0), (2 * unit, 0, 0), 2), _sec(unit))
    m.join(a.last, c.first)                      # 1e-11 sizes apart: coincident
