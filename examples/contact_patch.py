"""Contact patch test: two parallel straight beams with non-matching meshes pressed together.

The master (``n_master`` elements) and the slave (``n_slave`` elements) lie along
``e_x`` over the same length ``L``, touching.  A uniform line load ``q`` presses
the slave onto the master and the opposite load holds the master (``add_line_load``:
integrated by the elements like the contact pressure, with the end moments
``q L_e^2 / 12`` of the SE(3) interpolation), ramped over ``0 <= t <= 0.5``; then
a uniform axial line load ``tau`` pulls the slave along ``+e_x`` and the master
along ``-e_x`` (``0.5 <= t <= 1``), with the moment ``r tau`` per length of a
traction acting at the contact line, a radius off the centre line.  The master's
first node is held in ``x`` and its middle node in ``z`` and in rotation about ``y``
(no rigid mode); the loads balance through the contact alone.  Without friction
(``mu = 0``) the slave's middle node is held in ``x`` too.

Closed form: uniform contact pressure ``q`` along the overlap, both beams
straight; with ``tau < mu q`` the whole overlap sticks with the uniform traction
``tau``, neither beam strains and nothing slips (``stick="exact"``; the penalty
stick slips elastically by the same amount everywhere).

The Gauss points of ``integration="points"`` (fixed per slave element) integrate
the master's shape functions, kinked inside the slave elements, inexactly: the
pressure spreads by about 0.1 q on the 7 / 10 meshes.  ``integration="segments"``
passes the test to round-off (``tests/contact/test_contact_patch.py``).

Run ``python examples/contact_patch.py`` to print the pressure and traction
spreads of both integrations.
"""
import numpy as np

import beamsolver as bs

solve_options = dict(steps=4, check_rigid_modes=False)    # the slave beam is held by contact alone


def build(n_slave=7, n_master=10, L=1.0, r=0.01, E=1e9, q=100.0, tau=15.0, mu=0.3, **contact_options):
    """Model, slave and master (degrees of freedom out of the ``x-z`` plane fixed)."""
    model = bs.Model()
    sec = bs.Section.circular(radius=r, E=E, nu=0.3)
    master = model.add_beam(bs.geometry.straight((0, 0, 0), (L, 0, 0), n_master), sec)
    slave = model.add_beam(bs.geometry.straight((0, 0, 2 * r), (L, 0, 2 * r), n_slave), sec)
    for beam in (master, slave):
        for node in beam.nodes:
            model.fix(node, dofs=("uy", "rx", "rz"))
    model.fix(master.first, dofs=("ux", "uy", "rx", "rz"))
    model.fix(master.nodes[n_master // 2], dofs=("uy", "uz", "rx", "ry", "rz"))
    if mu == 0.0:
        model.fix(slave.nodes[n_slave // 2], dofs=("ux",))
    press = lambda t: min(2.0 * t, 1.0)      # noqa: E731
    pull = lambda t: max(2.0 * t - 1.0, 0.0)     # noqa: E731
    for beam, sign in ((slave, -1.0), (master, 1.0)):
        model.add_line_load(beam, force_per_length=(0, 0, sign * q), scale=press)
        # the traction acts at the contact line, a radius off the centre line: its moment per length with it
        model.add_line_load(beam, force_per_length=(-sign * tau, 0, 0), moment_per_length=(0, -r * tau, 0),
                            scale=pull)
    model.add_contact(slave, master, mu=mu, **contact_options)
    return model, slave, master


def tractions(sol, step=-1):
    """Normal and axial tangential tractions (force per length) of the active contact points."""
    c = sol.contact(step)
    on = c["normal_force"] > 0
    w = c["weight"][on]
    return c["normal_force"][on] / w, c["tangential_force"][on, 0] / w, c["stick"][on]


def relative_slip(sol, slave, master, L=1.0, step=-1):
    """Largest change of the axial distance between slave and master material points (slip)."""
    xs = sol.displacement(step)[slave.nodes, 0]
    xm = sol.displacement(step)[master.nodes, 0]
    s = np.linspace(0, L, len(slave.nodes))
    return np.abs(xs - np.interp(s, np.linspace(0, L, len(master.nodes)), xm)).max()


def straightness(sol, beam, step=-1):
    """Largest transverse (``z``) deflection of ``beam`` from the straight line through its end nodes."""
    z = sol.displacement(step)[beam.nodes, 2]
    s = np.linspace(0.0, 1.0, len(z))
    return np.abs(z - (z[0] + s * (z[-1] - z[0]))).max()


def main(steps=4, **kw):
    model, slave, master = build(**kw)
    return bs.solve(model, steps=steps, check_rigid_modes=False), slave, master


if __name__ == "__main__":
    for integration in ("points", "segments"):
        for stick in ("penalty", "exact"):
            sol, slave, master = main(integration=integration, stick=stick)
            p, t, stick_ = tractions(sol)
            print(f"{integration:8s} {stick:7s}: pressure {p.mean():.6g} (q = 100), spread (max - min) / q "
                  f"{np.ptp(p) / 100:.3g}; traction spread / tau {np.ptp(t) / 15:.3g}; all stick {stick_.all()}; "
                  f"largest slip {relative_slip(sol, slave, master):.3g} m; "
                  f"iterations {int(np.sum(sol.iterations))}")
