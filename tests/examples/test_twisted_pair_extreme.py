"""The 20 mm pair (``examples/twisted_pair_extreme.py``, the main job until issue 32): its
stability analysis against Greenhill's torque, a mathematical benchmark (strains far beyond any
material's range)."""

import numpy as np


import twisted_pair_extreme as twisted_pair

R = 0.5e-3


def test_pair_loses_stability_at_the_greenhill_torque():
    """Frictionless pair twisted by 2 turns: the lowest eigenvalue of the tangent changes sign
    near Greenhill's clamped-clamped limit M_c = 8.99 B / L (B = 2 E I, small pull), between two
    converged steps; interpolated, at M L / B = 8.2-8.4, some 7 % below it (examples/twisted_pair_extreme.py; one wire
    alone gives 8.99, benchmarks/twisted_pair_stability.py).  The torques of the two steps
    around the crossing depend on the step sizes (steps regrown after a cut-back bracket it by
    0.91-0.95 M_c, the user's steps by 0.91-0.99 M_c): the interpolated torque is the measure."""
    model, plate, _ = twisted_pair.build(turns=2.0, n_elements=8, mu=0.0)
    sol = twisted_pair.bs.solve(model, steps=8)
    first, lowest = twisted_pair.stability(model, sol, 2.0)
    assert first is not None and lowest < 0
    k = int(np.argmin(np.abs(2.0 * np.asarray(sol.times) - first)))
    torque = [sol.reaction(plate, j)[5] for j in (k - 1, k)]
    B = 2 * 200e9 * np.pi * R**4 / 4
    Mc = 8.99 * B / 0.02
    _, M = twisted_pair.crossing(model, sol, plate, 2.0)
    assert torque[0] <= M <= torque[1] and torque[0] < Mc * 1.03, (torque, M, Mc)
    assert 0.90 * Mc < M < 0.95 * Mc, (M, Mc)
