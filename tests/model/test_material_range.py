"""Material range of sections: closed-form surface strains, the once-only warning, the VTU field."""
import warnings

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.model import material_range as mr

R, E, NU, L = 1e-3, 200e9, 0.3, 0.1
G = E / (2 * (1 + NU))
A, I, J = np.pi * R**2, np.pi * R**4 / 4, np.pi * R**4 / 2


def cantilever(force=None, moment=None, steps=4, output=None, **section):
    """A straight steel rod along e_x, clamped at x = 0, loaded at its tip (ramped with t)."""
    model = bs.Model()
    beam = model.add_beam(bs.geometry.straight((0, 0, 0), (L, 0, 0), 8),
                          bs.Section.circular(radius=R, E=E, nu=NU, **section), name="arm")
    model.clamp(beam.first)
    model.add_load(beam.last, force=force, moment=moment)
    return bs.solve(model, steps=steps, output=output, verbose=False)


def test_pure_torsion_gives_gamma_r_dphi_ds():
    """A torque T twists the rod uniformly by dphi/ds = T / GJ: gamma = r dphi/ds at the surface,
    no normal strain, and eps_eq = sqrt(3) G gamma / E (von Mises of pure shear)."""
    T = 2.0
    sol = cantilever(moment=(T, 0, 0))
    e = sol.strains[-1] - sol.description["eps0"]
    eps, gamma = mr.surface_strains(e, R)
    np.testing.assert_allclose(gamma, R * T / (G * J), rtol=1e-9)
    assert np.all(np.abs(eps) < 1e-12 * gamma)
    np.testing.assert_allclose(sol.equivalent_strain(-1), np.sqrt(3) * G / E * R * T / (G * J), rtol=1e-9)


def test_pure_bending_gives_r_kappa():
    """An end moment bends the rod into a circle of curvature M / EI: eps = r kappa, eps_eq = eps."""
    M = 5.0
    sol = cantilever(moment=(0, 0, M))
    np.testing.assert_allclose(sol.equivalent_strain(-1), R * M / (E * I), rtol=1e-9)
    # no limit given: the utilisation is the equivalent strain
    np.testing.assert_array_equal(sol.utilisation(-1), sol.equivalent_strain(-1))


def test_axial_pull_gives_n_over_ea_and_stress_utilisation():
    N = 1000.0
    sol = cantilever(force=(N, 0, 0), yield_stress=1.2e9)
    np.testing.assert_allclose(sol.equivalent_strain(-1), N / (E * A), rtol=1e-9)
    np.testing.assert_allclose(sol.utilisation(-1), N / A / 1.2e9, rtol=1e-9)
    np.testing.assert_allclose(sol.utilisation(2), 0.5 * N / A / 1.2e9, rtol=1e-9)   # ramp: half at t = 0.5


def test_combined_parts_add_at_one_point():
    """Axial, bending, torsion and transverse shear on one synthetic strain (reference 0)."""
    e = np.array([[1e-3, 3e-4, -4e-4, 2.0, 0.3, -0.4]])
    eps, gamma = mr.surface_strains(e, R)
    assert eps[0] == pytest.approx(1e-3 + R * 0.5)
    assert gamma[0] == pytest.approx(2.0 * R + 4 / 3 * 5e-4)
    eq = mr.equivalent_strain(e, R, E, G)
    assert eq[0] == pytest.approx(np.sqrt((1e-3 + 0.5 * R) ** 2 + 3 * (G / E * (2 * R + 4 / 3 * 5e-4)) ** 2))


def test_warns_once_naming_beam_element_and_step():
    """Tip force F: element 0 (of 8) carries the moment at its middle, 15/16 F L, a stress
    15/16 F L R / I; the limit lies between the stresses of steps 2 and 3 (of 4): one warning,
    at step 3, element 0 of 'arm'."""
    F = 0.5                                             # tip deflection 2 % of L: nearly linear
    s_end = 15 / 16 * F * L * R / I
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = cantilever(force=(0, F, 0), yield_stress=0.6 * s_end)
    got = [w for w in caught if issubclass(w.category, bs.MaterialRangeWarning)]
    assert len(got) == 1, [str(w.message) for w in got]
    text = str(got[0].message)
    assert "step 3" in text and "'arm'" in text and "element 0 " in text, text
    u = np.array([s.get("utilisation") for s in sol.stats])
    assert u[2] < 1 < u[3] < u[4]
    assert u[4] == pytest.approx(1 / 0.6, rel=2e-4)     # shear and geometric nonlinearity: 4e-5
    assert np.argmax(sol.utilisation(-1)) == 0


def test_no_limit_no_check():
    """Without a limit nothing is recorded per step and nothing warns (no cost)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", bs.MaterialRangeWarning)
        sol = cantilever(force=(0, 1e4, 0), steps=1)
    assert all("utilisation" not in s for s in sol.stats)
    assert sol.utilisation(-1).max() > 0.01                  # far beyond any steel, but no limit given


def test_vtu_field_round_trips(tmp_path):
    meshio = pytest.importorskip("meshio")
    sol = cantilever(force=(0, 5.0, 0), steps=2, output=tmp_path, yield_strain=5e-3)
    mesh = meshio.read(tmp_path / "beams_0002.vtu")
    element = mesh.cell_data["element"][0]
    np.testing.assert_allclose(mesh.cell_data["utilisation"][0], sol.utilisation(2)[element], rtol=1e-12)
    np.testing.assert_allclose(mesh.cell_data["equivalent_strain"][0], sol.equivalent_strain(2)[element],
                               rtol=1e-12)
    np.testing.assert_allclose(sol.utilisation(2), sol.equivalent_strain(2) / 5e-3, rtol=1e-12)
    loaded = bs.load(tmp_path)
    np.testing.assert_array_equal(loaded.utilisation(2), sol.utilisation(2))


def test_archive_without_material_keys_uses_the_radius():
    """A description saved before the material range: moduli of a solid circle of the radius."""
    sol = cantilever(moment=(1.0, 0, 0), steps=1)
    d = {k: v for k, v in sol.description.items() if not k.startswith(("beam_E", "beam_G", "beam_yield"))}
    r, E_, G_, sy, ey = mr.element_properties(d)
    np.testing.assert_allclose(E_, E, rtol=1e-12)
    np.testing.assert_allclose(G_, G, rtol=1e-12)
    assert np.all(np.isinf(sy)) and np.all(np.isinf(ey))


@pytest.mark.parametrize("kw, word", [(dict(yield_stress=-1.0), "yield_stress"),
                                      (dict(yield_strain=0.0), "yield_strain"),
                                      (dict(yield_stress=1e9, yield_strain=1e-2), "not both")])
def test_bad_limits_are_named(kw, word):
    with pytest.raises(bs.InputError, match=word):
        bs.Section.circular(radius=R, E=E, **kw)
    with pytest.raises(bs.InputError, match=word):
        bs.Section(EA=1, GA2=1, GA3=1, GJ=1, EI2=1, EI3=1, radius=1, name="s", **kw)


def test_rectangle_keeps_its_moduli():
    s = bs.Section.rectangular(2e-3, 1e-3, E=E, nu=NU, yield_strain=1e-2)
    assert (s.E, s.G, s.yield_strain, s.yield_stress) == (E, G, 1e-2, None)


def test_strand_of_a_named_grade_gets_its_proof_stress():
    from beamsolver import cables
    st = cables.build_strand([cables.Layer(0.5e-3), cables.Layer(0.5e-3, 6, lay_angle=0.2)], length=0.02,
                             E=E, grade="1770", contact=False)
    assert {w.section.yield_stress for w in st.all_wires} == {cables.PROOF_FRACTION * 1770e6}
    plain = cables.build_strand([cables.Layer(0.5e-3)], length=0.02, E=E, contact=False)
    assert plain.all_wires[0].section.yield_stress is None
    with pytest.raises(bs.InputError, match="grade"):
        cables.build_strand([cables.Layer(0.5)], length=20.0, E=2e5, grade="1770")   # N, mm: no SI
    with pytest.raises(bs.InputError, match="grade"):
        cables.build_strand([cables.Layer(0.5e-3)], length=0.02, E=E, grade="steel")


def test_material_summary_names_the_worst_element():
    sol = cantilever(force=(0, 0.5, 0), steps=2, yield_stress=1e9)
    text = sol.material_summary()
    eq = sol.equivalent_strain(-1)
    assert f"{eq.max():.3g} ('arm' element 0, step 2)" in text
    assert f"up to {sol.utilisation(-1).max():.3g} (within range)" in text
    assert "no section has a limit" in cantilever(moment=(1.0, 0, 0), steps=1).material_summary()


def test_arc_length_and_restart_check_their_steps_too(tmp_path):
    """Both other ways a step is recorded (arc length, a restarted run) record the utilisation."""
    model = bs.Model()
    beam = model.add_beam(bs.geometry.straight((0, 0, 0), (L, 0, 0), 4),
                          bs.Section.circular(radius=R, E=E, nu=NU, yield_strain=1.0), name="arm")
    model.clamp(beam.first)
    model.add_load(beam.last, moment=(2.0, 0, 0))
    arc = bs.solve(model, steps=2, path="arc-length", verbose=False)
    assert all("utilisation" in s for s in arc.stats[1:])
    first = bs.solve(model, steps=4, t_end=0.5, output=tmp_path, verbose=False)
    again = bs.solve(model, steps=4, t_end=1.0, restart=first, verbose=False)
    assert again.stats[-1]["utilisation"] == pytest.approx(np.sqrt(3) * G / E * R * 2.0 / (G * J), rel=1e-9)
