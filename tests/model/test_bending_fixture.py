"""cables.bending_fixture: plates turned by -+kappa L / 2, a free axial plate under a dead pull, and
the P-delta-cancelling line load w = T kappa, which makes the moment uniform along an elastic bundle."""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver import cables

L, R, E = 1.0, 0.01, 1e9
SEC = bs.Section.circular(radius=R, E=E, nu=0.3)
EI, EA = SEC.C[4, 4], SEC.C[0, 0]
KAPPA = 0.2                             # 1/m at t = 1: plates turned by -+0.1 rad
PULL = 8.0 * EI / L**2                  # T L^2 / 8 EI = 1: the P-delta moment is of the order of EI kappa


def _beam_fixture(n=24, kappa=KAPPA):
    model = bs.Model()
    beam = model.add_beam(bs.geometry.straight((0, 0, 0), (0, 0, L), n), SEC)
    fx = cables.bending_fixture([beam], curvature=lambda t: kappa * t, pull=PULL, model=model)
    return model, beam, fx


def test_line_load_makes_the_moment_uniform_and_equal_to_EI_kappa():
    """Uniform to second order in kappa L: the pull and the line load keep their directions (dead)
    while the arc's tangent turns by up to kappa L / 2, so the deviation falls 4x when kappa halves."""
    dev = []
    for kappa in (KAPPA, KAPPA / 2):
        model, beam, fx = _beam_fixture(kappa=kappa)
        sol = bs.solve(model, steps=4)
        assert sol.converged
        M = np.array([fx.moment(sol, z, step=-1) for z in (0.125, 0.25, 0.5, 0.75)])
        dev.append(np.abs(M / (EI * kappa) - 1).max())
    assert dev[0] < 3e-4 and 3.5 < dev[0] / dev[1] < 4.5
    model, beam, fx = _beam_fixture()
    sol = bs.solve(model, steps=4)
    assert fx.moment(sol).shape == (5,)
    # the top plate: turned by +kappa L / 2 and pulled inwards by the chord shortening kappa^2 L^3 / 24
    top = sol.pose(fx.top)
    assert np.arctan2(top[0, 2], top[2, 2]) == pytest.approx(0.5 * KAPPA * L, rel=1e-12)
    dz = sol.position(fx.top)[2] - L
    assert dz == pytest.approx(-KAPPA**2 * L**3 / 24 + PULL * L / EA, rel=2e-3)
    # the bundle turns into an arc bulging away from the centre of curvature (+x here)
    assert sol.position(beam.nodes[12])[0] == pytest.approx(-(1 - np.cos(0.5 * KAPPA * L)) / KAPPA, rel=1e-3)


def test_without_the_line_load_the_pull_adds_its_P_delta_moment():
    model, beam, fx = _beam_fixture()
    model.line_loads.clear()
    sol = bs.solve(model, steps=4)
    M = np.array([fx.moment(sol, z, step=-1) for z in (0.125, 0.5)])
    assert abs(M[1] - M[0]) > 0.1 * EI * KAPPA


def test_strand_fixture_shares_the_line_load_as_the_axial_forces():
    beta = np.deg2rad(12.0)
    lay = 2 * np.pi * 2.1e-3 / np.tan(beta)
    st = cables.build_strand([cables.Layer(1.1e-3, 1), cables.Layer(1.0e-3, 6, lay_angle=beta)], lay, 200e9,
                             elements_per_lay=12)
    fx = cables.bending_fixture(st, curvature=1.0, pull=lambda t: 1000.0 * t)
    assert fx.length == pytest.approx(lay) and len(fx.line_loads) == 7
    # per unit T kappa, summed over the wires' reference lengths L_i = L / cos(beta_i): -L e_x
    total = sum(ld.q * lay / np.cos(0 if i == 0 else beta) for i, ld in enumerate(fx.line_loads))
    np.testing.assert_allclose(total / lay, (-1.0, 0.0, 0.0), rtol=1e-6, atol=1e-12)
    core, wire = fx.line_loads[0].q[0], fx.line_loads[1].q[0] / np.cos(beta)
    assert wire / core == pytest.approx(np.cos(beta) ** 3 / 1.1**2, rel=1e-6)   # EA c^3 shares
    with pytest.raises(bs.InputError, match="axis"):
        cables.bending_fixture(st, curvature=1.0, pull=1.0, axis="z")


def test_fixture_input_errors():
    model = bs.Model()
    along_x = model.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), SEC)
    with pytest.raises(bs.InputError, match=r"run along \+e_z"):
        cables.bending_fixture([along_x], curvature=1.0, pull=1.0, model=model)
    with pytest.raises(bs.InputError, match="model="):
        cables.bending_fixture([along_x], curvature=1.0, pull=1.0)
    with pytest.raises(bs.InputError, match="curvature"):
        cables.bending_fixture([along_x], curvature="big", pull=1.0, model=model)
