"""Shear lag with Coulomb friction: a wire on a rigid rod under a normal line load, pulled at one end.

The rod (master) lies along ``e_x`` with every node clamped (a rigid support);
the wire (slave) lies on it, pressed by a uniform dead line load ``q`` (force
per length, towards the rod, as consistent nodal loads ``q L_e / 2`` per
element end).  Then a dead force ``F`` pulls the wire's last node along
``e_x``.  With a rigid rod, Coulomb friction and ``F < mu q L``, the slip zone
grows from the pulled end over ``a = F / (mu q)``: there the axial force falls
linearly, ``N(x) = mu q (x - (L - a))``, and the rest of the wire sticks and
carries nothing.

Run ``python examples/shear_lag.py`` to print the slip-zone length and the axial
force profile beside the closed form.
"""
import numpy as np

import beamsolver as bs

solve_options = dict(steps=4)


def build(n_wire=20, n_rod=13, L=1.0, r=0.01, E=1e9, q=100.0, F=15.0, mu=0.3, **contact_options):
    """Model, wire and rod; the line load ``q`` ramps over ``0 <= t <= 0.5``, the pull ``F``
    over ``0.5 <= t <= 1``.  Degrees of freedom out of the ``x-z`` plane are fixed."""
    model = bs.Model()
    sec = bs.Section.circular(radius=r, E=E, nu=0.3)
    rod = model.add_beam(bs.geometry.straight((-0.05 * L, 0, 0), (1.05 * L, 0, 0), n_rod), sec)
    wire = model.add_beam(bs.geometry.straight((0, 0, 2 * r), (L, 0, 2 * r), n_wire), sec)
    for node in rod.nodes:
        model.clamp(node)
    for node in wire.nodes:
        model.fix(node, dofs=("uy", "rx", "rz"))
    le = L / n_wire
    for k, node in enumerate(wire.nodes):
        share = 0.5 if k in (0, n_wire) else 1.0
        model.add_load(node, force=(0, 0, -q * le * share), scale=lambda t: min(2.0 * t, 1.0))
    model.add_load(wire.last, force=(F, 0, 0), scale=lambda t: max(2.0 * t - 1.0, 0.0))
    model.add_contact(wire, rod, mu=mu, **contact_options)
    return model, wire, rod


def axial_force(sol, wire, step=-1):
    """Element midpoints ``x`` (reference) and axial forces ``N`` of the wire at ``step``."""
    x = np.linspace(0, 1, len(wire.elements) + 1)
    mid = 0.5 * (x[1:] + x[:-1])
    return mid, sol.section_forces[step][wire.elements, 0]


def slip_zone(sol, wire, L=1.0, step=-1):
    """Length of the zone of slipping contact points that reaches the pulled end (from the stick flags:
    the points from the pulled end up to the first sticking one; a point slipping elsewhere, e.g. at the
    free end under the pressing phase's self-equilibrated forces, is not part of it)."""
    c = sol.contact(step)
    on = c["normal_force"] > 0
    x, slipping = c["position"][on, 0], ~c["stick"][on]
    order = np.argsort(-x)
    held = np.flatnonzero(~slipping[order])
    if not slipping.any():
        return 0.0
    reach = order if not len(held) else order[:held[0]]
    return L - x[reach].min() if len(reach) else 0.0


def main(steps=4, **kw):
    model, wire, rod = build(**kw)
    sol = bs.solve(model, steps=steps)
    q, F, mu = kw.get("q", 100.0), kw.get("F", 15.0), kw.get("mu", 0.3)
    a = F / (mu * q)
    return sol, wire, a


if __name__ == "__main__":
    for n in (10, 20):
        sol, wire, a = main(n_wire=n)
        x, N = axial_force(sol, wire)
        exact = np.maximum(0.3 * 100.0 * (x - (1.0 - a)), 0.0)
        print(f"n_wire {n}: slip zone {slip_zone(sol, wire):.4f} (closed form {a:.4f}); "
              f"max |N - N_exact| {np.abs(N - exact).max():.4g} N of F = 15 N; "
              f"iterations {int(np.sum(sol.iterations))}")
