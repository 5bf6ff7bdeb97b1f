"""Peers side by side: beamsolver, OpenSees (openseespy) and PyElastica on two classic problems.

Problems (same data for every code):

- ``bend45``: the 45-degree bend of Bathe & Bolourchi / Simo & Vu-Quoc
  (``examples/bend45.py``): radius 100, unit square section, ``E = 1e7``,
  ``G = E / 2`` (``EA = 1e7``, ``GA = 5e6``, ``EI2 = EI3 = GJ = 1e7 / 12``),
  dead tip force 600 along ``+z``.  Error: distance of the tip from the
  converged reference ``REF_BEND`` (beamsolver's axes), divided by the arc
  length ``L = 25 pi``.
- ``roll_up``: straight steel cantilever (``examples/roll_up.py``: ``L = 1``,
  circular section radius 0.01, ``E = 210e9``, ``nu = 0.3``) under the end
  moment ``2 pi EI / L`` about ``z``; exact: a full circle.  Error: largest
  distance of a node from the exact position of its material point
  (``max_i |x_i - x_exact(s_i)| / L``).  Not the tip alone: for a full turn any
  regular polygon closes on itself, so the tip error says little.

Codes and settings:

- beamsolver: ``bs.solve(model, steps=1)`` (default tolerances), build + solve timed.
- OpenSees: ``elasticBeamColumn`` (Euler-Bernoulli, cubic in the basic frame)
  with the ``Corotational`` ``geomTransf``, static ``LoadControl`` with
  ``Newton``, ``NormDispIncr`` test at ``1e-9 L``; per mesh the smallest
  number of equal load increments in 1, 2, 4, ... 64 that converges (found
  before timing).  The end moment of the roll-up is a nodal moment about the
  fixed global ``z`` axis: in this planar problem the section rotation axis
  stays ``z``, so it equals the follower moment.
- PyElastica: ``CosseratRod`` on the same nodes (the bend: its rest curvature
  set to the initial one), stiffness matrices overwritten with the same
  ``EA, GA, EI, GJ``, ``OneEndFixedBC`` on node 0 / element 0, position-Verlet
  damped dynamics (``AnalyticalLinearDamper``, uniform damping ``2.5 omega_1``
  with ``omega_1`` the first cantilever bending frequency) run to equilibrium,
  detected when no node moves by more than ``1e-6 L`` over a window of
  ``0.1 / omega_1`` (then about ``1e-5 L`` of motion is left).  The
  bend's load: ``EndpointForces`` (dead, applied at once).  The roll-up's
  moment: a couple with constant *material-frame* components on the last
  element, i.e. a follower couple (``UniformTorques`` converts a global vector
  to the material frame at every step: a fixed-axis load, and spread over the
  rod).  Time step ``1.5 / (c sqrt(1 / r_g^2 + 4 / dx^2))``, ``c = sqrt(E /
  rho)``, ``r_g`` the radius of gyration of the section (about 75 % of the
  stability limit found by trial); a run that blows up is redone with a time
  step 1.5 times smaller.

Timing: wall time (and CPU time of the process, less sensitive to the load of
a shared machine) of build + solve, single thread (BLAS/OpenMP/numba pools at
1), median of ``--repeats`` runs (3) for beamsolver and OpenSees, interleaved
per mesh, after one untimed warm-up; one run for PyElastica (after a warm-up
that compiles its numba kernels).

"At equal accuracy": for each target error, the time a peer needs to reach it,
log-log interpolated between its two meshes around the target (extrapolated
from its two finest meshes when no mesh reaches it, marked ``extrap.``; the
coarsest mesh's time when even that one is more accurate, marked ``<=``),
divided by beamsolver's time at the mesh defining the target.

``python benchmarks/peers/peers.py [--quick] [--repeats N] [--write-doc]``

Markdown tables on stdout, CSV in ``benchmarks/results/peers.csv``, section
``peers`` of ``docs/benchmarks.md`` (only when every peer ran, or with
``--write-doc``; never with ``--quick``).  A peer that is not installed is
skipped with a message.
"""
import argparse
import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))                       # benchmarks/: _report
sys.path.insert(0, str(HERE.parents[1] / "examples"))      # bend45.py, roll_up.py

import _report  # noqa: E402

_report.single_thread()
os.environ["NUMBA_NUM_THREADS"] = "1"

import csv  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

import beamsolver as bs  # noqa: E402
import bend45  # noqa: E402
import roll_up  # noqa: E402

# --------------------------------------------------------------------------- problems

REF_BEND = np.array([47.150439, 15.684800, 53.474859])   # converged tip, beamsolver's axes
BEND = dict(R=bend45.RADIUS, angle=np.pi / 4.0, E=bend45.E, G=bend45.G, P=bend45.P_MAX,
            A=1.0, I=1.0 / 12.0, J=1.0 / 6.0)
BEND["L"] = BEND["R"] * BEND["angle"]

_sec = bs.Section.circular(radius=roll_up.RADIUS, E=roll_up.E, nu=roll_up.NU)
EA, GA2, GA3, GJ, EI2, EI3 = (float(c) for c in np.diag(_sec.C))
ROLL = dict(L=roll_up.LENGTH, r=roll_up.RADIUS, E=roll_up.E, G=roll_up.E / (2.0 * (1.0 + roll_up.NU)),
            EA=EA, GA2=GA2, GA3=GA3, GJ=GJ, EI2=EI2, EI3=EI3, rho=7850.0)
ROLL["M"] = 2.0 * np.pi * EI3 / ROLL["L"]

FAST_MESHES = {"bend45": (2, 4, 8, 16, 32, 64),
               "roll_up": (4, 8, 16, 32, 64)}  # 2 elements of half a turn each: SE(3) log at angle pi
ELASTICA_MESHES = (25, 50, 100, 200, 400)
TARGET_MESHES = (8, 16)            # bend: equal accuracy with beamsolver's 8 and 16 elements
ROLL_TARGETS = (1e-2, 1e-3)        # roll-up: beamsolver is exact on any mesh; fixed targets instead


def arc_nodes(n):
    th = np.linspace(0.0, BEND["angle"], n + 1)
    return np.stack([BEND["R"] * np.sin(th), BEND["R"] * (1.0 - np.cos(th)), 0.0 * th], axis=1)


def bend_error(x):
    return float(np.linalg.norm(x[-1] - REF_BEND) / BEND["L"])


def roll_error(x):
    n = len(x) - 1
    x_exact, _ = roll_up.exact_poses(n)
    return float(np.linalg.norm(x - x_exact, axis=1).max() / ROLL["L"])


ERROR = {"bend45": bend_error, "roll_up": roll_error}

# --------------------------------------------------------------------------- beamsolver


def ours(problem, n):
    """Node positions ``(n + 1, 3)`` and notes."""
    if problem == "bend45":
        model, beam = bend45.build(n)
    else:
        model, beam, _ = roll_up.build(n)
    try:
        sol = bs.solve(model, steps=1, verbose=False)
    except bs.ConvergenceError as exc:
        return None, f"failed: {exc}"
    x = sol.poses[-1][:, :3, 3]                  # one beam: all nodes, root to tip
    return x, f"{int(sol.iterations[1:].sum())} Newton it., {sol.n_steps} step(s)"


# --------------------------------------------------------------------------- OpenSees

ops = None


def _ops_model(problem, n, nsteps):
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    if problem == "bend45":
        x0 = arc_nodes(n)
        A, E, G, J, I = BEND["A"], BEND["E"], BEND["G"], BEND["J"], BEND["I"]
        Iy = Iz = I
        load = (0.0, 0.0, BEND["P"], 0.0, 0.0, 0.0)
        L = BEND["L"]
    else:
        x0 = np.zeros((n + 1, 3))
        x0[:, 0] = np.linspace(0.0, ROLL["L"], n + 1)
        E, G = ROLL["E"], ROLL["G"]
        A, J, Iy, Iz = ROLL["EA"] / E, ROLL["GJ"] / G, ROLL["EI2"] / E, ROLL["EI3"] / E
        load = (0.0, 0.0, 0.0, 0.0, 0.0, ROLL["M"])
        L = ROLL["L"]
    for i, p in enumerate(x0):
        ops.node(i + 1, *map(float, p))
    ops.fix(1, 1, 1, 1, 1, 1, 1)
    ops.geomTransf("Corotational", 1, 0.0, 0.0, 1.0)          # local z = global z (both problems lie in z = 0)
    for i in range(n):
        ops.element("elasticBeamColumn", i + 1, i + 1, i + 2, A, E, G, J, Iy, Iz, 1)
    ops.timeSeries("Linear", 1)
    ops.pattern("Plain", 1, 1)
    ops.load(n + 1, *load)
    ops.constraints("Plain")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1e-9 * L, 50, 0)
    ops.algorithm("Newton")
    ops.integrator("LoadControl", 1.0 / nsteps)
    ops.analysis("Static")


def opensees(problem, n, nsteps):
    _ops_model(problem, n, nsteps)
    ok = ops.analyze(nsteps)
    if ok != 0:
        return None, f"failed ({ok})"
    x = np.array([[ops.nodeCoord(i + 1, k + 1) + ops.nodeDisp(i + 1, k + 1) for k in range(3)]
                  for i in range(n + 1)])
    return x, f"{nsteps} load increment(s)"


def opensees_steps(problem, n):
    """Smallest number of load increments (1, 2, 4, ..., 64) with which Newton converges, or None."""
    for nsteps in (1, 2, 4, 8, 16, 32, 64):
        x, _ = opensees(problem, n, nsteps)
        if x is not None:
            return nsteps
    return None


# --------------------------------------------------------------------------- PyElastica

ea = None
_Sim = None


def _elastica_setup(problem, n):
    """Simulator, rod, time step, first bending frequency, length."""
    if problem == "bend45":
        L, E, G, rho = BEND["L"], BEND["E"], BEND["G"], 1.0
        radius = 1.0 / np.sqrt(np.pi)             # area 1 (mass and rotary inertia of a disc of that area)
        x0 = arc_nodes(n).T
        t = np.diff(x0, axis=1)
        t /= np.linalg.norm(t, axis=0)
        d1 = np.repeat(np.array([[0.0], [0.0], [1.0]]), n, axis=1)
        directors = np.stack([d1, np.cross(t.T, d1.T).T, t])
        rod = ea.CosseratRod.straight_rod(n, np.zeros(3), np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]),
                                          L, radius, rho, youngs_modulus=E, shear_modulus=G,
                                          position=x0, directors=directors)
        rod.rest_kappa[:] = rod.kappa                # stress-free in the initial (curved) shape
        shear = (G * BEND["A"], G * BEND["A"], E * BEND["A"])
        bend = (E * BEND["I"], E * BEND["I"], G * BEND["J"])
        EI = E * BEND["I"]
    else:
        L, E, G, rho = ROLL["L"], ROLL["E"], ROLL["G"], ROLL["rho"]
        radius = ROLL["r"]
        rod = ea.CosseratRod.straight_rod(n, np.zeros(3), np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]),
                                          L, radius, rho, youngs_modulus=E, shear_modulus=G)
        shear = (ROLL["GA2"], ROLL["GA3"], ROLL["EA"])
        bend = (ROLL["EI2"], ROLL["EI3"], ROLL["GJ"])
        EI = ROLL["EI3"]
    rod.shear_matrix[:] = 0.0
    rod.bend_matrix[:] = 0.0
    for k in range(3):
        rod.shear_matrix[k, k] = shear[k]
        rod.bend_matrix[k, k] = bend[k]
    area = np.pi * radius**2
    omega1 = 3.516 * np.sqrt(EI / (rho * area * L**4))
    r_g = radius / 2.0                                # radius of gyration of the disc used for the inertia
    c = np.sqrt(E / rho)
    dt = 1.5 / (c * np.sqrt(1.0 / r_g**2 + 4.0 / (L / n) ** 2))

    sim = _Sim()
    sim.append(rod)
    sim.constrain(rod).using(ea.OneEndFixedBC, constrained_position_idx=(0,), constrained_director_idx=(0,))
    if problem == "bend45":
        sim.add_forcing_to(rod).using(ea.EndpointForces, np.zeros(3), np.array([0.0, 0.0, BEND["P"]]),
                                      ramp_up_time=1e-12)
    else:
        # d1 = +z, so the moment about +z has material components (M, 0, 0).
        sim.add_forcing_to(rod).using(_FollowerEndCouple, np.array([ROLL["M"], 0.0, 0.0]))
    return sim, rod, dt, omega1, L


def _elastica_run(problem, n, dt_scale=1.0, tol=1e-6, window=0.1, max_periods=10.0):
    """Damped dynamics until no node moves by more than ``tol L`` over ``window / omega_1``.

    A position test, not a velocity test: on fine meshes (roll-up, 400
    elements) the rod keeps a high-frequency jitter of tiny amplitude (nodal
    speeds ~0.1 m/s, displacements < 1e-7 L) that never lets a speed test pass.
    With the damping about critical for the first mode, the motion left when
    the test passes is about ``tol L / window``.
    """
    sim, rod, dt, omega1, L = _elastica_setup(problem, n)
    dt *= dt_scale
    sim.dampen(rod).using(ea.AnalyticalLinearDamper, uniform_damping_constant=2.5 * omega1, time_step=dt)
    sim.finalize()
    stepper = ea.PositionVerlet()
    t, steps, dt64 = np.float64(0.0), 0, np.float64(dt)
    check = max(1, int(round(window / (omega1 * dt))))
    t_max = max_periods * 2.0 * np.pi / omega1
    status = "equilibrium"
    x_old = rod.position_collection.copy()
    while True:
        for _ in range(check):
            t = stepper.step(sim, t, dt64)
        steps += check
        x = rod.position_collection
        if not np.isfinite(x).all() or np.abs(x).max() > 1e3 * L:
            return None, dict(dt=dt, steps=steps, t=float(t), status="blew up")
        if np.abs(x - x_old).max() < tol * L:
            break
        if t > t_max:
            status = "time cap reached"
            break
        x_old[:] = x
    return rod.position_collection.T.copy(), dict(dt=dt, steps=steps, t=float(t), status=status)


def elastica(problem, n):
    """Damped dynamics to equilibrium; retries with smaller time steps if it blows up (only the last run counts)."""
    scale = 1.0
    for _ in range(5):
        with Timer() as tm:
            x, info = _elastica_run(problem, n, dt_scale=scale)
        if x is not None:
            note = (f"dt {info['dt']:.2e}, {info['steps']} steps, t_end {info['t']:.3g}"
                    + ("" if info["status"] == "equilibrium" else f", {info['status']}"))
            return x, note, tm
        scale /= 1.5
    return None, "blew up", None


def _load_peers():
    global ops, ea, _Sim, _FollowerEndCouple
    missing = []
    try:
        import openseespy.opensees as _ops
        ops = _ops
    except Exception as exc:   # ImportError, or RuntimeError when its shared libraries are missing
        missing.append(("OpenSees", f"cannot import openseespy ({type(exc).__name__}: {exc}). "
                                    "Install: pip install openseespy (on Linux it also needs the system "
                                    "BLAS, e.g. Debian/Ubuntu: apt-get install libblas3)"))
    try:
        import elastica as _ea
        ea = _ea

        class Sim(ea.BaseSystemCollection, ea.Constraints, ea.Forcing, ea.Damping):
            pass

        class FollowerEndCouple(ea.NoForces):
            """Constant material-frame couple on the last element: a follower end moment."""

            def __init__(self, couple):
                super().__init__()
                self.couple = np.asarray(couple, dtype=float)

            def apply_torques(self, system, time=np.float64(0.0)):
                system.external_torques[:, -1] += self.couple

        _Sim, _FollowerEndCouple = Sim, FollowerEndCouple
    except Exception as exc:
        missing.append(("PyElastica", f"cannot import elastica ({type(exc).__name__}: {exc}). "
                                      "Install: pip install pyelastica"))
    return missing


_FollowerEndCouple = None

# --------------------------------------------------------------------------- measurements


class Timer:
    """Wall (``perf_counter``) and CPU (``process_time``) seconds of a ``with`` block."""

    def __enter__(self):
        self._w, self._c = time.perf_counter(), time.process_time()
        return self

    def __exit__(self, *exc):
        self.wall = time.perf_counter() - self._w
        self.cpu = time.process_time() - self._c


def measure(problems, fast_meshes, elastica_meshes, repeats, have_ops, have_ea):
    rows = []
    for problem in problems:
        err = ERROR[problem]
        for n in fast_meshes[problem]:
            ours(problem, n)                                      # warm-up
            nsteps = opensees_steps(problem, n) if have_ops else None
            t_ours, t_ops = [], []
            for _ in range(repeats):                             # interleaved repeats
                with Timer() as tm:
                    x, note = ours(problem, n)
                t_ours.append((tm.wall, tm.cpu))
                if nsteps is not None:
                    with Timer() as tm:
                        xo, note_o = opensees(problem, n, nsteps)
                    t_ops.append((tm.wall, tm.cpu))
            wall, cpu = np.median(t_ours, axis=0)
            rows.append(dict(problem=problem, code="beamsolver", elements=n,
                             error=err(x) if x is not None else float("nan"),
                             wall=float(wall), cpu=float(cpu), repeats=repeats, notes=note))
            print(_row_line(rows[-1]), flush=True)
            if have_ops:
                if nsteps is None:
                    rows.append(dict(problem=problem, code="OpenSees", elements=n, error=float("nan"),
                                     wall=float("nan"), cpu=float("nan"), repeats=0,
                                     notes="no convergence with up to 64 increments"))
                else:
                    wall, cpu = np.median(t_ops, axis=0)
                    rows.append(dict(problem=problem, code="OpenSees", elements=n, error=err(xo),
                                     wall=float(wall), cpu=float(cpu), repeats=repeats, notes=note_o))
                print(_row_line(rows[-1]), flush=True)
        if have_ea:
            _elastica_run(problem, 5, max_periods=0.01)               # compile the numba kernels
            for n in elastica_meshes:
                x, note, tm = elastica(problem, n)
                rows.append(dict(problem=problem, code="PyElastica", elements=n,
                                 error=err(x) if x is not None else float("nan"),
                                 wall=tm.wall if tm else float("nan"), cpu=tm.cpu if tm else float("nan"),
                                 repeats=1, notes=note))
                print(_row_line(rows[-1]), flush=True)
    return rows


def _row_line(r):
    return f"  {r['problem']:8s} {r['code']:10s} n={r['elements']:<4d} error/L={r['error']:.3e}  " \
           f"wall={r['wall']:.4f} s  cpu={r['cpu']:.4f} s  ({r['notes']})"


def time_at(target, rows, key="wall"):
    """Time (``key``: wall or cpu) to reach ``error <= target`` from one code's rows, by mesh: ``(time, flag)``."""
    pts = [(r["error"], r[key]) for r in rows if np.isfinite(r["error"]) and np.isfinite(r[key])]
    if len(pts) < 2:
        return float("nan"), "n/a"
    if pts[0][0] <= target:
        return pts[0][1], "<="
    for (e0, t0), (e1, t1) in zip(pts, pts[1:]):
        if e1 <= target < e0:
            w = np.log(target / e0) / np.log(e1 / e0)
            return float(np.exp(np.log(t0) + w * np.log(t1 / t0))), ""
    (e0, t0), (e1, t1) = pts[-2], pts[-1]
    if not e1 < e0:
        return float("nan"), "not reached"
    w = np.log(target / e0) / np.log(e1 / e0)
    return float(np.exp(np.log(t0) + w * np.log(t1 / t0))), "extrap."


def equal_accuracy(rows, peers):
    """Rows ``(problem, target, our time, [peer time, flag, ratio] ...)``."""
    out = []
    by = {}
    for r in rows:
        by.setdefault((r["problem"], r["code"]), []).append(r)
    problems = sorted({r["problem"] for r in rows}, key=["bend45", "roll_up"].index)
    for problem in problems:
        mine = {r["elements"]: r for r in by.get((problem, "beamsolver"), [])}
        if problem == "bend45":
            targets = [(mine[n]["error"], mine[n], f"{mine[n]['error']:.2e} (ours, {n} el.)")
                       for n in TARGET_MESHES if n in mine]
        else:
            n0 = 8 if 8 in mine else min(mine)
            targets = [(e, mine[n0], f"{e:.0e} (ours: {n0} el., error {mine[n0]['error']:.0e})")
                       for e in ROLL_TARGETS]
        for target, r0, label in targets:
            line = [problem, label, f"{1e3 * r0['wall']:.1f}"]
            for peer in peers:
                t, flag = time_at(target, by.get((problem, peer), []))
                c, _ = time_at(target, by.get((problem, peer), []), key="cpu")
                if np.isfinite(t):
                    line += [(flag + " " if flag else "") + f"{1e3 * t:.1f}", f"{t / r0['wall']:.3g}",
                             f"{c / r0['cpu']:.3g}"]
                else:
                    line += [flag, "-", "-"]
            out.append(line)
    return out


def markdown(rows, peers, skipped, command):
    parts = ["## Peers side by side: beamsolver, OpenSees, PyElastica\n",
             f"`{command}` ({_report.machine()}, single thread; "
             f"{', '.join(_versions(peers))}).\n",
             "Errors are divided by the length; wall time is build + solve ("
             f"{_runs(max(r['repeats'] for r in rows))} for beamsolver and OpenSees, one run for PyElastica). "
             "bend45: tip distance from the converged tip (47.150439, 15.684800, 53.474859); "
             "roll_up: largest node distance from its exact position on the circle.\n"]
    parts.append(
        "Settings (details: `benchmarks/peers/README.md`). beamsolver: one load step, default tolerances. "
        "OpenSees: `elasticBeamColumn` with the `Corotational` transformation (Euler-Bernoulli: without "
        "shear flexibility it converges to about 4e-5 L from the bend's reference), `LoadControl` + `Newton` "
        "with the fewest load increments (1, 2, 4, ...) that converge, searched before timing; the roll-up "
        "moment is a nodal moment about the fixed z axis, equal to the follower moment in this planar problem. "
        "PyElastica: `CosseratRod` with the same stiffnesses, `OneEndFixedBC`, `PositionVerlet` + "
        "`AnalyticalLinearDamper` (2.5 omega_1) run until no node moves by more than 1e-6 L in 0.1 / omega_1; "
        "follower end couple (material-frame torque on the last element) for the roll-up. Its error falls "
        "as 1/n: the clamp fixes the whole first element.\n")
    if skipped:
        parts.append("Skipped: " + "; ".join(name for name, _ in skipped) + ".\n")
    for problem in ("bend45", "roll_up"):
        pr = [r for r in rows if r["problem"] == problem]
        if not pr:
            continue
        parts.append(f"### {problem}\n")
        parts.append(_report.table(["code", "elements", "error / L", "wall [ms]", "CPU [ms]", "notes"],
                                   [[r["code"], r["elements"], r["error"], 1e3 * r["wall"], 1e3 * r["cpu"],
                                     r["notes"]] for r in pr], fmt={2: ".2e", 3: ".1f", 4: ".1f"}) + "\n")
    head = ["problem", "target error / L", "beamsolver wall [ms]"]
    for p in peers:
        head += [f"{p} wall [ms]", f"{p} / ours (wall)", f"{p} / ours (CPU)"]
    parts.append("### At equal accuracy\n")
    parts.append("Time a peer needs to reach the target error (log-log interpolation between its meshes; "
                 "`extrap.`: beyond its finest mesh, from its two finest; `<=`: its coarsest mesh is already "
                 "more accurate), divided by beamsolver's time for that accuracy; the same with CPU "
                 "(process) times, less sensitive to the load of a shared machine.\n")
    parts.append(_report.table(head, equal_accuracy(rows, peers)) + "\n")
    verdict = targets_verdict(rows, peers)
    if verdict:
        parts.append(verdict + "\n")
    return "\n".join(parts)


def targets_verdict(rows, peers):
    """One line on the issue's targets for the bend (wall-time ratios at beamsolver's 8-element accuracy)."""
    mine = {r["elements"]: r for r in rows if r["problem"] == "bend45" and r["code"] == "beamsolver"}
    if 8 not in mine:
        return ""
    target, t_ours = mine[8]["error"], mine[8]["wall"]
    out = []
    for peer, goal, text in (("OpenSees", 1.0, "faster than OpenSees"),
                             ("PyElastica", 100.0, "at least 100x faster than PyElastica")):
        if peer not in peers:
            continue
        t, flag = time_at(target, [r for r in rows if r["problem"] == "bend45" and r["code"] == peer])
        if np.isfinite(t):
            ratio = t / t_ours
            out.append(f"{text}: **{'met' if ratio > goal else 'not met'}** "
                       f"({peer} / beamsolver = {ratio:.3g}{' ' + flag if flag else ''})")
    return ("Issue targets on the 45-degree bend at beamsolver's 8-element accuracy: " + "; ".join(out) + "."
            if out else "")


def _runs(k):
    return "one run" if k == 1 else f"median of {k} runs"


def _versions(peers):
    from importlib.metadata import PackageNotFoundError, version
    out = []
    for name, pkg in (("beamsolver", "beamsolver"), ("OpenSees", "openseespy"), ("PyElastica", "pyelastica")):
        if name == "beamsolver" or name in peers:
            try:
                out.append(f"{pkg} {version(pkg)}")
            except PackageNotFoundError:
                pass
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="small meshes, one repeat; no docs update")
    ap.add_argument("--repeats", type=int, default=3, help="timed runs per mesh for beamsolver and OpenSees")
    ap.add_argument("--write-doc", action="store_true", help="update docs/benchmarks.md even if a peer is missing")
    args = ap.parse_args(argv)

    skipped = _load_peers()
    for name, why in skipped:
        print(f"{name} skipped: {why}")
    peers = [p for p in ("OpenSees", "PyElastica") if p not in {s[0] for s in skipped}]
    if args.quick:
        fast, slow, repeats = {p: (4, 8, 16) for p in FAST_MESHES}, (20, 40), 1
    else:
        fast, slow, repeats = FAST_MESHES, ELASTICA_MESHES, args.repeats
    if ops is not None:
        ops.logFile(os.devnull, "-noEcho")            # silence convergence failures of the increment search

    rows = measure(("bend45", "roll_up"), fast, slow, repeats, "OpenSees" in peers, "PyElastica" in peers)

    _report.RESULTS.mkdir(parents=True, exist_ok=True)
    path = _report.RESULTS / "peers.csv"
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["problem", "code", "elements", "error", "wall", "cpu", "repeats", "notes"])
        w.writeheader()
        w.writerows(rows)
    command = "python benchmarks/peers/peers.py" + (" --quick" if args.quick else "")
    text = markdown(rows, peers, skipped, command)
    print()
    print(text)
    print(f"CSV: {path}")
    if args.quick:
        print("--quick: docs/benchmarks.md not updated")
    elif skipped and not args.write_doc:
        print("docs/benchmarks.md not updated (a peer is missing; --write-doc to update anyway)")
    else:
        print(f"updated section 'peers' of {_report.write_section('peers', text)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
