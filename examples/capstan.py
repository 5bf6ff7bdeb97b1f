"""Capstan (Euler-Eytelwein): a flexible rope wrapped around a stiff post, pulled until it slides.

Material: the rope is given by its stiffnesses (``EA``, ``EI``: a flexible fibre rope), the post
is stiff (``E = 1 GPa``); no yield limit.  The largest equivalent surface strain, 0.0096
(printed), is within a synthetic fibre rope's elastic range (a few per cent).

The post is a clamped beam along ``e_z``; the rope lies in the plane ``z = 0``,
wrapped over the angle ``theta`` around the post, with straight tangent
segments at both ends.  Phase 1 (``0 <= t <= t_hold``): a dead force ``T_hold``
ramps up at the held end while the pulled end is clamped.  Phase 2
(``t_hold <= t <= 1``): the pulled end moves away along its tangent by ``pull``,
the rope slides over the post, and the pulling force is
``T_pull = T_hold exp(mu theta)`` (bending stiffness small).

Run ``python examples/capstan.py`` to print the computed ratio beside
``exp(mu theta)``.
"""
import numpy as np

import beamsolver as bs


def rope_path(radius, theta, straight, n_arc, n_straight):
    """Node positions and tangents: straight, arc of ``theta`` about ``e_z``, straight."""
    phi = np.linspace(-0.5 * theta, 0.5 * theta, n_arc + 1)
    arc_x = radius * np.stack([np.cos(phi), np.sin(phi), 0 * phi], axis=1)
    arc_t = np.stack([-np.sin(phi), np.cos(phi), 0 * phi], axis=1)
    s = np.linspace(straight, 0.0, n_straight + 1)[:-1]
    x_in = arc_x[0] - s[:, None] * arc_t[0]
    x_out = arc_x[-1] + s[::-1][:, None] * arc_t[-1]
    x = np.concatenate([x_in, arc_x, x_out])
    t = np.concatenate([np.repeat(arc_t[:1], len(s), 0), arc_t, np.repeat(arc_t[-1:], len(s), 0)])
    return x, t


solve_options = dict(steps=8)       # for `beamsolver run examples/capstan.py`


def build(mu=0.3, theta=np.pi, T_hold=10.0, pull=0.005, n_arc=24, n_straight=None, straight=0.03,
          post_radius=0.05, rope_radius=5e-4, EA=1e5, EI=1e-5, penalty=3e8, penalty_t=1e6,
          t_hold=0.25, **contact_options):
    """Model, rope, post and the pulled end's outward tangent.

    The dead force ramps up over ``0 <= t <= t_hold``; the pulled end then
    moves by ``pull`` until ``t = 1``.  The rope is thin (``rope_radius /
    post_radius = 1 %``): friction acts on the rope's surface, not on its
    centre line, and a thick rope with no bending stiffness obeys
    ``exp(mu theta R_post / (R_post + r))`` instead.
    """
    model = bs.Model()
    post_sec = bs.Section.circular(radius=post_radius, E=1e9)
    GA = EA / 2.6
    rope_sec = bs.Section(EA=EA, GA2=GA, GA3=GA, GJ=EI, EI2=EI, EI3=EI, radius=rope_radius)
    post = model.add_beam(bs.geometry.straight((0, 0, -0.2), (0, 0, 0.2), 9), post_sec)
    model.clamp(post.first)
    model.clamp(post.last)
    rc = post_radius + rope_radius
    if n_straight is None:        # the same element length as on the arc
        n_straight = int(np.ceil(straight * n_arc / (rc * theta)))
    x, t = rope_path(rc, theta, straight, n_arc, n_straight)
    rope = model.add_beam(bs.geometry.frames_from_tangents(x, t, e2=(0, 0, 1)), rope_sec)
    t_in, t_out = t[0], t[-1]
    model.add_load(rope.first, force=-T_hold * t_in, scale=lambda s: min(s / t_hold, 1.0))
    model.prescribe(rope.last, bs.motion.translation(
        lambda s: pull * max(s - t_hold, 0.0) / (1.0 - t_hold) * t_out))
    model.add_contact(rope, post, mu=mu, penalty=penalty, penalty_t=penalty_t, **contact_options)
    return model, rope, post, t_out


def main(mu=0.3, theta=np.pi, n_arc=24, steps=8, T_hold=10.0, verbose=False, **kw):
    """Solve the capstan scene; returns ``(ratio, exp(mu theta), solution)``."""
    model, rope, post, t_out = build(mu=mu, theta=theta, T_hold=T_hold, n_arc=n_arc, **kw)
    sol = bs.solve(model, steps=steps, t_end=1.0, verbose=verbose)
    T_pull = abs(float(np.dot(sol.reaction(rope.last)[:3], t_out)))
    return T_pull / T_hold, float(np.exp(mu * theta)), sol


if __name__ == "__main__":
    for mu in (0.1, 0.3):
        for theta in (0.5 * np.pi, np.pi):
            ratio, exact, sol = main(mu=mu, theta=theta)
            print(f"mu = {mu:.1f}  theta = {theta:.4f}  T_pull/T_hold = {ratio:.5f}  "
                  f"exp(mu theta) = {exact:.5f}  error {100 * (ratio / exact - 1):+.2f} %  "
                  f"Newton iterations {sol.iterations}")
            print(f"  {sol.material_summary()}")
