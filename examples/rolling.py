"""Rolling without slipping: a beam lying across a perpendicular beam, turned about its own axis.

Material: stiff beams (``E = 1 GPa``, no yield limit); the largest equivalent surface strain
is 4e-5 (printed), within the range of any structural material.

The master beam lies along ``e_y`` (clamped at both ends).  The slave beam lies
across it along ``e_x``, pressed down by dead forces at its ends; both its
ends turn about ``e_x`` by ``theta`` (rotations prescribed, translations
``uy, uz`` free).  With enough friction the slave sticks and rolls along the
master by ``-R theta`` (``R`` its radius) with no tangential force: the SE(3)
slip increment of a rolling contact is ``O(dtheta^3)`` per step.  With
``mu = 0`` it turns in place (one end is then held in ``uy``, the direction
frictionless contact leaves free).

Run ``python examples/rolling.py`` to print the computed distance beside ``R theta``.
"""
import numpy as np

import beamsolver as bs


solve_options = dict(steps=11)      # for `beamsolver run examples/rolling.py`


def build(mu=0.5, theta=1.0, radius=0.05, force=10.0, n_elements=5, E=1e9, t_load=0.1,
          **contact_options):
    """The pressing forces ramp up over ``0 <= t <= t_load``, then the ends turn until ``t = 1``."""
    model = bs.Model()
    sec = bs.Section.circular(radius=radius, E=E, nu=0.3)
    master = model.add_beam(bs.geometry.straight((0, -1, 0), (0, 1, 0), n_elements), sec)
    slave = model.add_beam(bs.geometry.straight((-0.5, 0, 2 * radius), (0.5, 0, 2 * radius), n_elements), sec)
    model.clamp(master.first)
    model.clamp(master.last)
    turn = {"rx": lambda t: theta * max(t - t_load, 0.0) / (1.0 - t_load)}
    held = ("ux", "uy") if mu == 0 else ("ux",)
    model.fix(slave.first, held + ("rx", "ry", "rz"), values=turn)
    model.fix(slave.last, ("rx", "ry", "rz"), values=turn)
    for node in (slave.first, slave.last):
        model.add_load(node, force=(0.0, 0.0, -force), scale=lambda t: min(t / t_load, 1.0))
    model.add_contact(slave, master, mu=mu, **contact_options)
    return model, slave, master


def main(mu=0.5, theta=1.0, steps=11, radius=0.05, n_elements=5, verbose=False):
    """Returns ``(distance rolled, R theta, largest tangential force, solution)``."""
    model, slave, master = build(mu=mu, theta=theta, radius=radius, n_elements=n_elements)
    sol = bs.solve(model, steps=steps, verbose=verbose)
    mid = slave.nodes[len(slave.nodes) // 2]
    y = [sol.position(mid, k)[1] - sol.position(mid, 0)[1] for k in range(len(sol.times))]
    ft = max(np.abs(sol.contact(k)["tangential_force"]).max(initial=0.0) for k in range(1, len(sol.times)))
    return -float(y[-1]), radius * theta, float(ft), sol


if __name__ == "__main__":
    for mu in (0.5, 0.0):
        d, exact, ft, sol = main(mu=mu)
        print(f"mu = {mu}: distance rolled {d:.6e}  (R theta = {exact:.6e}, "
              f"{'rolling' if mu else 'turning in place: 0'})  max tangential force {ft:.2e} N  "
              f"Newton iterations per step {sol.iterations[1:].tolist()}")
        print(f"  {sol.material_summary()}")
