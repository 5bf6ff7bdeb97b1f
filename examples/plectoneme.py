"""The twisted pair twisted on past Greenhill's torque: the two-ply writhes into a plectoneme loop.

The scene is the 20 mm benchmark's (``examples/twisted_pair_extreme.py``, the main job until
issue 32; linear elastic, no yield limit: surface strains far beyond steel's range, a
mathematical benchmark like it): two wires of radius ``R = 0.5 mm``, 20 mm long, clamped
below, their upper ends rigidly linked to a plate turned about ``e_z`` under a 5 N dead
pull, Coulomb friction ``mu = 0.3`` (exact stick, the library's default, since session 8 of 2026-11-27; the runs
below were measured with the penalty stick, ``build(stick="penalty")``, unless said otherwise),
with two additions:

- a small imperfection: a dead lateral force of ``imperfection`` times the pull on the
  mid-node of each wire, so that the pair leaves the straight (unstable) two-ply;
- self-contact: each wire is made of two beams joined rigidly at mid-length, and contact is
  declared between every two of the four beams (the wires against each other, and the lower
  half of each wire against its upper half), so the arms of the loop push each other apart
  (a beam cannot be in contact with itself; elements sharing a node never pair).

Past the onset of writhing no quasi-static path is traceable under the dead pull: the pair
snaps into a loop.  The solve is stabilised (``solve(stabilize=...)``: artificial viscous
damping in pseudo-time chosen from a dissipated-energy fraction); the script prints per step
the twist, the torque, the ribbon's twist ``Tw`` and writhe ``Wr`` (``beamsolver.topology``; the
axis closed by half-lines along ``e_z``), the linking number ``Lk`` (the plate's turns: the pair
starts untwisted), ``|Lk - Tw - Wr| / Lk``, the fraction converted to writhe ``Wr / Lk`` and the
fraction of the strain energy dissipated by the stabilisation.  It checks ``Lk = Tw + Wr``
within 2 % and compares the torque at the onset of writhing with Greenhill's.

Measured (16 elements per wire, 40 steps, one run each on a loaded 2-core machine):

- defaults with exact stick (session 8): the pair stays a straight two-ply (sticking, it bends as one rod) and stops
  at 4.16 turns (Newton fails at steps of 6e-6; ``Wr / Lk = 0.008``), 475 Newton iterations, 9 s CPU; with
  ``--stick penalty`` it writhes from 2.08 turns and stops at 2.91 (872 iterations, 12 s);
- defaults (``mu = 0.3``, imperfection 1e-2, ``stabilize = 2e-2``): writhing from 2.08 turns
  (10.9 N m), a loop at the top; stops at 2.12 of the 5 turns (Newton fails as the loop
  tightens on itself), ``Wr / Lk = 0.41``, ``|Lk - Tw - Wr| / Lk <= 1.5e-3``, dissipated 0.40 of
  the strain energy (warned: polluted), solve 134 s (286 s on a loaded machine);
- ``--stabilize 0.2``: 2.62 turns, ``Wr / Lk = 0.37``, dissipated 0.48; ``--stabilize 2e-3``:
  no writhing, stops at 4.16 turns as the unstabilised run (sticking friction stiffens the pair);
- ``--mu 0 --imperfection 1e-3 --stabilize 2e-3 --steps 80``: writhing from 1.63 turns at
  8.31 N m (``M L / B = 8.47``; the frictionless tangent turns indefinite at 8.36), the wires
  separate into two loops, stops at 1.64 turns with ``Wr / Lk = 0.56``.

Longer pairs (``--length 0.06 --pull 50 --elements 24 --steps 50``: ``sqrt(B / F) = 20 mm``, a
third of the length, so that a loop fits) writhe later and further but still stop once one loop
has formed (``Wr`` about 1 turn, the plate fallen from 60 to about 30 mm), as the loop closes on
itself: defaults 2.78 turns (onset 2.6 turns, 4.22 N m; dissipated 0.40); ``--stabilize 0.2``
3.63 turns (dissipated 0.33); ``--pull 200`` 3.32 turns (0.24); ``--pull 100 --stabilize 0.2``
3.51 turns, ``Wr / Lk = 0.42`` (0.41); ``--elements 32 --stabilize 0.2`` 3.37 turns,
``Wr / Lk = 0.55`` (0.76); ``--mu 0`` 2.43 turns, onset at 2.23 turns and 3.58 N m (the
tension-stiffened Greenhill estimate ``M = 2 B sqrt((4.49 / L)^2 + F / B)`` gives 3.54).
48 elements, 80 steps, a ten times softer contact penalty or a five times wider smoothing
change this by less than 0.3 turn.  ``|Lk - Tw - Wr| / Lk <= 6.7e-3`` in all of them.  At ``--length 0.1`` (24 or 40 elements) the
contact of the straight touching wires finds no equilibrium at ``t = 0`` (Newton stalls at a
scaled residual of 2e-3, also without friction or imperfection; 0.06 m is fine).

The writhing torque with friction lies above Greenhill's ``8.99 B / L`` for ``B = 2 E I``: the
sticking wires bend stiffer than two free ones, and the damping delays the snap.

Extension control (``--approach s``: the plate's height prescribed as ``L (1 - s t)`` together
with its turns, so the plate cannot fall; the axial force, the pull plus the support's reaction in
``z``, tension positive, is then an output) removes the dead-load snap of the plate but not the
pop of the loop.  ``--length 0.06 --pull 50 --elements 24 --steps 50 --stabilize 2e-3
--approach 0.3`` (``mu = 0.3``): the shortened pair first buckles in the plane of the imperfection
at its Euler load (-211 N; ``4 pi^2 B / L^2 = 215 N``) and twists bent (``Wr / Lk <= 0.06`` to
1.5 turns); from 1.8 turns the twisted pair takes up more length than the plate gives and the
axial force turns tensile (298 N at 3 turns, 5.5 N m); a loop grows at mid-height from about 3.5
turns and the solve stops at 3.972 turns, ``Wr = 0.55``, ``Wr / Lk = 0.14``, 990 N, where the
loop pops (a limit point: 3 negative eigenvalues), ``|Lk - Tw - Wr| / Lk <= 3.2e-3``, dissipated
at most 1.4e-2 of the strain energy (the first steps; 2.6e-4 at the end), 519 s on a loaded
machine.  It stops at the same pop with ``--mu 0`` (3.952 turns), ``--pieces 4`` (each wire four
beams in self-contact: 3.972; a self-contact of point kind only, ``line_angle = 0``: 3.972),
``--elements 32`` (3.943) and ``--stabilize 5e-2`` (3.978); ``--approach 0.5`` pops earlier
(3.116 turns, ``Wr = 0.57``).  More damping and shorter steps carry the pop in pseudo-time but
not past it: ``--mu 0 --stabilize 0.2 --min-step-ratio 1.5e-5`` completes the loop at 3.972
turns (``Wr = 0.94``, ``Wr / Lk = 0.24``, 1809 N, dissipated 5.2e-2, warned) and stops there
(with ``--approach 0.5``: at 3.122 turns, ``Wr = 0.89``, 964 N, dissipated 5.0e-2; with
``--elements 32``: at 3.945 turns, ``Wr = 0.96``, 1838 N, dissipated 5.8e-2);
with ``mu = 0.3``, ``--stabilize 5e-2 --min-step-ratio 1e-7`` creeps to 4.07 turns and
``--stabilize 0.2 --min-step-ratio 1e-7`` to 4.02 turns in steps of 1e-9 (both stopped by hand).
None of these reached the 5 turns: the tight, tensioned loop (its radius about two wire
diameters) is where every run stalled.  With the crossing kinds kept within a step
(``docs/theory.md`` section 20) the extension-control run passes the pop and the 5 turns:

    python examples/plectoneme.py --length 0.06 --pull 50 --elements 24 --steps 50 --stabilize 5e-2
        --approach 0.3 --min-step-ratio 1e-7

gives at 5 turns ``Wr = 1.09``, ``Wr / Lk = 0.22``, ``|Lk - Tw - Wr| / Lk <= 1.14e-2``, 1470 N,
dissipated 3.3e-2 of the strain energy at the end, 3025 Newton iterations, 196 s (loaded 2-core
machine): one loop at mid-height whose arms press on each other (``docs/plectoneme.png``).

Two-stage path, the magnetic-tweezers protocol (``--twist-until t1 --relax F``): the turns are
reached at ``t1`` under a dead pull high enough to keep the two-ply straight (Greenhill with
tension, ``M_c = 2 B sqrt((4.49 / L)^2 + F / B)``), then held, ``Lk`` fixed, while the pull falls
linearly to ``F``, so the pair writhes at ``Lk`` = 5.5 turns:

    python examples/plectoneme.py --length 0.06 --elements 48 --pieces 4 --mu 0 --pull 2000 --relax 300
        --twist-until 0.5 --turns 5.5 --steps 40 --stabilize 0.2

(Measured before section 20; with it, below.)  The straight two-ply twists to 5.5 turns
(9.55 N m, plate 60.38 -> 57.84 mm, ``Wr = 0``, ``Lk = Tw`` to 3e-8), writhes from 1250 N
(9.41 N m; ``M_c = 10.1``), a loop grows near the plate and the plate falls under the dead pull;
the run stops at ``t = 0.879``, 712 N, plate 44.5 mm, ``Wr = 1.08``, ``Wr / Lk = 0.20``,
``|Lk - Tw - Wr| / Lk <= 7.8e-4``, dissipated 0.18 of the strain energy (warned), 446-569 s: steps
of 6e-6 do not converge (scaled residual 0.76, positive definite tangent) once the loop has
closed, its arms crossing at 57-85 deg with contact forces about 1.2 kN, every contact of kind
orthogonal projection (Gauss points), none of kind point.  Every variant stops there, at
``Wr`` = 1.0-1.1 (one loop, no plectoneme yet), with ``|Lk - Tw - Wr| / Lk < 1e-3``:
``--stabilize 2e-2`` at ``t = 0.762`` (1110 N, ``Wr / Lk = 0.18``, dissipated 0.098), ``--pieces 8``
the same, contact ``--smoothing 0.1`` (gap / R) at ``t = 0.846`` (``Wr = 1.01``), ``--line-angle 50``
at ``t = 0.873`` (``Wr = 0.99``; crossing pairs still orthogonal, 1.4 kN), and with
``--point-ratio 0.05`` too at ``t = 0.872`` (``Wr = 0.95``; the crossing now one point pair,
2.1 kN; scaled residual 2e-5 at steps of 6e-6): not the contact kind then.  With 24 elements
(``--stabilize 2e-2``, ``mu = 0`` / ``0.3``: writhing from 1180 / 778 N) the loop goes on to
``Wr = 1.55``, ``Wr / Lk = 0.28``, then "elements turn by up to 2.04 rad within one element" (the
loop is 5 elements); with two pieces the loop near the plate lies in one beam (no self-contact)
and for one step the pair passes through itself (``|Lk - Tw - Wr| / Lk = 0.35``).  A longer pair
writhes at a lower pull (a wider loop, ``sqrt(B / F)``): ``--length 0.09 --elements 64 --relax
100 --stabilize 2e-2`` twists straight to 5.5 turns at 6.16 N m and writhes from 385 N
(``M_c = 6.4`` N m), reaching ``t = 1`` at 100 N mid-snap (``Wr = 0.52``, ``Wr / Lk = 0.094``,
plate 88.9 -> 72.9 mm, ``|Lk - Tw - Wr| / Lk <= 4.5e-5``, 770 s).  With section 20's crossing
kinds (48 elements, 4 pieces, ``mu = 0``) the loop closes and the two-ply starts to wrap round
itself near the plate: ``--stabilize 0.2`` to ``Wr = 1.20`` (``t = 0.885``), ``--stabilize 2e-2`` to
``Wr = 1.52``, ``Wr / Lk = 0.28`` (``t = 0.765``, 1100 N, plate 39.7 mm; also with
``--min-step-ratio 1e-7``), ``--stabilize 5e-2 --min-step-ratio 1e-7`` to ``Wr = 2.00``,
``Wr / Lk = 0.36`` (``t = 0.803``, 971 N, plate 33.1 mm, ``|Lk - Tw - Wr| / Lk <= 1.3e-3``,
dissipated 0.35: polluted, warned; 435 s), each stopping at steps of 6e-6 / 2.5e-9 with a scaled
residual of 3e-3 to 0.16 and a positive definite tangent.

    python examples/plectoneme.py [--output plectoneme_output] [--turns 5] [--steps 40] [--mu 0.3] [--stabilize 2e-2]
        [--elements 16] [--imperfection 1e-2] [--length 0.02] [--pull 5] [--approach s] [--pieces 2]
        [--min-step-ratio 2**-12] [--twist-until 1] [--relax F] [--path load] [--smoothing 2e-3]
        [--line-angle deg] [--point-ratio r] [--stick exact|penalty]
"""
import argparse
import time
from collections import namedtuple

import numpy as np

import beamsolver as bs
from beamsolver import topology

R, LENGTH, PULL = 0.5e-3, 0.02, 5.0
GREENHILL = 8.99             # M L / B of a clamped-clamped rod at the onset of buckling
LK_MIN = 0.1                 # Lk = Tw + Wr is checked (relative error) from this many turns on
# for `beamsolver run examples/plectoneme.py`; settle: the last step is solved again without damping
# (docs/theory_stabilized_equilibrium.md), so the saved answer is an equilibrium of the model
solve_options = dict(steps=40, stabilize=dict(fraction=2e-2, settle=True))


def build(turns=5.0, n_elements=16, mu=0.3, imperfection=1e-2, pull=PULL, E=200e9, nu=0.3, length=LENGTH,
          approach=None, pieces=2, twist_until=1.0, relax=None, smoothing=2e-3, line_angle=None,
          point_ratio=None, stick=None):
    """Returns ``(model, plate node, (wire a, wire b))``, each wire a tuple of ``pieces`` beams
    (bottom to top) of ``n_elements // pieces`` elements joined rigidly.  ``approach=None``: a
    dead ``pull`` on the plate (free in ``z``); a number ``s``: extension control, the plate's
    height prescribed as ``length (1 - s t)`` together with its turns (``pull`` then only scales
    the imperfection).  ``twist_until = t1 < 1``: a two-stage path, the turns reached at ``t1``
    and then held; over ``[t1, 1]`` the dead pull goes linearly from ``pull`` to ``relax`` (``relax``
    also scales the imperfection), or with ``approach`` the plate's height from ``length`` to
    ``length (1 - s)``.  ``stick``: ``add_contact(stick=)`` of every declaration (None: the library's default)."""
    sec = bs.Section.circular(radius=R, E=E, nu=nu)
    model = bs.Model()
    if pieces < 2 or n_elements % pieces:
        raise bs.InputError(f"build: pieces must be >= 2 and divide n_elements = {n_elements}, got {pieces}")
    if not 0.0 < twist_until <= 1.0:
        raise bs.InputError(f"build: twist_until must be in (0, 1], got {twist_until}")
    if relax is not None and (approach is not None or twist_until == 1.0):
        raise bs.InputError(f"build: relax = {relax} needs a dead pull (approach None) and twist_until < 1")
    t1 = twist_until
    stage2 = lambda t: max(0.0, t - t1) / (1.0 - t1) if t1 < 1.0 else t  # noqa: E731
    angle = lambda t: 2.0 * np.pi * turns * min(t / t1, 1.0)  # noqa: E731
    lateral = imperfection * (pull if relax is None else relax)
    cuts = np.linspace(0.0, length, pieces + 1)
    wires = []
    for x, name in ((R, "wire a"), (-R, "wire b")):
        wire = tuple(model.add_beam(bs.geometry.straight((x, 0, z0), (x, 0, z1), n_elements // pieces), sec,
                                    name=f"{name} piece {k}") for k, (z0, z1) in enumerate(zip(cuts, cuts[1:])))
        for lo, up in zip(wire, wire[1:]):
            model.join(lo.last, up.first, rigid=True)
        model.clamp(wire[0].first)
        mid = wire_nodes(wire)[n_elements // 2]
        model.add_load(int(mid), force=(0.0, lateral, 0.0), scale=lambda t: 1.0)
        wires.append(wire)
    plate = model.add_node((0.0, 0.0, length), name="plate")
    for wire in wires:
        model.join(plate, wire[-1].last, rigid=True)
    if approach is None:
        model.fix(plate, ("ux", "uy", "rx", "ry", "rz"), values={"rz": angle})
        if relax is None:
            model.add_load(plate, force=(0.0, 0.0, pull), scale=lambda t: 1.0)
        else:
            model.add_load(plate, force=(0.0, 0.0, pull), scale=lambda t: 1.0 + (relax / pull - 1.0) * stage2(t))
    else:
        model.prescribe(plate, bs.motion.compose(
            bs.motion.translation(lambda t: (0.0, 0.0, -approach * length * stage2(t))),
            bs.motion.rotation((0.0, 0.0, 1.0), angle)))
    # stick None: the library's default, exact stick; the five-turn extension-controlled run converges with it since
    # session 8 (docs/benchmarks.md, "Exact stick, session 8: plectoneme"; it stopped at t = 0.68 or 0.86 before)
    opts = dict(mu=mu, smoothing=smoothing * R)
    if stick is not None:
        opts["stick"] = stick
    if line_angle is not None:
        opts["line_angle"] = np.radians(line_angle)
    if point_ratio is not None:
        opts["point_ratio"] = point_ratio
    model.add_contact(list(wires[0]), list(wires[1]), **opts)
    for wire in wires:
        for i, j in zip(*np.triu_indices(pieces, 1)):
            model.add_contact(wire[i], wire[j], **opts)
    return model, plate, tuple(wires)


def wire_nodes(wire):
    """Node numbers along a wire (its beams in order, each joined node once)."""
    return np.concatenate([wire[0].nodes] + [b.nodes[1:] for b in wire[1:]])


def ribbon_measures(sol, wires, step):
    """``(Tw, Wr)`` of the ribbon of the two wires' centre lines at ``step``."""
    na, nb = wire_nodes(wires[0]), wire_nodes(wires[1])
    P = np.array([sol.pose(int(i), step) for i in np.concatenate([na, nb])])
    pa, pb = P[:len(na)], P[len(na):]
    axis, u = topology.ribbon(pa[:, :3, 3], pb[:, :3, 3])
    tw = topology.twist(axis, u, tangents=pa[:, :3, 0] + pb[:, :3, 0])
    return tw, topology.writhe_open(axis)


COLUMNS = ("t", "turns = Lk", "torque [N m]", "axial force [N]", "plate z [mm]", "Tw", "Wr", "|Lk-Tw-Wr|/Lk", "Wr/Lk",
           "dissipated / strain energy", "contacts", "Newton it.")


Row = namedtuple("Row", "t lk torque axial z tw wr error writhe_fraction dissipated contacts iterations")


def table(sol, plate, wires, turns, pull=0.0, twist_until=1.0, relax=None):
    """One row of ``COLUMNS`` per step; ``pull`` the dead pull on the plate (the axial force is
    the pull plus the support's reaction in ``z``: tension positive), going to ``relax`` over
    ``[twist_until, 1]`` if given; the turns are reached at ``twist_until``."""
    rows = []
    for k in range(len(sol.times)):
        t = sol.times[k]
        lk = turns * min(t / twist_until, 1.0)
        if relax is not None:
            pull_t = pull + (relax - pull) * max(0.0, t - twist_until) / (1.0 - twist_until)
        else:
            pull_t = pull
        tw, wr = ribbon_measures(sol, wires, k)
        st = sol.stats[k].get("stabilization", {})
        c = sol.contact(k) or {}
        active = int((np.asarray(c.get("normal_force", np.zeros(0))) > 0).sum())
        err = abs(lk - tw - wr) / lk if lk > 0 else abs(tw + wr)
        react = sol.reaction(plate, k)
        rows.append(Row(t, lk, react[5], pull_t + react[2], 1e3 * sol.position(plate, k)[2], tw, wr, err,
                     wr / lk if lk > 0 else 0.0, st.get("fraction", 0.0), active, sol.stats[k]["iterations"]))
    return rows


def onset(rows):
    """Twist [turns] and torque [N m] at the onset of writhing: the largest torque before the
    writhe exceeds 5 % of the linking number."""
    lk, torque, frac = (np.array([getattr(r, f) for r in rows]) for f in ("lk", "torque", "writhe_fraction"))
    before = frac < 0.05
    k = int(np.argmax(np.where(before, torque, -np.inf)))
    return lk[k], torque[k]


def main(output=None, turns=5.0, steps=40, n_elements=16, mu=0.3, stabilize=2e-2, imperfection=1e-2,
         verbose=False, length=LENGTH, pull=PULL, approach=None, pieces=2, min_step_ratio=2.0**-12,
         twist_until=1.0, relax=None, path="load", smoothing=2e-3, line_angle=None,
         point_ratio=None, stick=None):
    """Solve, print the table and the checks; returns ``(solution, rows, wall time, checks)``."""
    model, plate, wires = build(turns=turns, n_elements=n_elements, mu=mu, imperfection=imperfection,
                                 length=length, pull=pull, approach=approach,
                                 pieces=pieces, twist_until=twist_until, relax=relax,
                                 smoothing=smoothing, line_angle=line_angle,
                                 point_ratio=point_ratio, stick=stick)
    t0 = time.perf_counter()
    try:
        sol = bs.solve(model, steps=steps, output=output, verbose=verbose, stabilize=stabilize,
                       min_step_ratio=min_step_ratio, path=path)
    except bs.ConvergenceError as e:
        print(f"stopped: {e}")
        sol = e.solution
    wall = time.perf_counter() - t0
    rows = table(sol, plate, wires, turns, pull=pull if approach is None else 0.0, twist_until=twist_until,
                 relax=relax)
    control = f"pull {pull:g} N" if approach is None else f"extension control, approach {approach:g}"
    if twist_until < 1.0:
        control += f", turns reached at t = {twist_until:g} then held" + (f", pull relaxed to {relax:g} N"
                                                                         if relax is not None else "")
    print(f"plectoneme: 2 wires R = {R * 1e3:g} mm, L = {length * 1e3:g} mm, {control}, {n_elements} elements "
          f"each in {pieces} pieces, mu = {mu}, {turns:g} turns in {steps} steps, stabilize = {stabilize}, "
          f"imperfection {imperfection * (pull if relax is None else relax):g} N")
    print("| " + " | ".join(COLUMNS) + " |")
    print("|" + "---:|" * len(COLUMNS))
    for t, lk, tq, fz, z, tw, wr, err, fw, fd, nc, it in rows:
        print(f"| {t:.4f} | {lk:.4f} | {tq:.4g} | {fz:.4g} | {z:.3f} | {tw:.4f} | {wr:.4f} | {err:.2e} | {fw:.3f} "
              f"| {fd:.2e} | {nc} | {it} |")
    B = 2.0 * model.beams[0].section.C[4, 4]
    worst = max((r.error for r in rows if r.lk >= LK_MIN), default=np.nan)     # relative error: Lk not near 0
    tw_c, m_c = onset(rows)
    checks = dict(reached=rows[-1].lk, t_end=float(sol.times[-1]), lk_error=worst, onset_turns=tw_c, onset_torque=m_c,
                  onset_ratio=m_c * length / B, wall=wall, writhe=rows[-1].writhe_fraction)
    print(f"reached {checks['reached']:.3f} of {turns:g} turns, t = {checks['t_end']:.4f}, in {wall:.1f} s; "
          f"Newton iterations "
          f"{int(sol.iterations.sum())}; writhe at the end {rows[-1].writhe_fraction:.1%} of Lk")
    print(f"Lk = Tw + Wr: largest |Lk - Tw - Wr| / Lk {worst:.2e} ({'within' if worst <= 0.02 else 'NOT within'} 2 %)")
    print(f"{sol.material_summary()} (linear elastic, a mathematical benchmark)")
    print(f"onset of writhing at {tw_c:.3f} turns, torque {m_c:.4g} N m: M L / B = {checks['onset_ratio']:.2f} "
          f"(B = 2 E I; Greenhill clamped-clamped {GREENHILL}, the pair's frictionless tangent 8.36)")
    if output is not None:
        print(f"ParaView: paraview --script={bs.io.paraview.paraview_script(output)} (or open {output}/*.pvd)")
        try:
            from beamsolver import viz
            png = f"{output}/plectoneme.png"
            viz.render(sol, step=-1, path=png, color_by="T", view="yz", window_size=(640, 640), zoom=1.3)
            print(f"picture: {png}")
        except ImportError:
            print("picture: install the [viz] extra (pyvista) to render one")
        except Exception as exc:          # a picture must never fail the run
            print(f"picture: not rendered ({exc})")
    return sol, rows, wall, checks


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--output", default="plectoneme_output")
    ap.add_argument("--turns", type=float, default=5.0)
    ap.add_argument("--steps", type=int, default=40)
    ap.add_argument("--elements", type=int, default=16)
    ap.add_argument("--mu", type=float, default=0.3)
    ap.add_argument("--stabilize", type=float, default=2e-2)
    ap.add_argument("--imperfection", type=float, default=1e-2)
    ap.add_argument("--length", type=float, default=LENGTH, help="wire length [m]")
    ap.add_argument("--pull", type=float, default=PULL, help="dead pull on the plate [N]")
    ap.add_argument("--min-step-ratio", type=float, default=2.0**-12, help="solve(min_step_ratio=)")
    ap.add_argument("--pieces", type=int, default=2, help="beams per wire (self-contact between them)")
    ap.add_argument("--approach", type=float, default=None,
                    help="extension control: the plate's height prescribed as length (1 - approach t)")
    ap.add_argument("--twist-until", type=float, default=1.0,
                    help="two-stage path: the turns reached at this t, then held while the pull relaxes "
                         "(--relax) or the plate approaches (--approach)")
    ap.add_argument("--relax", type=float, default=None, help="dead pull [N] at t = 1 (with --twist-until)")
    ap.add_argument("--path", default="load", help="solve(path=): load or arc-length")
    ap.add_argument("--smoothing", type=float, default=2e-3, help="contact smoothing gap / wire radius")
    ap.add_argument("--line-angle", type=float, default=None, help="add_contact(line_angle=) in degrees")
    ap.add_argument("--point-ratio", type=float, default=None, help="add_contact(point_ratio=)")
    ap.add_argument("--stick", default=None, help="add_contact(stick=): exact (the default) or penalty")
    a = ap.parse_args()
    main(output=a.output, turns=a.turns, steps=a.steps, n_elements=a.elements, mu=a.mu, stabilize=a.stabilize,
         imperfection=a.imperfection, verbose=True, length=a.length, pull=a.pull,
         approach=a.approach, pieces=a.pieces, min_step_ratio=a.min_step_ratio, twist_until=a.twist_until,
         relax=a.relax, path=a.path, smoothing=a.smoothing, line_angle=a.line_angle,
         point_ratio=a.point_ratio, stick=a.stick)
