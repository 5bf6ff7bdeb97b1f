"""Small API frictions a new user met (issue 17): progress text, bs.io.vtk, contact groups, constants."""
import dataclasses
import io
import subprocess
import sys

import numpy as np
import pytest

import beamsolver as bs
from beamsolver import cables
from beamsolver.contact.options import ContactOptions


def cantilever(n=4, load=1.0, scale=None):
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (10, 0, 0), n), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(0, load, 0), **({} if scale is None else dict(scale=scale)))
    return m, b


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def test_progress_bar_has_no_stray_comma(monkeypatch):
    term = _Terminal()
    monkeypatch.setattr("sys.stderr", term)
    bs.solve(cantilever()[0], steps=4)
    text = term.getvalue()
    assert "t = ," not in text and "t = 0 [" in text and "t = 1  step 4  iterations" in text


def test_io_vtk_is_reachable_after_import_beamsolver():
    code = ("import sys, beamsolver as bs; assert 'meshio' not in sys.modules; "
            "w = bs.io.vtk.StepWriter; assert 'meshio' in sys.modules or w; print(w.__name__)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "StepWriter"
    with pytest.raises(AttributeError):
        bs.io.no_such_module


def test_add_contact_docstring_lists_every_option():
    doc = bs.Model.add_contact.__doc__
    for name in sorted({f.name for f in dataclasses.fields(ContactOptions)} | {"mu", "penalty"}):
        assert f"``{name}``" in doc, name


def three_wires(group, mu=0.0):
    """Three touching helical wires around an empty centre, stretched by a plate."""
    st = cables.build_strand([cables.Layer(1e-3, 3, lay_angle=np.deg2rad(12.0))], 0.02, 200e9,
                             elements_per_lay=12, contact=False)
    w = st.wires[0]
    if group:
        decls = st.model.add_contact(w, w, mu=mu)
    else:
        decls = [st.model.add_contact(w[0], w[1], mu=mu), st.model.add_contact(w[0], w[2], mu=mu),
                 st.model.add_contact(w[1], w[2], mu=mu)]
    st.clamp("bottom")
    plate = st.plate("top")
    st.model.prescribe(plate, bs.motion.translation((0.0, 0.0, 2e-6)))
    return st, plate, decls


def test_group_contact_declaration_equals_the_pairwise_one():
    st_g, plate, decls = three_wires(True)
    assert [(d.slave[0].id, d.master[0].id) for d in decls] == [(0, 1), (0, 2), (1, 2)]
    st_p, _, _ = three_wires(False)
    sol_g, sol_p = bs.solve(st_g.model, steps=1), bs.solve(st_p.model, steps=1)
    cg, cp = sol_g.contact(), sol_p.contact()
    assert cg["normal_force"].sum() > 0                              # the wires press on each other
    np.testing.assert_array_equal(cg["normal_force"], cp["normal_force"])
    np.testing.assert_array_equal(sol_g.reactions, sol_p.reactions)
    a, b, c = st_g.wires[0]
    with pytest.raises(bs.InputError, match="with itself"):
        st_g.model.add_contact(a, [a])
    with pytest.raises(bs.InputError, match="same beams on both sides"):
        st_g.model.add_contact([a, b], [b, c])                      # only partly overlapping: a mistake
    with pytest.raises(bs.InputError, match="already in contact"):
        st_g.model.add_contact([c, a, b], [a, b, c])                 # declared twice: twice the penalty
    fresh = cables.build_strand([cables.Layer(1e-3, 3, lay_angle=np.deg2rad(12.0))], 0.02, 200e9,
                                elements_per_lay=12, contact=False)
    a, b, c = fresh.wires[0]
    more = fresh.model.add_contact([c, a, b], [a, b, c])            # the same group in another order
    assert [(d.slave[0].id, d.master[0].id) for d in more] == [(2, 0), (2, 1), (0, 1)]


def test_fix_values_accept_a_constant():
    m, b = cantilever()
    m.add_load(b.last, force=(0, -1.0, 0))           # cancels the other load: only the fix value acts
    m.fix(b.last, ("uz",), values={"uz": 0.01})
    sol = bs.solve(m, steps=2)
    for k in range(3):                               # held from step 0 (solved at t = 0) to the end
        assert sol.position(b.last, k)[2] == pytest.approx(0.01, abs=1e-12)
    for bad in ("x", np.inf, None):
        with pytest.raises(bs.InputError, match=r"values\['uz'\]"):
            m.fix(b.last, ("uz",), values={"uz": bad})


def test_step_0_is_the_equilibrium_when_loads_act_at_t_start():
    m, b = cantilever(load=1.0, scale=lambda t: 1.0)          # a constant load, acting at t = 0
    sol = bs.solve(m, steps=2)
    assert sol.stats[0]["iterations"] > 0
    np.testing.assert_allclose(sol.reaction(b.first, 0)[:3], [0, -1.0, 0], atol=1e-9)
    np.testing.assert_allclose(sol.poses[0], sol.poses[-1], atol=1e-12)   # nothing changes after t = 0
    # a ramped load is zero at t = 0: step 0 is the reference, no Newton iterations
    m, b = cantilever()
    sol = bs.solve(m, steps=2)
    assert sol.stats[0]["iterations"] == 0 and np.array_equal(sol.poses[0], m.poses0)
    # a prescribed motion already non-zero at t_start
    m, b = cantilever(load=0.0)
    m.prescribe(b.last, bs.motion.translation(lambda t: (0.0, 0.1 * (1.0 + t), 0.0)))
    sol = bs.solve(m, steps=1)
    np.testing.assert_allclose(sol.position(b.last, 0), [10.0, 0.1, 0.0], atol=1e-12)
    assert abs(sol.reaction(b.last, 0)[1]) > 0


def test_no_equilibrium_at_t_start_raises_convergence_error():
    m, b = cantilever(n=2)
    m.add_load(b.last, moment=(0, 0, 2 * np.pi * 1e2 / 10 * 2.0), follower=True, scale=lambda t: 1.0)
    with pytest.raises(bs.ConvergenceError, match="t_start"):
        bs.solve(m, steps=2)


def test_one_twisted_wire_buckles_at_greenhill_torque():
    """The eigenvalue test behind the twisted pair's stability message, on one clamped wire:
    Greenhill's M L / B = 8.99 (8 elements, 8 steps per turn: within 2 %)."""
    import twisted_pair_stability as ts
    (turns, M), _ = ts.run_wire(8, 8, pull=0.0)
    B = bs.Section.circular(radius=ts.R, E=ts.E, nu=ts.NU).C[4, 4]
    assert M * ts.L / B == pytest.approx(8.99, rel=0.02)
