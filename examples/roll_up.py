"""Cantilever roll-up: an end moment ``M = 2 pi EI / L`` bends a straight beam into a full circle.

Material: steel's moduli (``E = 210 GPa``) and no yield limit, on purpose: rolling the beam
into a full circle bends its surface by ``r kappa = 2 pi r / L = 0.063`` (printed), ten times
steel's elastic range; a benchmark of the element's kinematics, not of a material.

The exact solution is a circle of radius ``L / (2 pi)`` through the root, tangent
to the beam axis there; node ``i`` (arc length ``s_i``) sits at
``(rho sin(s_i / rho), rho (1 - cos(s_i / rho)), 0)`` with ``rho = L / (2 pi fraction)``
and its section frame turned by ``s_i / rho`` about ``e_z``.  The SE(3) element
has constant strain, so it reproduces this state exactly on any mesh
(docs/theory.md eqs. 3.8 and 9.1).  The moment is a follower load (it turns with
the tip section), which is what keeps the bending moment uniform.

Run ``python examples/roll_up.py`` to print, for 4, 8 and 16 elements, the
largest distance of any node from the exact circle and from its exact material
position, the tip error, the Newton iterations and the wall time.
"""
import time

import numpy as np

import beamsolver as bs

LENGTH = 1.0
RADIUS = 0.01        # section radius
E = 210e9
NU = 0.3


def exact_poses(n_elements, fraction=1.0, length=LENGTH):
    """Exact node positions ``(n + 1, 3)`` and rotation angles about ``e_z`` ``(n + 1,)``."""
    s = np.linspace(0.0, length, n_elements + 1)
    phi = 2.0 * np.pi * fraction * s / length
    rho = length / (2.0 * np.pi * fraction)
    x = np.stack([rho * np.sin(phi), rho * (1.0 - np.cos(phi)), 0.0 * phi], axis=1)
    return x, phi


solve_options = dict(steps=1)       # for `beamsolver run examples/roll_up.py`


def build(n_elements=8, fraction=1.0, follower=True):
    """Model, beam and the applied moment vector (body components)."""
    section = bs.Section.circular(radius=RADIUS, E=E, nu=NU)
    EI = section.C[5, 5]
    model = bs.Model()
    beam = model.add_beam(bs.geometry.straight((0, 0, 0), (LENGTH, 0, 0), n_elements), section)
    model.clamp(beam.first)
    moment = np.array([0.0, 0.0, fraction * 2.0 * np.pi * EI / LENGTH])
    model.add_load(beam.last, moment=moment, follower=follower)
    return model, beam, moment


def run(n_elements, fraction=1.0, steps=1, **solve_options):
    """Solve and measure; returns a dict of errors (relative to ``L``), iterations and wall time."""
    model, beam, moment = build(n_elements, fraction)
    t0 = time.perf_counter()
    sol = bs.solve(model, steps=steps, **solve_options)
    wall = time.perf_counter() - t0
    x = sol.poses[-1][:, :3, 3]
    x_exact, phi = exact_poses(n_elements, fraction)
    rho = LENGTH / (2.0 * np.pi * fraction)
    centre = np.array([0.0, rho, 0.0])
    R = sol.poses[-1][:, :3, :3]
    angle = np.arctan2(R[:, 1, 0], R[:, 0, 0])
    dphi = (angle - phi + np.pi) % (2.0 * np.pi) - np.pi
    return dict(
        n_elements=n_elements, fraction=fraction, solution=sol, beam=beam, moment=moment,
        circle_error=float(np.abs(np.linalg.norm(x - centre, axis=1) - rho).max() / LENGTH),
        position_error=float(np.linalg.norm(x - x_exact, axis=1).max() / LENGTH),
        rotation_error=float(np.abs(dphi).max() + np.abs(R[:, 2, 2] - 1.0).max()),
        tip_error=float(np.linalg.norm(x[-1] - x_exact[-1]) / LENGTH),
        iterations=int(sol.iterations[1:].sum()),
        cutbacks=int(sum(s["cutbacks"] for s in sol.stats)),
        wall_time=wall,
    )


def table(element_counts=(4, 8, 16), fraction=1.0):
    rows = [run(n, fraction) for n in element_counts]
    lines = [f"roll-up, end moment {fraction:g} x 2 pi EI / L (follower), one load step",
             f"{'elements':>8}  {'max |dist - rho| / L':>20}  {'max |x - x_exact| / L':>21}  "
             f"{'tip error / L':>13}  {'Newton it.':>10}  {'wall [s]':>8}"]
    for r in rows:
        lines.append(f"{r['n_elements']:>8}  {r['circle_error']:>20.2e}  {r['position_error']:>21.2e}  "
                     f"{r['tip_error']:>13.2e}  {r['iterations']:>10d}  {r['wall_time']:>8.3f}")
    return "\n".join(lines), rows


if __name__ == "__main__":
    for fraction in (1.0, 0.5, 0.25):
        text, rows = table(fraction=fraction)
        print(text)
        print(rows[-1]["solution"].material_summary())
        print()
