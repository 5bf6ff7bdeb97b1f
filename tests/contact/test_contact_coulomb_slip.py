"""The compiled Coulomb law's slip branch (``law.coulomb``) written without temporaries per point
(issue 14): bit-identical to the array form it replaced, kept here as the reference."""
import numpy as np

from beamsolver.contact.law import coulomb


def _array_form(trial0, trial1, Dtrial, mu, lam, Dlam):
    """``law.coulomb`` before: ``tt``, ``proj`` and two outer products allocated per point."""
    norm = np.sqrt(trial0 * trial0 + trial1 * trial1)
    limit = mu * lam
    if norm <= limit:
        return trial0, trial1, Dtrial, True
    tt = np.array([trial0 / norm, trial1 / norm])
    proj = tt[0] * Dtrial[0] + tt[1] * Dtrial[1]
    D = np.outer(tt, mu * Dlam) + (limit / norm) * (Dtrial - np.outer(tt, proj))
    return limit * tt[0], limit * tt[1], D, False


def test_slip_branch_is_bit_identical_to_the_array_form():
    rng = np.random.default_rng(14)
    n_slip = 0
    for _ in range(400):
        trial = rng.normal(size=2) * 10.0 ** rng.uniform(-6, 6)
        lam = rng.uniform(0.0, 2.0) * np.hypot(*trial)
        Dtrial, Dlam = rng.normal(size=(2, 24)), rng.normal(size=24)
        mu = rng.uniform(0.05, 1.0)
        got = coulomb(trial[0], trial[1], Dtrial, mu, lam, Dlam)
        want = _array_form(trial[0], trial[1], Dtrial, mu, lam, Dlam)
        assert got[0] == want[0] and got[1] == want[1] and got[3] == want[3]
        np.testing.assert_array_equal(got[2], want[2])
        n_slip += not want[3]
    assert 100 < n_slip < 390          # both branches were exercised
