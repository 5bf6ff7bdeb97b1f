"""Two beams crossing at 90 degrees, pushed together by a force at the crossing.

Material: a contact benchmark in consistent units (``E = 1e7``, no yield limit); its largest
equivalent surface strain is 0.0094 (printed).

The master beam (along ``e_y``) is clamped at both ends; the slave beam (along
``e_x``) lies on it, its ends free to move only along ``e_z``, and a force
``P`` pushes its middle down.  The contact force equals ``P``; with an
augmented-Lagrangian ``tolerance`` the penetration falls below it.

Run ``python examples/crossing_beams.py`` to print both beside the load.
"""
import beamsolver as bs


solve_options = dict(steps=2)       # for `beamsolver run examples/crossing_beams.py`


def build(load=50.0, n_elements=8, tolerance=None, radius=0.05, E=1e7, mu=0.0):
    model = bs.Model()
    sec = bs.Section.circular(radius=radius, E=E, nu=0.3)
    master = model.add_beam(bs.geometry.straight((0, -1, 0), (0, 1, 0), n_elements), sec)
    slave = model.add_beam(bs.geometry.straight((-1, 0, 2 * radius), (1, 0, 2 * radius), n_elements), sec)
    model.clamp(master.first)
    model.clamp(master.last)
    for node in (slave.first, slave.last):
        model.fix(node, ("ux", "uy", "rx", "ry", "rz"))
    model.add_load(slave.nodes[n_elements // 2], force=(0.0, 0.0, -load))
    options = {} if tolerance is None else dict(tolerance=tolerance)
    model.add_contact(slave, master, mu=mu, **options)
    return model, slave, master


def main(load=50.0, n_elements=8, tolerance=None, steps=2):
    """Returns ``(contact force, penetration, solution)``."""
    model, slave, master = build(load=load, n_elements=n_elements, tolerance=tolerance)
    sol = bs.solve(model, steps=steps)
    c = sol.contact()
    return float(c["normal_force"].sum()), float(max(-c["gap"].min(), 0.0)), sol


if __name__ == "__main__":
    for tol in (None, 1e-6):
        f, pen, sol = main(tolerance=tol)
        print(f"tolerance {tol}: contact force {f:.6f} N (load 50 N), penetration {pen:.3e} m, "
              f"Newton iterations per step {sol.iterations[1:].tolist()}")
        print(f"  {sol.material_summary()}")
