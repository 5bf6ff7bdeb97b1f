"""Strand builders: stress-free reference, exact helices, contact for touching neighbours only."""
import numpy as np
import pytest

from beamsolver import cables
from beamsolver.assembly.system import System
from beamsolver.errors import InputError

E = 200e9


def _strand(Rc=1.03e-3, Rw=1.0e-3, beta_deg=12.0, **kw):
    layers = [cables.Layer(Rc, 1), cables.Layer(Rw, 6, lay_angle=np.deg2rad(beta_deg))]
    return cables.build_strand(layers, 0.03, E, **kw)


def test_reference_residual_is_zero_for_every_wire():
    st = _strand(contact=False)
    sysm = System(st.model, check_rigid_modes=False)
    r, _, info = sysm.evaluate(sysm.poses0, np.zeros(len(sysm.load_scales)), tangent=False)
    scale = E * np.pi * 1e-6            # EA of a wire
    assert np.abs(r).max() < 1e-9 * scale
    assert np.abs(info["state"].sigma).max() < 1e-9 * scale


@pytest.mark.parametrize("direction", ["right", "left"])
def test_helices_have_the_exact_lay_angle_and_pitch_radius(direction):
    beta = np.deg2rad(12.0)
    layers = [cables.Layer(1.03e-3, 1), cables.Layer(1.0e-3, 6, lay_angle=beta, direction=direction)]
    st = cables.build_strand(layers, 0.03, E, contact=False)
    r = 1.03e-3 + 1.0e-3
    assert st.pitch_radii[1] == pytest.approx(r, rel=1e-14)
    assert st.lay_lengths[1] == pytest.approx(2 * np.pi * r / np.tan(beta), rel=1e-14)
    P = st.model.poses0
    for w in st.wires[1]:
        x, e1 = P[w.nodes, :3, 3], P[w.nodes, :3, 0]
        np.testing.assert_allclose(np.hypot(x[:, 0], x[:, 1]), r, rtol=1e-13)
        np.testing.assert_allclose(np.arccos(e1[:, 2]), beta, atol=1e-12)
        # handedness: the angular velocity of the centre line about e_z has the lay's sign
        turn = x[:, 0] * e1[:, 1] - x[:, 1] * e1[:, 0]
        assert np.all(np.sign(turn) == (1 if direction == "right" else -1))
    core = P[st.wires[0][0].nodes, :3, 3]
    np.testing.assert_allclose(core[:, :2], 0.0, atol=1e-15)


def test_contact_declared_for_touching_neighbours_only():
    # neighbouring helices come as close as about 2 r sin(pi/6) cos(beta): 2.0000 mm for
    # Rc = 1.034 mm (just touching; 1.03 mm overlaps, tests/model/test_strand_geometry.py), 2.05 mm for
    # Rc = 1.1 mm (2.7 % above 2 R = 2 mm)
    assert len(_strand(Rc=1.034e-3, touch_tol=1e-4).contacts) == 1 + 6
    assert len(_strand(Rc=1.1e-3, touch_tol=0.05).contacts) == 1 + 6
    assert len(_strand(Rc=1.1e-3, touch_tol=0.01).contacts) == 1
    # a core so thick that the outer wires are far apart
    assert len(_strand(Rc=1.5e-3, touch_tol=0.05).contacts) == 1
    assert len(_strand(contact=False).contacts) == 0


def test_bad_layers_raise_input_error():
    with pytest.raises(InputError, match="wire_radius"):
        cables.build_strand([cables.Layer(-1e-3, 1)], 0.03, E)
    with pytest.raises(InputError, match="length"):
        cables.build_strand([cables.Layer(1e-3, 1)], 0.0, E)
    with pytest.raises(InputError, match="direction"):
        cables.build_strand([cables.Layer(1e-3, 1), cables.Layer(1e-3, 6, lay_angle=0.2, direction="up")],
                            0.03, E)


def test_strand_contacts_take_exact_stick_s_c_from_the_wires_axial_stiffness():
    """``build_strand`` gives its frictional contacts exact stick's ``c`` from the slave wire's axial stiffness,
    ``EXACT_C_AXIAL EA / (L_e L_s)`` with ``L_s = n L_e / EXACT_N`` (slip in a strand runs along the wires), not the
    library's bending-based default (1/159 of it on the 6 deg strand of examples/strand_bending.py, whose slip steps
    crawled with it: docs/benchmarks.md, "Strand bending, session 10"); a user's ``penalty_t``, the penalty stick
    and frictionless contacts keep their options."""
    from beamsolver.model import contact_options as co
    layers = [cables.Layer(1e-3), cables.Layer(1e-3, 6, lay_length=0.1)]
    st = cables.build_strand(layers, 0.2, E=2e11, elements_per_lay=12, mu=0.3, fit_core=True)
    wire = st.wires[1][0]
    x = st.model.poses0[wire.nodes, :3, 3]
    n = len(wire.elements)
    Le = np.median(np.linalg.norm(np.diff(x, axis=0), axis=1))       # two-node elements
    EA = 2e11 * np.pi * 1e-6
    c = co.EXACT_C_AXIAL * EA / (Le * n * Le / co.EXACT_N)
    assert len(st.contacts) == 7                     # the core, and the closed layer's neighbours
    assert all(d.options["penalty_t"] == pytest.approx(c, rel=1e-12) for d in st.contacts)
    EI = 2e11 * np.pi * 1e-12 / 4
    assert c > 10 * co.EXACT_C * EI / (Le * (n * Le / co.EXACT_N) ** 3)     # stiffer than the bending-based c
    for kw in (dict(contact_options=dict(penalty_t=5.0)), dict(contact_options=dict(stick="penalty")), dict(mu=0.0)):
        st = cables.build_strand(layers, 0.2, E=2e11, elements_per_lay=12, **(dict(mu=0.3) | kw), fit_core=True)
        assert all(d.options.get("penalty_t") == kw.get("contact_options", {}).get("penalty_t") for d in st.contacts)
