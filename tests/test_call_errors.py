"""Bad input named by an ``InputError`` at the call, not a traceback later or a silent wrong answer
(issue 28 items 6 and 13, API part): write_vtk's steps, a duplicated contact declaration, a contact
law of plain Python functions, linearize's step, plot_history's node, topology's polygons,
build_strand's layers and solve's ``output=""``."""
import os

import numpy as np
import pytest
from numba.core import config as numba_config

import beamsolver as bs
from beamsolver import cables, topology
from beamsolver.contact.law import PENALTY_COULOMB, ContactLaw
from beamsolver.io.vtk import write_vtk


def _cantilever(n=2):
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(0, 1.0, 0))
    return m, b


@pytest.fixture(scope="module")
def solved():
    m, b = _cantilever()
    return m, bs.solve(m, steps=4, verbose=False)


@pytest.mark.parametrize("steps, words", [([7], "step 7 out of range"), ([-6], "step -6 out of range"),
                                          (5, "list of step numbers"), ([1.5], "integers"),
                                          ("1", "list of step numbers")])
def test_write_vtk_refuses_steps_the_solution_lacks(solved, tmp_path, steps, words):
    _, sol = solved
    with pytest.raises(bs.InputError, match=words):
        write_vtk(sol, tmp_path / "v", steps=steps)
    assert not list((tmp_path / "v").glob("*.vtu")) if (tmp_path / "v").exists() else True
    write_vtk(sol, tmp_path / "ok", steps=[-1, 0])
    assert sorted(p.name for p in (tmp_path / "ok").glob("*.vtu")) == ["beams_0000.vtu", "beams_0004.vtu"]


def _two_beams():
    sec = bs.Section.circular(radius=1e-3, E=200e9, nu=0.3)
    m = bs.Model()
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), sec)
    b = m.add_beam(bs.geometry.straight((0, 0, 2e-3), (1, 0, 2e-3), 4), sec)
    c = m.add_beam(bs.geometry.straight((0, 0, 4e-3), (1, 0, 4e-3), 4), sec)
    return m, a, b, c


def test_duplicated_contact_declaration_is_refused_naming_the_pair():
    m, a, b, c = _two_beams()
    m.add_contact(a, b, mu=0.2)
    for slave, master in ((a, b), (b, a), ([a, c], b), ([a, b, c], [a, b, c])):
        with pytest.raises(bs.InputError, match="beams 0 and 1 are already in contact"):
            m.add_contact(slave, master)
    assert len(m.contacts) == 1
    m.add_contact(b, c)                      # another pair is fine
    assert len(m.contacts) == 2


@pytest.mark.skipif(numba_config.DISABLE_JIT, reason="NUMBA_DISABLE_JIT=1: every function is plain Python")
def test_contact_law_of_plain_python_functions_is_refused_at_add_contact():
    m, a, b, _ = _two_beams()
    plain = ContactLaw("plain", PENALTY_COULOMB.normal.py_func, PENALTY_COULOMB.tangential)
    with pytest.raises(bs.InputError, match="'plain': normal must be numba-compiled"):
        m.add_contact(a, b, law=plain)
    assert not m.contacts
    m.add_contact(a, b, law=PENALTY_COULOMB)


@pytest.mark.parametrize("step", [1.5, "1", None, True])
def test_linearize_refuses_a_step_that_is_not_a_step_number(solved, step):
    m, sol = solved
    with pytest.raises(bs.InputError, match="linearize: step"):
        bs.linearize(m, sol, step=step)
    assert bs.linearize(m, sol, step=-1).step == 4


@pytest.mark.parametrize("node, words", [(99, "unknown node id 99"), (1.5, "unknown node id 1.5"),
                                         ("tip", "unknown node id 'tip'")])
def test_plot_history_names_a_bad_node(solved, node, words):
    pytest.importorskip("matplotlib")
    from beamsolver import viz
    _, sol = solved
    with pytest.raises(bs.InputError, match=words):
        viz.plot_history(sol, "reaction", node=node)


@pytest.mark.parametrize("call, words", [
    (lambda: topology.writhe_open(np.full((5, 3), np.nan)), "writhe_open: points must be finite"),
    (lambda: topology.writhe_open(np.zeros((5, 2))), r"writhe_open: points must have shape \(n, 3\)"),
    (lambda: topology.writhe_open(np.zeros((1, 3))), "at least 2 points"),
    (lambda: topology.writhe_open(np.eye(3), axis=(0, 0, 0)), "writhe_open: axis"),
    (lambda: topology.writhe_closed(np.zeros((4, 4))), r"writhe_closed: points must have shape \(n, 3\)"),
    (lambda: topology.linking(np.eye(3), np.ones(3)), r"linking: points_b must have shape \(n, 3\)"),
    (lambda: topology.twist(np.eye(3), np.eye(4)), "twist: ribbon_vectors"),
    (lambda: topology.writhe_fuller(np.eye(3)[:, :2]), "writhe_fuller: points"),
    (lambda: topology.ribbon(np.eye(3), np.eye(4)[:, :3]), "ribbon: x_b"),
])
def test_topology_names_bad_polygons(call, words):
    with pytest.raises(bs.InputError, match=words):
        call()


def test_writhe_open_of_a_straight_polygon_is_still_zero():
    p = np.c_[np.zeros(5), np.zeros(5), np.linspace(0, 1, 5)]
    assert topology.writhe_open(p) == 0.0


def test_build_strand_takes_layer_dicts_and_names_a_bad_one():
    good = cables.build_strand([dict(wire_radius=1e-3), dict(wire_radius=1e-3, n_wires=6, lay_angle=0.2)],
                                  length=0.05, E=200e9, contact=False)
    assert len(good.wires[1]) == 6
    with pytest.raises(bs.InputError, match=r"layer 1.*'radius'"):
        cables.build_strand([dict(wire_radius=1e-3), dict(radius=1e-3, n_wires=6)], length=0.05, E=200e9)
    with pytest.raises(bs.InputError, match="layer 0 must be a cables.Layer or a dict"):
        cables.build_strand([1e-3], length=0.05, E=200e9)


def test_empty_output_folder_name_is_refused(tmp_path):
    m, _ = _cantilever()
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        with pytest.raises(bs.InputError, match="output"):
            bs.solve(m, steps=1, output="", verbose=False)
    finally:
        os.chdir(cwd)
    assert not list(tmp_path.iterdir())
