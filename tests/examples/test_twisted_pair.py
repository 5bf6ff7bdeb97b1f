"""The main job (``examples/twisted_pair.py``: two 1 m steel wires, 500 N, mu = 0.3) at a reduced
size, against the two-ply's closed forms (docs/theory_twoply.md) and the material range."""
import warnings

import numpy as np
import pytest


import twisted_pair

KW = dict(turns=1.0, steps=4, n_elements=16, mu=0.3, check_stability=False)
R, L, PULL = 0.5e-3, 1.0, 500.0
PHI = 2 * np.pi * KW["turns"]


@pytest.fixture(scope="module")
def runs():
    with warnings.catch_warnings():
        warnings.simplefilter("error")             # in range: no MaterialRangeWarning (nor any other)
        base = twisted_pair.main(**KW)
    swapped = twisted_pair.main(swap=True, **KW)
    return base, swapped


def test_closed_form_by_hand():
    """Small angle: sin(theta) = R Phi / L; torque (2 C + T R^2) Phi / L; shortening L theta^2 / 2."""
    cf = twisted_pair.closed_form(PHI)
    C = 200e9 / 2.6 * np.pi * R**4 / 2
    assert cf["torque_small"] == pytest.approx((2 * C + PULL * R**2) * PHI / L, rel=1e-12)
    assert cf["torque"] == pytest.approx(cf["torque_small"], rel=2e-4)            # theta = 0.18 deg
    assert np.sin(cf["ply_angle"]) == pytest.approx(R * PHI / L, rel=2e-3)       # stretch 1.6e-3
    assert cf["shortening"] == pytest.approx(L * cf["ply_angle"] ** 2 / 2, rel=1e-5)


def test_torque_and_shortening_match_the_closed_form(runs):
    """16 elements: torque within 1e-3 of the helix (it converges to 1e-4,
    benchmarks/twisted_pair_closed_form.py), shortening within 6 %, at every step."""
    (sol, rows, _), _ = runs
    assert sol.times[-1] == pytest.approx(1.0)
    for tw, torque, closed, axial, dz, *_ in rows[1:]:
        assert torque == pytest.approx(closed, rel=1e-3)
        assert axial == pytest.approx(PULL, rel=1e-9)                 # the clamps carry the pull
        cf = twisted_pair.closed_form(2 * np.pi * tw)
        assert dz * 1e-6 == pytest.approx(cf["shortening"], rel=0.06)
        assert dz * 1e-6 > cf["shortening"]                           # the clamped ends steepen the helix


def test_wires_touch_along_the_whole_length(runs):
    (sol, _, _), _ = runs
    c = sol.contact(-1)
    active = c["normal_force"] > 0
    assert active.sum() >= 30
    assert np.all(c["gap"][active] < 2e-3 * R) and np.all(c["gap"][active] > -2e-2 * R)
    z = c["position"][active, 2]
    assert z.min() < 0.1 * L and z.max() > 0.9 * L


def test_friction_acts_within_the_coulomb_cone(runs):
    """The law's cone: with exact stick (mortar) that of the nodal tractions, which the complementarity
    functions hold to Newton's tolerance (``|C_g| m_g <= rtol F``, ``F`` the force scale, at least the pull);
    the tractions interpolated to the Gauss points may leave it near the ends of the contact zone.  With the
    penalty stick, every Gauss point's traction, to round-off (its return mapping is pointwise)."""
    (sol, _, _), _ = runs
    if sol.extra.get("mortar_status"):
        st = sol.extra["mortar_status"][-1]
        ft = np.linalg.norm(sol.extra["mortar_tangential_force"][-1], axis=1)[st > 0]
        fn = sol.extra["mortar_normal_force"][-1][st > 0]
        slip = st[st > 0] == 2
        tol = 1e-8 * PULL                                                # Newton's rtol on the force scale
        assert ft.max() > 0.1 * 0.3 * fn.max() and slip.any()
        assert np.all(ft <= 0.3 * fn + tol)
        np.testing.assert_allclose(ft[slip], 0.3 * fn[slip], rtol=0, atol=tol)
        return
    c = sol.contact(-1)
    active = c["normal_force"] > 0
    ft = np.linalg.norm(c["tangential_force"], axis=1)[active]
    fn = c["normal_force"][active]
    assert ft.max() > 0.1 * 0.3 * fn.max()                            # friction is on
    assert np.all(ft <= 0.3 * fn * (1 + 1e-9))                         # Coulomb cone
    slipping = ~c["stick"][active]
    np.testing.assert_allclose(ft[slipping], 0.3 * fn[slipping], rtol=1e-9)


def test_strains_stay_in_the_elastic_range(runs):
    """Largest von Mises surface stress: the helix's closed form (axial 318 MPa, shear G R kappa_t)
    within 2 %, below the grade-1770 yield stress (1416 MPa); step 0 is the pull alone."""
    (sol, _, _), _ = runs
    sec = sol.description
    assert sec["beam_yield_stress"][0] == pytest.approx(0.8 * 1770e6)
    u0 = sol.utilisation(0).reshape(2, -1)
    u_pull = PULL / 2 / (np.pi * R**2) / 1416e6
    np.testing.assert_allclose(u0[:, 6:10], u_pull, rtol=1e-6)        # mid-length: the pull alone
    np.testing.assert_allclose(u0, u_pull, rtol=3e-4)                 # ends: the touching wires bow apart
    vm = sol.equivalent_strain(-1).max() * 200e9
    assert vm == pytest.approx(twisted_pair.closed_form(PHI)["von_mises"], rel=0.02)
    assert sol.utilisation(-1).max() < 1 and sol.stats[-1]["utilisation"] == sol.utilisation(-1).max()


def test_slave_master_symmetry(runs):
    """The two wires are mirror images: swapping slave and master gives the same answer (1e-14)."""
    (_, rows, _), (_, rows_s, _) = runs
    assert rows_s[-1][1] == pytest.approx(rows[-1][1], rel=1e-9)
    assert rows_s[-1][4] == pytest.approx(rows[-1][4], rel=1e-9)


@pytest.mark.slow
def test_halved_steps_agree(runs):
    """4 steps of a quarter turn are cut (``motion_path``, cut-backs; the steps then regrow,
    ``stepping.steady``); 16 steps take the user's size: the path's friction history changes
    torque and shortening by 4e-6 and 4e-5."""
    (sol, rows, _), _ = runs
    sol_h, rows_h, _ = twisted_pair.main(**dict(KW, steps=16))
    assert sol.times[-1] == sol_h.times[-1] == 1.0 and len(sol_h.times) == 17
    assert rows_h[-1][1] == pytest.approx(rows[-1][1], rel=2e-5)
    assert rows_h[-1][4] == pytest.approx(rows[-1][4], rel=2e-4)


def test_friction_changes_the_answer_only_slightly(runs):
    """Torsion of the wires dominates the torque: frictional and frictionless runs differ by
    well under 1e-3, but they differ."""
    (_, rows, _), _ = runs
    _, rows_0, _ = twisted_pair.main(**dict(KW, mu=0.0))
    assert rows_0[-1][1] == pytest.approx(rows[-1][1], rel=1e-3)
    assert rows_0[-1][1] != rows[-1][1]


def test_pair_is_stable_far_below_greenhill_under_tension(runs):
    """The frictionless twin's tangent is positive definite at every step; the torque is a few
    per cent of 2 sqrt(T B) (B = 2 E I)."""
    (sol, rows, _), _ = runs
    model, _, _ = twisted_pair.build(turns=KW["turns"], n_elements=KW["n_elements"], mu=0.0)
    lowest = twisted_pair.lowest_eigenvalues(model, sol)
    assert np.all(lowest > 0)
    B = 2 * 200e9 * np.pi * R**4 / 4
    assert rows[-1][1] < 0.05 * 2 * np.sqrt(PULL * B)


def test_refinement_approaches_the_closed_form():
    """Frictionless, 16 -> 32 elements: the errors of the ply angle and the shortening more than
    halve and the torque's falls below 3e-4 (docs/benchmarks.md, twisted pair closed form)."""
    err = []
    for n in (16, 32):
        model, plate, beams = twisted_pair.build(n_elements=n, turns=1.0, mu=0.0)
        sol = twisted_pair.bs.solve(model, steps=4, verbose=False)
        cf = twisted_pair.closed_form(PHI)
        dz = sol.position(plate, 0)[2] - sol.position(plate, -1)[2]
        theta = np.mean([twisted_pair.ply_angle(sol, b) for b in beams])
        err.append((sol.reaction(plate, -1)[5] / cf["torque"] - 1, theta / cf["ply_angle"] - 1,
                    dz / cf["shortening"] - 1))
    (t16, a16, s16), (t32, a32, s32) = err
    assert abs(t32) < 3e-4 and abs(a32) < 0.5 * abs(a16) and abs(s32) < 0.5 * abs(s16), err
