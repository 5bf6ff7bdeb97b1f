"""The contact-law interface of the compiled kernel (contact/law.py ``ContactLaw``, ``kernel_jit.make_kernel``).

The default law's scalar compiled forms equal the numpy forms the complex-step oracle
uses (values and derivatives); a new normal law (linear then stiffening, defined here)
plugs into the kernel without editing it, gives its own normal traction and a tangent
that matches central finite differences of the kernel's forces.
"""

import numpy as np
import pytest

from beamsolver import se3
from beamsolver._jit import jit
from beamsolver.contact import kernel_jit
from beamsolver.contact.law import (PENALTY_COULOMB, ContactLaw, coulomb, coulomb_return_mapping, normal_force,
                                    penalty_normal)

from helpers import crossing_at_nodes, kernel_scene as _scene

STIFFENING = 0.05     # length over which the stiffening law doubles its stiffness


@jit
def stiffening_normal(gap, penalty, multiplier, smoothing):
    """``lam = penalty x (1 + x / STIFFENING)``, ``x = multiplier / penalty - gap`` > 0 (a test law)."""
    x = multiplier / penalty - gap
    if x >= 0.0:
        return penalty * x * (1.0 + x / STIFFENING), -penalty * (1.0 + 2.0 * x / STIFFENING), True
    return 0.0, 0.0, False


STIFF = ContactLaw("stiffening_test", stiffening_normal, coulomb)


@pytest.mark.parametrize("smoothing, multiplier", [(0.0, 0.0), (0.0, 3.0), (0.02, 0.0), (0.02, 3.0)])
def test_compiled_normal_law_equals_the_numpy_law(smoothing, multiplier):
    gaps = np.linspace(-0.1, 0.1, 401)
    lam0, act0 = normal_force(gaps, 100.0, multiplier, smoothing)
    dlam0 = np.imag(normal_force(gaps + 1e-30j, 100.0, multiplier, smoothing)[0]) / 1e-30
    got = np.array([penalty_normal(g, 100.0, multiplier, smoothing) for g in gaps])
    np.testing.assert_allclose(got[:, 0], lam0, rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(got[:, 1], dlam0, rtol=1e-14, atol=1e-14)
    inside = np.abs(multiplier - 100.0 * gaps + 100.0 * smoothing) > 1e-9      # off the switch itself
    np.testing.assert_array_equal(got[inside, 2].astype(bool), act0[inside])


def test_compiled_coulomb_law_equals_the_numpy_return_mapping():
    rng = np.random.default_rng(3)
    seed = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]), np.array([0.0, 0.0, 1.0])   # d/d(trial0, trial1, lam)
    for trial, lam in zip(rng.normal(size=(50, 2)), rng.uniform(0.0, 5.0, 50)):
        lt0, lt1, D, stick = coulomb(trial[0], trial[1], seed[0], 0.3, lam, seed[1])
        lt, stick0 = coulomb_return_mapping(trial, 0.3, lam)
        np.testing.assert_allclose([lt0, lt1], lt, rtol=1e-14)
        assert stick == stick0
        for j in range(2):        # d lt / d trial_j and d lt / d lam by complex step
            d = np.imag(coulomb_return_mapping(trial + 1e-30j * np.eye(2)[j], 0.3, lam)[0]) / 1e-30
            np.testing.assert_allclose(D[:, j], d, rtol=1e-12, atol=1e-14)
        d = np.imag(coulomb_return_mapping(trial + 0j, 0.3, lam + 1e-30j)[0]) / 1e-30
        np.testing.assert_allclose(D[:, 2], d, rtol=1e-12, atol=1e-14)


def _fd_tangent(X, p, friction, law, eps=1e-6):
    """Central differences of the kernel's wrenches for body increments ``exp(eps e_k)`` of each node."""
    P = len(X)
    K = np.empty((P, 24, 24))
    for j in range(4):
        for k in range(6):
            step = np.zeros(6)
            step[k] = eps
            Xp, Xm = X.copy(), X.copy()
            Xp[:, j] = X[:, j] @ se3.exp(step)
            Xm[:, j] = X[:, j] @ se3.exp(-step)
            fp = kernel_jit.kernel_and_tangent(Xp, p, friction, law)[0].reshape(P, 24)
            fm = kernel_jit.kernel_and_tangent(Xm, p, friction, law)[0].reshape(P, 24)
            K[:, :, 6 * j + k] = (fp - fm) / (2 * eps)
    return K


@pytest.mark.slow
@pytest.mark.parametrize("friction", [False, True])
def test_a_new_normal_law_plugs_in_without_kernel_edits_with_an_fd_correct_tangent(friction):
    X, p = _scene(7, friction, 0.0, 0.0, True, 0.5)
    p["penalty_t"] = np.full(len(X), 50.0)             # a stick-slip mix away from the law's switches
    f, K, out = kernel_jit.kernel_and_tangent(X, p, friction, law=STIFF)
    on = out["active"]
    assert on.sum() >= 4
    x = -out["gap"][on]
    np.testing.assert_allclose(out["lam_n"][on], 100.0 * x * (1.0 + x / STIFFENING), rtol=1e-12)
    f0, _, out0 = kernel_jit.kernel_and_tangent(X, p, friction)           # the default law differs
    np.testing.assert_allclose(out0["lam_n"][on], 100.0 * x, rtol=1e-12)
    assert not np.allclose(f0, f)
    Kfd = _fd_tangent(X, p, friction, STIFF)
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max()


def test_the_default_law_kernel_is_the_module_kernel():
    assert kernel_jit.make_kernel(PENALTY_COULOMB) is kernel_jit.evaluate
    assert kernel_jit.make_kernel(STIFF) is kernel_jit.make_kernel(ContactLaw("stiffening_test", stiffening_normal,
                                                                              coulomb))


def _crossing(law):
    m, _, _, sec = crossing_at_nodes(**({} if law is None else dict(law=law)))
    return m, sec


@pytest.mark.parametrize("law", [None, STIFF])
def test_a_declared_law_is_the_one_the_solve_obeys(law):
    import beamsolver as bs
    from beamsolver.contact.law import default_penalty
    m, sec = _crossing(law)
    sol = bs.solve(m, steps=2, verbose=False)
    c = sol.contact()
    on = c["normal_force"] > 0
    assert on.sum() == 1
    lam, x, pen = c["normal_force"][on] / c["weight"][on], -c["gap"][on], default_penalty(sec, sec)
    expected = pen * x if law is None else pen * x * (1.0 + x / STIFFENING)
    np.testing.assert_allclose(lam, expected, rtol=1e-9)
    np.testing.assert_allclose(c["normal_force"].sum(), 25.0, rtol=0.02)     # half the load, as with any law


def test_a_law_that_is_not_a_contact_law_is_refused_naming_it():
    import beamsolver as bs
    with pytest.raises(bs.InputError, match="law must be .*ContactLaw.*'hertz'"):
        _crossing("hertz")
