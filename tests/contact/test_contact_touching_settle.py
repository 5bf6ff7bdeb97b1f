"""A touching start moved by contact alone settles without exact stick's friction (issue 30, session 11).

A strand built with its layers touching (``build_strand(fit_core=True)``) is pushed at t_start by the smoothed normal
law alone (its force at zero gap): nothing else acts there, and step 0 is that law's settling, a motion of the order
of its smoothing width.  Exact stick's friction has no slip before t_start, so the settling is solved without it and
friction starts from zero traction at the state found -- what the solve fell back to after a failed attempt with
friction (the attempt cycles: every sliding group's traction reverses at every iteration, the residual stays near 0.07;
docs/benchmarks.md, "Step 0 of touching strands, session 11").  No warning: it is the rule, not a failure.
"""
import numpy as np

import beamsolver as bs


def _strand(n_layers, elements_per_lay=12):
    L = bs.cables.Layer
    r, lay = 1e-3, 0.1
    st = bs.cables.build_strand([L(r)] + [L(r, 6 * k, lay_length=lay) for k in range(1, n_layers + 1)], lay, E=2e11,
                                elements_per_lay=elements_per_lay, mu=0.3, contact_options=dict(stick="exact"),
                                fit_core=True, touch_tol=-0.5)
    st.clamp("bottom")
    for w in st.all_wires:
        st.model.prescribe(w.last, bs.motion.translation(lambda t: (0.0, 0.0, 1e-4 * st.length * t)))
    return st


def test_a_touching_strand_s_step_zero_settles_without_a_failed_attempt_with_friction():
    """1+6+12 wires, 12 elements a lay: step 0 in the frictionless settling's iterations (it took 14 with friction,
    given up, then 7 without it, and a warning), and the stretched step converges with friction as before."""
    st = _strand(2)
    calls = []
    sol = bs.solve(st.model, steps=1, callback=lambda d: calls.append(d["t"]))
    assert sol.converged
    s0 = sol.stats[0]
    assert not s0.get("warnings"), s0.get("warnings")
    assert s0["iterations"] <= 8
    assert sum(1 for t in calls if t == 0.0) <= 8          # no iterations spent on a failed attempt
    assert sol.stats[-1]["iterations"] <= 5
    c = sol.contact()
    pressed = c["normal_force"] > 0
    assert pressed.sum() > 100 and c["stick"][pressed].any()


def test_a_touching_strand_of_seven_wires_settles_in_the_frictionless_iterations():
    """1+6 wires: step 0 converged with friction, in 7 iterations and two augmented-Lagrangian re-solves (13); now
    the settling's 7, the same with friction off altogether at step 0."""
    st = _strand(1)
    sol = bs.solve(st.model, steps=1)
    assert sol.converged and not sol.stats[0].get("warnings")
    assert sol.stats[0]["iterations"] <= 8
    assert sol.stats[0].get("augmentations", 0) == 0
    assert np.isfinite(sol.poses[-1]).all()
