"""Contact options as one validated, typed object (``contact.options.ContactOptions``)."""
import dataclasses

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.nonlinear.problem import Problem
from beamsolver.contact.options import GAUSS_POINTS, SEGMENT_POINTS, SLIP_TOLERANCE, SMOOTHING, ContactOptions


def test_defaults_live_in_one_place():
    o = ContactOptions.from_dict({})
    assert o == ContactOptions()
    assert o.slip_tolerance == SLIP_TOLERANCE and o.smoothing is None and o.gauss_points is None
    assert o.integration == "points" and (GAUSS_POINTS, SEGMENT_POINTS) == (5, 3)
    assert o.line_angle == pytest.approx(np.deg2rad(20.0)) and o.margin is None
    assert SMOOTHING >= 0.0


@pytest.mark.parametrize("options, n", [({}, (5, 3)), (dict(integration="segments"), (5, 3)),
                                        (dict(integration="segments", gauss_points=4), (4, 4))])
def test_gauss_points_default_per_integration(options, n):
    """``gauss_points=None``: 5 per whole slave element (points; with segments, the orthogonal pairs), 3 per
    segment."""
    m = bs.Model()
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 2), bs.Section.circular(radius=0.01, E=1e9, nu=0.3))
    b = m.add_beam(bs.geometry.straight((0, 0, 0.02), (1, 0, 0.02), 3), bs.Section.circular(radius=0.01, E=1e9, nu=0.3))
    m.add_contact(b, a, **options)
    contact = Problem.from_model(m, check_rigid_modes=False).contact
    d = contact.decls[0]
    assert (d.n_gp, d.n_seg) == n and (len(d.gauss[0]), len(d.seg_gauss[0])) == n


def test_given_values_are_kept_and_typed():
    o = ContactOptions.from_dict(dict(gauss_points=3, smoothing=1e-6, line_angle=0.0))
    assert (o.gauss_points, o.smoothing, o.line_angle) == (3, 1e-6, 0.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        o.gauss_points = 4


@pytest.mark.parametrize("options,name", [(dict(gauss_points=0), "gauss_points"), (dict(smoothing=-1.0), "smoothing"),
                                          (dict(colour="red"), "colour"), (dict(line_angle=2.0), "line_angle")])
def test_bad_options_name_themselves(options, name):
    with pytest.raises(bs.InputError, match=name):
        ContactOptions.from_dict(options)


def test_the_contact_system_reads_the_object():
    sec = bs.Section.circular(radius=0.05, E=1e7, nu=0.3)
    m = bs.Model()
    a = m.add_beam(bs.geometry.straight((0, -1, 0), (0, 1, 0), 2), sec)
    b = m.add_beam(bs.geometry.straight((-1, 0, 0.1), (1, 0, 0.1), 2), sec)
    m.clamp(a.first)
    m.clamp(b.first)
    m.add_contact(b, a, gauss_points=3, margin=0.2)
    d = Problem.from_model(m, check_rigid_modes=False).contact.decls[0]
    assert d.options == ContactOptions(gauss_points=3, margin=0.2)
    assert (d.n_gp, d.margin) == (3, 0.2)


def test_the_search_returns_one_typed_pair_record():
    from beamsolver.contact.record import PairSet
    sec = bs.Section.circular(radius=0.05, E=1e7, nu=0.3)
    m = bs.Model()
    a = m.add_beam(bs.geometry.straight((0, -1, 0), (0, 1, 0), 3), sec)
    b = m.add_beam(bs.geometry.straight((-1, 0, 0.1), (1, 0, 0.1), 3), sec)       # crossing, touching
    c = m.add_beam(bs.geometry.straight((-1, 0.3, 0.1), (1, 0.3, 0.1), 3), sec)   # crossing, touching
    m.clamp(a.first)
    m.add_contact([b, c], a)
    problem = Problem.from_model(m, check_rigid_modes=False)
    system = problem.system
    P = problem.contact.pairs(system.poses0)
    assert isinstance(P, PairSet) and len(P) == 2
    assert set(P.e.tolist()) == {b.elements[1], c.elements[1]} and set(P.m.tolist()) <= set(a.elements.tolist())
    np.testing.assert_array_equal(P.nodes[:, :2], system.enodes[P.e])
    one = P.take(P.e == c.elements[1])
    assert len(one) == 1 and one.R1[0] == 0.05
    both = PairSet.concatenate([one, P.take(P.e != c.elements[1])])
    assert sorted(both.key.tolist()) == sorted(P.key.tolist())


def test_default_smoothing_only_for_line_contact():
    sec = bs.Section.circular(radius=0.05, E=1e7, nu=0.3)
    m = bs.Model()
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 2), sec)
    line = m.add_beam(bs.geometry.straight((0, 0, 0.1), (1, 0, 0.1), 2), sec)        # parallel: line
    cross = m.add_beam(bs.geometry.straight((0.5, -1, -0.1), (0.5, 1, -0.1), 2), sec)  # crossing: point
    m.clamp(a.first)
    m.add_contact([line, cross], a)
    m.add_contact(line, cross, smoothing=1e-3)
    cs = Problem.from_model(m, check_rigid_modes=False).contact
    P = cs.pairs(cs.sys.poses0)
    w = cs._smoothing(P, slice(None))
    from beamsolver.contact.frames import LINE, POINT
    first = P.decl == 0
    np.testing.assert_allclose(w[first & (P.kind == LINE)], SMOOTHING * 0.1)
    assert (first & (P.kind == POINT)).any() and np.all(w[first & (P.kind == POINT)] == 0.0)
    assert (~first).any()
    np.testing.assert_allclose(w[~first], 1e-3)


def test_each_option_is_written_once_with_its_default_check_and_meaning():
    """Every field carries its check and meaning; ``add_contact``'s docstring is made from them, and
    ``add_contact`` refuses a bad value through the same check (naming the option)."""
    from beamsolver.model.contact_options import describe
    doc = bs.Model.add_contact.__doc__
    for f in dataclasses.fields(ContactOptions):
        assert callable(f.metadata["check"]) and f.metadata["doc"], f.name
        assert f"``{f.name}``: " in doc and f"``{f.name}``: " in describe(), f.name
    assert "{contact_options}" not in doc
    m = bs.Model()
    sec = bs.Section.circular(radius=0.05, E=1e7, nu=0.3)
    a = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 2), sec)
    b = m.add_beam(bs.geometry.straight((0, 0, 0.2), (1, 0, 0.2), 2), sec)
    with pytest.raises(bs.InputError, match="add_contact: point_ratio"):
        m.add_contact(a, b, point_ratio=1.5)


def test_the_kernel_table_is_built_from_the_options():
    """``declaration_table``: one entry per declaration, ``None`` as the option's ``kernel_none``
    (smoothing and adjust: derived per pair, nan; tolerance: no updates, inf); the contact
    system's per-declaration arrays are that table."""
    from beamsolver.contact.options import declaration_table
    sec = bs.Section.circular(radius=0.05, E=1e7, nu=0.3)
    m = bs.Model()
    a = m.add_beam(bs.geometry.straight((0, -1, 0), (0, 1, 0), 2), sec)
    b = m.add_beam(bs.geometry.straight((-1, 0, 0.1), (1, 0, 0.1), 2), sec)
    c = m.add_beam(bs.geometry.straight((-1, 0.5, 0.1), (1, 0.5, 0.1), 2), sec)
    m.clamp(a.first)
    m.add_contact(b, a)
    m.add_contact(c, a, tolerance=1e-4, smoothing=2e-3, adjust=0.0)
    cs = Problem.from_model(m, check_rigid_modes=False).contact
    table = declaration_table([d.options for d in cs.decls])
    assert sorted(table) == ["adjust", "penalty_t", "smoothing", "tolerance"]
    np.testing.assert_array_equal(table["tolerance"], [np.inf, 1e-4])
    np.testing.assert_array_equal(table["smoothing"], [np.nan, 2e-3])
    np.testing.assert_array_equal(table["adjust"], [np.nan, 0.0])
    np.testing.assert_array_equal(cs._decl_tolerance, table["tolerance"])
    np.testing.assert_array_equal(cs._decl_smoothing, table["smoothing"])
    np.testing.assert_array_equal(cs._decl_adjust, table["adjust"])
