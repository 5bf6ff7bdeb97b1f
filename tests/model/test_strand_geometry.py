"""cables.build_strand builds valid geometry: neighbouring wires' clearance from the helix geometry,
overlaps refused (or the core fitted), per-lay core meshing, a section per layer, and the step-0
report of the pre-stress of overlapping wires."""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver import cables

E = 200e9
B12 = np.deg2rad(12.0)


def _layers(Rc, beta=B12, **kw):
    return [cables.Layer(Rc, 1), cables.Layer(1.0e-3, 6, lay_angle=beta, **kw)]


@pytest.mark.parametrize("Rc,deg,clearance", [(1.0e-3, 12, -33.4e-6), (1.03e-3, 12, -3.90e-6),
                                              (1.03e-3, 15, -23.4e-6), (1.1e-3, 12, 64.9e-6)])
def test_clearance_of_neighbouring_helices_against_dense_sampling(Rc, deg, clearance):
    beta = np.deg2rad(deg)
    c = cables.layer_clearance(Rc + 1e-3, 1e-3, 6, beta)
    assert c == pytest.approx(clearance, abs=0.5e-6)         # the numbers: -33, -3.9, -23 um
    st = cables.build_strand(_layers(Rc, beta), 0.02, E, contact=False)
    s = np.linspace(0.0, 0.02, 200001)                       # centre lines sampled every 0.1 um
    phi = np.tan(beta) * s / (Rc + 1e-3)
    x = (Rc + 1e-3) * np.stack([np.cos(phi), np.sin(phi)])
    y = (Rc + 1e-3) * np.stack([np.cos(phi + np.pi / 3), np.sin(phi + np.pi / 3)])
    mid = len(s) // 2
    d = np.sqrt(((x[:, mid, None] - y) ** 2).sum(axis=0) + (s[mid] - s) ** 2).min()
    assert c == pytest.approx(d - 2e-3, abs=1e-9)
    assert st.clearances[1] == c and st.clearances[0] is None


def test_elliptical_cut_closes_the_layer_where_the_exact_clearance_vanishes():
    for deg, tol in ((5, 1e-5), (12, 2e-4), (20, 1.5e-3)):
        beta = np.deg2rad(deg)
        r = cables.closing_radius(1e-3, 6, beta)
        exact = r + cables.layer_clearance(r, 1e-3, 6, beta)  # a first-order root correction
        assert abs(cables.layer_clearance(r, 1e-3, 6, beta)) < tol * r
        assert abs(exact / r - 1) < tol


def test_overlapping_layer_is_refused_with_the_clearance_and_the_core_that_fixes_it():
    with pytest.raises(bs.InputError, match=r"layer 1 .*overlap each other: clearance -3.9e-06; a core radius "
                                            r"of at least 0.00103397 \(now 0.00103\)"):
        cables.build_strand(_layers(1.03e-3), 0.03, E)
    st = cables.build_strand(_layers(1.03397e-3), 0.03, E)   # the radius the message gives
    assert st.clearances[1] > 0 and len(st.contacts) == 1 + 6
    # without contact between the neighbours an overlap puts no force: allowed, as before
    assert len(cables.build_strand(_layers(1.03e-3), 0.03, E, touch_tol=-0.5).contacts) == 1


def test_fit_core_sizes_the_core_so_the_layer_just_closes():
    st = cables.build_strand(_layers(1.0e-3), 0.03, E, fit_core=True, touch_tol=1e-6)
    Rc = st.layers[0].wire_radius
    assert Rc == pytest.approx(1.033967e-3, rel=1e-6)
    assert abs(st.clearances[1]) < 1e-12
    assert st.pitch_radii[1] == pytest.approx(Rc + 1e-3, rel=1e-15)
    assert st.wires[0][0].section.radius == Rc
    assert len(st.contacts) == 1 + 6
    # a core that already leaves room is kept
    assert cables.build_strand(_layers(1.1e-3), 0.03, E, fit_core=True).layers[0].wire_radius == 1.1e-3


def test_core_is_meshed_per_lay_and_each_layer_has_its_section():
    soft = bs.Section.circular(radius=1.0e-3, E=E / 2, nu=0.3)
    layers = [cables.Layer(1.1e-3, 1), cables.Layer(1.0e-3, 6, lay_angle=B12, section=soft)]
    lay = 2 * np.pi * 2.1e-3 / np.tan(B12)
    st = cables.build_strand(layers, 4 * lay, E, elements_per_lay=12)
    assert st.wires[0][0].n_elements == 48                       # was 12: per total length
    assert all(w.n_elements == 48 for w in st.wires[1])
    assert all(w.section is soft for w in st.wires[1])
    assert st.wires[0][0].section.C[0, 0] == pytest.approx(E * np.pi * 1.1e-3 ** 2)
    with pytest.raises(bs.InputError, match="section radius"):
        cables.build_strand([cables.Layer(1.5e-3, 1), cables.Layer(1.2e-3, 6, lay_angle=B12, section=soft)],
                            lay, E)


def test_step_zero_reports_the_prestress_of_initial_overlaps():
    # the outer wires' pitch radius 2 um inside the core: they press on it in the unloaded model
    # (adjust=0: the default strain-free adjustment, 1e-3 (R1 + R2) = 2.1 um, takes it as touching)
    layers = [cables.Layer(1.1e-3, 1), cables.Layer(1.0e-3, 6, lay_angle=B12, pitch_radius=2.098e-3)]
    lay = 2 * np.pi * 2.1e-3 / np.tan(B12)
    st = cables.build_strand(layers, 0.5 * lay, E, elements_per_lay=12, contact_options=dict(adjust=0))
    st.clamp("bottom")
    st.clamp("top")
    with pytest.warns(RuntimeWarning, match=r"overlap in the given poses, the deepest by 2e-06"):
        sol = bs.solve(st.model, steps=1)
    assert "pre-stresses" in sol.message and "pre-stresses" in sol.stats[0]["warnings"][0]
    adjusted = cables.build_strand(layers, 0.5 * lay, E, elements_per_lay=12)
    adjusted.clamp("bottom")
    adjusted.clamp("top")
    sol = bs.solve(adjusted.model, steps=1)
    assert sol.message == "" and sol.stats[0]["adjusted"]["count"] > 0
    assert sol.stats[0]["adjusted"]["largest"] == pytest.approx(2e-6, rel=1e-2)
    ok = cables.build_strand([cables.Layer(1.1e-3, 1), cables.Layer(1.0e-3, 6, lay_angle=B12)], 0.5 * lay, E,
                             elements_per_lay=12)
    ok.clamp("bottom")
    ok.clamp("top")
    assert bs.solve(ok.model, steps=1).message == ""


def test_wires_around_an_empty_centre_just_touch():
    """The default pitch radius of a first layer without core closes it exactly (it was the
    straight wires' R / sin(pi / n), where helices overlap: 12 um for three wires at 12 deg)."""
    st = cables.build_strand([cables.Layer(1e-3, 3, lay_angle=B12)], 0.02, E, contact=False)
    assert abs(st.clearances[0]) < 1e-12
    assert cables.layer_clearance(1e-3 / np.sin(np.pi / 3), 1e-3, 3, B12) < -10e-6
