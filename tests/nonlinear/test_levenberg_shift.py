"""Exact stick's Levenberg shift after backtracked line searches (``newton.LM_SHIFT``, ``LM_AFTER``, ``LM_FAR``;
``Problem.levenberg``): the direction's tangent gets ``LM_SHIFT |diag K|`` on its diagonal; the residual and the
convergence test are unchanged, so the answer is too."""
import contextlib
import io

import numpy as np
import pytest
import scipy.sparse as sp

from beamsolver.nonlinear import augmented, newton
from beamsolver.nonlinear.problem import Problem


def test_shifted_adds_the_diagonals_magnitudes_on_the_same_pattern():
    K = sp.csc_matrix(np.array([[4.0, 1.0, 0.0], [1.0, -2.0, 3.0], [0.0, 3.0, 5.0]]))
    p = Problem.__new__(Problem)
    p.shift = 0.0
    assert p.levenberg(K) is K
    p.shift = 0.5
    S = p.levenberg(K)
    assert np.allclose(S.diagonal(), [6.0, -1.0, 7.5])
    assert np.array_equal(S.indptr, K.indptr) and np.array_equal(S.indices, K.indices)
    assert np.allclose((S - K).toarray(), np.diag([2.0, 1.0, 2.5]))
    assert np.allclose(K.diagonal(), [4.0, -2.0, 5.0])          # the tangent itself is left as it was


def _three_wires():
    import three_wires
    with contextlib.redirect_stdout(io.StringIO()):
        sol = three_wires.main(stick="exact", n_elements=12, turns=0.125, steps=1)[0]
    return sol


@pytest.mark.slow
def test_the_shift_changes_the_iterations_not_the_answer(monkeypatch):
    """Three wires twisted an eighth of a turn (exact stick, the augmented path forced at this size; both runs on the
    same steps, t = 0.5 and 1): with the shift taken after every backtracked iteration (39 times; 55 iterations
    against 44) the run converges to the poses and reactions of the run without it, to the Newton tolerance
    (measured 8e-16 m, 9e-10 of the largest reaction)."""
    monkeypatch.setattr(augmented, "MIN_UNKNOWNS", 0)
    monkeypatch.setattr(newton, "LM_SHIFT", 0.0)
    plain = _three_wires()
    used = []
    shifted = Problem.levenberg
    monkeypatch.setattr(Problem, "levenberg", lambda self, K: used.append(self.shift) or shifted(self, K))
    monkeypatch.setattr(newton, "LM_SHIFT", 1e-3)
    monkeypatch.setattr(newton, "LM_AFTER", 1)
    monkeypatch.setattr(newton, "LM_FAR", False)
    sol = _three_wires()
    assert sol.converged and plain.converged and any(s > 0 for s in used)
    assert np.array_equal(sol.times, plain.times)
    assert np.abs(sol.poses[-1][:, :3, 3] - plain.poses[-1][:, :3, 3]).max() < 1e-12
    R = np.abs(plain.reactions[-1]).max()
    assert np.abs(sol.reactions[-1] - plain.reactions[-1]).max() < 1e-7 * R
