"""Twisting two steel wires into a two-ply: the main job of beamsolver.

Two straight steel wires (grade 1770: tensile strength 1770 MPa, yield taken as
0.8 of it, 1416 MPa; ``E = 200 GPa``, ``nu = 0.3``), radius ``R = 0.5 mm``,
length ``L = 1 m``, touch along their length, side by side at ``x = +-R``; both
are clamped at ``z = 0``.  Their upper ends are rigidly linked to a plate node
on the pair's axis, which is turned about ``e_z`` by two full turns under a
dead pull of 500 N (250 N a wire, 18 % of its breaking load; its other degrees
of freedom held).  The wires wrap around each other into a two-ply in contact
with Coulomb friction (``mu = 0.3``; the slip increment is the SE(3) finite
difference of the seed paper; sliding starts at an elastic slip of 0.005
element lengths, Abaqus' default penalty friction).

Material range: a twisted touching wire has a surface shear strain of about
``sin(theta) = R Phi / L`` (docs/theory_twoply.md), so a steel two-ply twisted
elastically needs ``L / R`` above about 1300 for two turns; at 2000 here the largest
von Mises surface stress is 64 % of the yield stress (printed; the sections
carry ``yield_stress`` and the solver would warn, ``bs.MaterialRangeWarning``).
Real ropes are preformed (their wires laid plastically into helices); the
20 mm pair of ``examples/twisted_pair_extreme.py`` (shear strain 0.31) is a
mathematical benchmark.

The summary checks the model against the two-ply's closed forms
(docs/theory_twoply.md, after Love 1927 and Costello 1997): ply angle
``sin(theta) = R Phi / (lambda L)``, torque ``2 (C Phi cos(theta) / L + T_w R
sin(theta)) + O(theta^3)``, about ``(2 C + T R^2) Phi / L``, and shortening
``L (1 - cos(theta))``; and the stability of the path with ``bs.linearize``: under
this pull the pair stays far below Greenhill's limit of a long rod under
tension, ``M_c = 2 sqrt(T B)`` with ``B = 2 E I`` (the frictionless tangent stays
positive definite at every step).

    python examples/twisted_pair.py [--output twisted_pair_output] [--turns 2] [--steps 16] [--mu 0.3]

Contact options: a normal law smoothed over a gap of ``1e-3 (R1 + R2)`` and a
penalty of ``1e-4 E`` per unit length (elements 125 radii long: the default
penalty ``E`` is 1e8 times their bending stiffness and makes Newton crawl;
the largest penetration stays below 2 % of ``R``, printed).
"""
import argparse
import time

import numpy as np

import beamsolver as bs
from beamsolver.cables import steel_yield_stress

solve_options = dict(steps=16)      # for `beamsolver run examples/twisted_pair.py`


def build(radius=0.5e-3, length=1.0, n_elements=16, turns=2.0, pull=500.0, mu=0.3, E=200e9, nu=0.3,
          grade="1770", swap=False, smoothing=None, penalty=None, **contact_options):
    """Returns ``(model, plate node, (beam_a, beam_b))``; ``swap`` exchanges slave and master;
    ``grade``: steel grade setting the sections' yield stress (``None``: no limit);
    ``contact_options`` go to ``add_contact``."""
    ys = None if grade is None else steel_yield_stress(grade, E, "twisted_pair.build")
    sec = bs.Section.circular(radius=radius, E=E, nu=nu, yield_stress=ys)
    model = bs.Model()
    a = model.add_beam(bs.geometry.straight((radius, 0, 0), (radius, 0, length), n_elements), sec, name="wire a")
    b = model.add_beam(bs.geometry.straight((-radius, 0, 0), (-radius, 0, length), n_elements), sec, name="wire b")
    model.clamp(a.first)
    model.clamp(b.first)
    plate = model.add_node((0.0, 0.0, length), name="plate")
    model.join(plate, a.last, rigid=True)
    model.join(plate, b.last, rigid=True)
    model.fix(plate, ("ux", "uy", "rx", "ry", "rz"), values={"rz": lambda t: 2.0 * np.pi * turns * t})
    model.add_load(plate, force=(0.0, 0.0, pull), scale=lambda t: 1.0)
    slave, master = (b, a) if swap else (a, b)
    model.add_contact(slave, master, mu=mu, smoothing=2e-3 * radius if smoothing is None else smoothing,
                      penalty=1e-4 * E if penalty is None else penalty, **contact_options)
    return model, plate, (a, b)


def closed_form(phi, radius=0.5e-3, length=1.0, pull=500.0, E=200e9, nu=0.3):
    """Two-ply of touching wires (helix radius ``radius``) twisted by ``phi`` [rad] between clamped
    plates under the axial pull ``pull`` (docs/theory_twoply.md): ply angle [rad], torque [N m]
    (helix, all orders), its small-angle form ``(2 C + T R^2) phi / L``, shortening [m] and the
    wires' largest von Mises surface stress [Pa] (uniform helix, ends left out)."""
    A, I = np.pi * radius**2, np.pi * radius**4 / 4
    G = E / (2 * (1 + nu))
    B, C = E * I, 2 * G * I
    k = phi / length                                  # rotation rate about the axis per reference length
    cos = 1.0
    for _ in range(50):                               # T_w = T / (2 cos theta), stretch lambda = 1 + T_w / EA
        tw = pull / (2 * cos)
        sin = radius * k / (1 + tw / (E * A))
        cos = np.sqrt(1 - sin**2)
    k_t, k_b = k * cos, k * sin                       # twist and curvature per reference length
    per_wire = (tw * radius * sin + C * k_t * cos + B * k_b * sin
                + (B - C) * radius * k_b * k_t * cos / (1 + tw / (E * A)))
    sigma = tw / A + E * radius * k_b
    tau = G * radius * k_t
    return dict(ply_angle=np.arcsin(sin), torque=2 * per_wire, torque_small=(2 * C + pull * radius**2) * k,
                shortening=length * (1 - cos), von_mises=np.sqrt(sigma**2 + 3 * tau**2))


def ply_angle(sol, beam, step=-1):
    """Mean angle [rad] between the centre line of ``beam`` and the axis ``e_z`` over the middle half of
    its nodes (the helix, away from the clamped ends), from the node frames' ``e1``."""
    nodes = beam.nodes[len(beam.nodes) // 4: 3 * len(beam.nodes) // 4 + 1]
    e1 = sol.poses[step][nodes, :3, 0]
    return float(np.mean(np.arccos(np.clip(e1[:, 2], -1, 1))))


COLUMNS = ("twist [turns]", "torque [N m]", "closed form [N m]", "axial force [N]", "shortening [um]",
           "contacts", "sticking", "min gap [m]", "utilisation", "Newton it.", "wall [s]")


def table(sol, plate, clamps, turns, **scene):
    """Rows, one per step: twist [turns], torque on the plate about e_z [N m], its closed form
    (``closed_form``), axial force (the clamps' reaction along e_z) [N], shortening of the
    plate's height from step 0 [um], contact points carrying force, of which sticking, smallest
    gap of those [m], largest utilisation (von Mises stress / yield stress), Newton iterations,
    wall time of the step [s]."""
    rows = []
    z0 = sol.position(plate, 0)[2]
    for k in range(len(sol.times)):
        r = sol.reaction(plate, k)
        axial = -sum(sol.reaction(c, k)[2] for c in clamps)
        c = sol.contact(k) or {}
        gap = np.asarray(c.get("gap", np.zeros(0)))
        active = np.asarray(c.get("normal_force", np.zeros(0))) > 0
        stick = np.asarray(c.get("stick", np.zeros(0, dtype=bool)))
        phi = 2 * np.pi * turns * sol.times[k]
        rows.append((turns * sol.times[k], r[5], closed_form(phi, **scene)["torque"], axial,
                     1e6 * (z0 - sol.position(plate, k)[2]), int(active.sum()),
                     int((stick & active).sum()) if len(stick) else 0,
                     float(gap[active].min()) if active.any() else np.nan, float(sol.utilisation(k).max()),
                     sol.stats[k]["iterations"], sol.stats[k].get("wall_time", 0.0)))
    return rows


def lowest_eigenvalues(model, sol):
    """Lowest eigenvalue of the symmetric part of the tangent (``bs.linearize``) at steps 1..n."""
    lowest = []
    for k in range(1, len(sol.times)):
        K = bs.linearize(model, sol, k).K.toarray()
        lowest.append(np.linalg.eigvalsh(0.5 * (K + K.T))[0])
    return np.array(lowest)


def stability(model, sol, turns):
    """Twist [turns] from which the tangent (``bs.linearize``) has a negative eigenvalue (None
    if never), and its lowest eigenvalue at the last step.  ``model`` should be the frictionless
    twin of the solved scene: the elastic, load and normal-contact stiffness at the solution's
    poses is symmetric (conservative), so its eigenvalues decide stability; a slipping point's
    tangent is not symmetric, and sticking friction is left out (the estimate is conservative).
    Cheap here (about 200 unknowns, dense)."""
    lowest = lowest_eigenvalues(model, sol)
    neg = np.flatnonzero(lowest < 0)
    first = None if len(neg) == 0 else turns * sol.times[1 + neg[0]]
    return first, float(lowest[-1]) if len(lowest) else np.nan


def summary(sol, model, plate, beams, turns, scene):
    """Lines comparing the last step with the closed forms, and the material range."""
    cf = closed_form(2 * np.pi * turns, **scene)
    torque = sol.reaction(plate, -1)[5]
    z = sol.position(plate, 0)[2] - sol.position(plate, -1)[2]
    theta = np.mean([ply_angle(sol, b) for b in beams])
    eq = sol.equivalent_strain(-1)
    u = sol.utilisation(-1)
    sec = beams[0].section
    c = sol.contact(-1)
    active = c["normal_force"] > 0
    pen = max(0.0, -float(c["gap"][active].min())) if active.any() else 0.0
    return [
        f"closed form (docs/theory_twoply.md), {turns:g} turns: ply angle {np.degrees(theta):.4f} deg "
        f"(closed form {np.degrees(cf['ply_angle']):.4f}, {theta / cf['ply_angle'] - 1:+.2%}); torque {torque:.5g} N m "
        f"(closed form {cf['torque']:.5g}, {torque / cf['torque'] - 1:+.2%}; (2 C + T R^2) Phi / L = "
        f"{cf['torque_small']:.5g}); shortening {z * 1e6:.4g} um (closed form L (1 - cos theta) = "
        f"{cf['shortening'] * 1e6:.4g} um, {z / cf['shortening'] - 1:+.1%})",
        f"material: largest equivalent surface strain {eq.max():.3e}, "
        f"von Mises stress {eq.max() * sec.E / 1e6:.0f} MPa "
        f"(closed form {cf['von_mises'] / 1e6:.0f} MPa) = {u.max():.2f} of the yield stress "
        f"{sec.yield_stress / 1e6:.0f} MPa: {'within' if u.max() <= 1 else 'BEYOND'} the elastic range; "
        f"largest penetration {pen:.2e} m ({pen / sec.radius:.1%} of R)",
    ]


def main(output=None, turns=2.0, steps=16, n_elements=16, mu=0.3, length=1.0, pull=500.0, verbose=False,
         swap=False, check_stability=True):
    """Solve and print the summary; returns ``(solution, rows, wall time)``."""
    scene = dict(length=length, pull=pull)
    model, plate, (a, b) = build(n_elements=n_elements, turns=turns, mu=mu, swap=swap, **scene)
    print(f"twisted pair: 2 steel wires (grade 1770, yield stress 1416 MPa) R = 0.5 mm, L = {length:g} m, "
          f"{n_elements} elements each, pull {pull:g} N, mu = {mu}, {turns:g} turns in {steps} steps", flush=True)
    t0 = time.perf_counter()
    sol = bs.solve(model, steps=steps, output=output, verbose=verbose)
    wall = time.perf_counter() - t0
    rows = table(sol, plate, (a.first, b.first), turns, **scene)
    print("| " + " | ".join(COLUMNS) + " |")
    print("|" + "---:|" * len(COLUMNS))
    for tw, tq, cf, ax, dz, nc, ns, g, u, it, w in rows:
        print(f"| {tw:.3f} | {tq:.5g} | {cf:.5g} | {ax + 0.0:.4g} | {dz:.4g} | {nc} | {ns} | {g:.2e} | {u:.3f} | "
              f"{it} | {w:.2f} |")
    n_it = sum(s["iterations"] for s in sol.stats)
    print(f"converged steps {len(sol.times) - 1}, Newton iterations {n_it}, wall time {wall:.2f} s")
    for line in summary(sol, model, plate, (a, b), turns, dict(scene, radius=a.section.radius)):
        print(line)
    if check_stability:
        twin, _, _ = build(n_elements=n_elements, turns=turns, mu=0.0, swap=swap, **scene)
        tw_c, lam = stability(twin, sol, turns)
        B = 2.0 * model.beams[0].section.C[4, 4]
        mc = 2.0 * np.sqrt(pull * B)
        if tw_c is None:
            print(f"stability: the frictionless tangent stays positive definite at every step (lowest eigenvalue "
                  f"{lam:.3g} N m at the end): the two-ply is stable; the torque {rows[-1][1]:.3g} N m is "
                  f"{rows[-1][1] / mc:.1%} of Greenhill's limit under tension 2 sqrt(T B) = {mc:.3g} N m "
                  f"(B = 2 E I)")
        else:
            print(f"stability: the frictionless tangent has a negative eigenvalue from {tw_c:.3g} turns on "
                  f"(lowest {lam:.3g} N m at the end): the straight two-ply is then an unstable equilibrium "
                  f"(Greenhill's limit under tension 2 sqrt(T B) = {mc:.3g} N m)")
    if output is not None:
        script = bs.io.paraview.paraview_script(output)
        print(f"ParaView: paraview --script={script} (smooth tubes at the real radii coloured by utilisation, "
              "contact points green stick / yellow slip; or open the .pvd files)")
        try:
            from beamsolver import viz
            png = f"{output}/twisted_pair.png"
            viz.render(sol, step=-1, path=png, color_by="utilisation", scale=(1, 1, 0.02), view="xz",
                       window_size=(560, 720))
            print(f"picture: {png} (the axis squeezed 50 times to show the lay)")
        except ImportError:
            print("picture: install the [viz] extra (pyvista) to render one")
        except Exception as exc:          # a picture must never fail the run
            print(f"picture: not rendered ({exc})")
    return sol, rows, wall


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--output", default="twisted_pair_output")
    ap.add_argument("--turns", type=float, default=2.0)
    ap.add_argument("--steps", type=int, default=16)
    ap.add_argument("--elements", type=int, default=16)
    ap.add_argument("--mu", type=float, default=0.3, help="friction coefficient (0: frictionless)")
    args = ap.parse_args()
    main(output=args.output, turns=args.turns, steps=args.steps, n_elements=args.elements, mu=args.mu)
