"""Argyris' right-angle frame past its lateral buckling load, with an imperfection (issue 31).

Argyris et al. (1979), Simo & Vu-Quoc (1986): the frame buckles sideways at F_cr = 1.088 N.  With
an out-of-plane imperfection of 1e-4 F, force control to 1.15 N in 23 steps (10 elements a leg)
follows the stable buckled path (tip 36.8 mm out of plane; test_buckling checks the perfect
frame's switch against it at 1.5 N).  On 07a7d6e it took 246 steps and 1986 Newton iterations
(the undamped fallback ran into the residual line search), fewer than 230 before; with
``line_search=False`` it ended on the unstable side (w_tip = -0.079 mm) without a word.
"""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver.nonlinear.definiteness import negative_eigenvalues
from scenes import argyris_frame


@pytest.mark.parametrize("line_search", [True, False])
def test_imperfect_frame_follows_the_stable_buckled_path(line_search):
    m, b = argyris_frame(1.15)
    sol = bs.solve(m, steps=23, verbose=False, line_search=line_search)
    assert sol.times[-1] == 1.0 and sol.message == ""
    assert sol.position(b.last)[2] == pytest.approx(36.82, abs=0.01)
    assert negative_eigenvalues(bs.linearize(m, sol, -1).K)[0] == 0
    assert sol.n_steps < 60 and int(np.sum(sol.iterations)) < 350       # 40 / 239 and 44 / 230
