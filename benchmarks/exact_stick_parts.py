"""Exact stick's cost per Newton iteration by part (issue 26 speed, session 7): CPU time (``time.process_time``)
of search, projection, mortar kernel, nodal state, multiplier blocks, elements, assembly, Newton system (condense /
augmented ``A``), factorisation, solve and the rest, exclusive (a part's time without the parts it calls), split
into tangent evaluations and forces-only (line-search) trials.

    python benchmarks/exact_stick_parts.py [--scenes twisted_pair bundle19 strand19] [--stick exact penalty]
        [--repeat 2] [--fresh]

``twisted_pair``: the main job's warm solve (``twisted_pair128``: its scene at 128 elements a wire) (``examples/twisted_pair.py``, 16 steps), per linear solve (every
Newton iteration, failed attempts included).  ``bundle19`` (``bundle37``, ``bundle61``) / ``strand19``: one
Newton iteration at the reference poses of ``scaling.bundle_model`` / ``scaling_scenes.strand_model("19")``
(tangent evaluation, Newton system, factorisation with the solver's lagging, or afresh with ``--fresh``, solve)
and the line search's full-step trial at the step's end (forces only for exact stick, as ``newton.backtrack``
evaluates it).  Best of ``--repeat`` warm runs (least total CPU).
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parents[0] / "examples"))

import beamsolver as bs  # noqa: E402
from beamsolver.assembly import system as asm  # noqa: E402
from beamsolver.contact import kernel_jit, mortar, mortar_jit, system as csys  # noqa: E402
from beamsolver.nonlinear import augmented, lagged, linsolve, newton  # noqa: E402
from beamsolver.nonlinear.problem import Problem  # noqa: E402

# (part, owner, attribute): the functions timed; a part's time excludes the timed functions it calls
TARGETS = [
    ("search", csys, "broad_pairs"), ("search", csys, "element_spheres"),
    ("projection", csys, "gauss_projections"), ("projection", csys, "closest_points"),
    ("pairs: owners, records", csys.ContactSystem, "pairs"),
    ("active set, parameters", csys.ContactSystem, "_active"), ("active set, parameters", csys.ContactSystem, "_params"),
    ("active set, parameters", csys.ContactSystem, "_centres"),
    ("point kernel", csys.ContactSystem, "_kernels"),
    ("mortar kernel", kernel_jit, "mortar_terms"), ("mortar kernel", kernel_jit, "mortar_forces"),
    ("mortar groups", csys.ContactSystem, "_nodal_weights"),
    ("nodal state", mortar, "nodal_state"),
    ("multiplier blocks", mortar, "multiplier_blocks"), ("multiplier blocks", mortar, "multiplier_basis"),
    ("multiplier blocks", mortar, "group_forces"), ("multiplier blocks", mortar, "add_pairs"),
    ("multiplier blocks", mortar_jit, "subtract_indexed"),
    ("contact glue", csys.ContactSystem, "_mortar"), ("contact glue", csys.ContactSystem, "_local_blocks"),
    ("contact glue", csys.ContactSystem, "evaluate"),
    ("contact assembly", csys, "_with_mortar"), ("contact assembly", asm.System, "assemble_blocks"),
    ("elements", asm.System, "evaluate"),
    ("evaluation glue", Problem, "evaluate"), ("evaluation glue", Problem, "_multipliers"),
    ("Newton system", Problem, "linear_system"), ("Newton system", Problem, "augmented_system"),
    ("Newton system", asm.System, "matrix"),
    ("factorisation", linsolve.Solver, "factorize"), ("factorisation", linsolve, "factorize_tangent"),
    ("solve", augmented.Augmented, "solve"), ("solve", linsolve._Typed, "solve"),
    ("solve", lagged.LaggedFactor, "solve"),
    ("Newton loop", newton.Newton, "iterate"),
]
ORDER = ["search", "projection", "pairs: owners, records", "active set, parameters", "point kernel", "mortar kernel",
         "mortar groups", "nodal state", "multiplier blocks", "contact glue", "contact assembly", "elements",
         "evaluation glue", "Newton system", "factorisation", "solve", "Newton loop"]

TIMES = {}         # (part, trial) -> CPU s
STACK = []         # [children's time] of the timed calls in progress
TRIAL = [0]        # > 0 inside a forces-only ``Problem.evaluate``


def _wrap(part, f):
    """``f`` timed into ``TIMES[(part, inside a trial)]``, exclusive of the timed calls it makes."""
    def g(*a, **k):
        trial = f is ORIG.get((Problem, "evaluate")) and not k.get("tangent", a[3] if len(a) > 3 else True)
        TRIAL[0] += trial
        STACK.append(0.0)
        t0 = time.process_time()
        try:
            return f(*a, **k)
        finally:
            dt = time.process_time() - t0
            kids = STACK.pop()
            key = (part, TRIAL[0] > 0)
            TIMES[key] = TIMES.get(key, 0.0) + dt - kids
            if STACK:
                STACK[-1] += dt
            TRIAL[0] -= trial
    return g


ORIG = {}


def install():
    """Wrap every ``TARGETS`` function (``uninstall`` puts them back)."""
    for part, owner, name in TARGETS:
        f = owner.__dict__[name] if isinstance(owner, type) else getattr(owner, name)
        if isinstance(f, staticmethod):
            continue
        ORIG.setdefault((owner, name), f)
    for part, owner, name in TARGETS:
        if (owner, name) in ORIG:
            setattr(owner, name, _wrap(part, ORIG[(owner, name)]))


def uninstall():
    for (owner, name), f in ORIG.items():
        setattr(owner, name, f)


def stick_mode(stick):
    """``(original, wrapper)`` of ``Model.add_contact`` with the given ``stick`` as its default."""
    orig = bs.Model.add_contact

    def add_contact(self, *a, **options):
        options.setdefault("stick", stick)
        return orig(self, *a, **options)
    return orig, add_contact


SOLVES = [0]
LAGGED = ["auto"]  # the bundles' solver: ``--fresh``: a factorisation per iteration (the iterations share their poses)


def twisted_pair(n_elements=None):
    """The main job's warm solve (``n_elements`` a wire: ``twisted_pair128`` for 128): ``(CPU s, linear solves,
    evaluations)``."""
    import twisted_pair as tp
    model = tp.build()[0] if n_elements is None else tp.build(n_elements=n_elements)[0]
    direction = newton.Newton.direction
    count = [0, 0]
    evaluate = Problem.evaluate

    def counted(self, *a, **k):
        count[0] += 1
        return direction(self, *a, **k)

    def ev(self, *a, **k):
        count[1] += 1
        return evaluate(self, *a, **k)
    newton.Newton.direction, Problem.evaluate = counted, ev
    try:
        t0 = time.process_time()
        sol = bs.solve(model, steps=16)
        t = time.process_time() - t0
    finally:
        newton.Newton.direction, Problem.evaluate = direction, evaluate
    return t, count[0], count[1], int(sum(s["iterations"] for s in sol.stats))


def _one_iteration(model):
    """``(CPU s, times)`` of one Newton iteration of ``model`` at its reference poses and the full-step trial (the
    best of three: patterns and the solver's analysis in place, lagged factorisations where ``linsolve`` lags)."""
    problem = Problem.from_model(model)
    H = problem.system.poses0.copy()
    solver = linsolve.Solver(lagged=LAGGED[0])
    best = None
    for _ in range(3):
        TIMES.clear()
        problem.begin_step(H, 0.0)
        t0 = time.process_time()
        ev = problem.evaluate(H, 1.0, tangent=True)
        if problem.augments(ev):
            x = problem.augmented_system(ev).solve(solver)
        else:
            K, rhs = problem.linear_system(ev)
            x = linsolve.factorize_tangent(K, solver, saddle=ev.mult is not None).solve(rhs)
        dzf, dlam = problem.split_solution(ev, x)
        if ev.mult is not None:
            problem.multiplier_step(ev, dlam)
        dz = np.zeros(6 * problem.system.n_nodes)
        dz[problem.system.free_dofs] = dzf
        # a line-search trial along the step (the step at the rest poses is far too long to be taken: a length that
        # moves no node by more than 1e-3 of the smallest radius, with the multipliers' step scaled alike)
        s = min(1.0, 1e-3 * float(np.min(problem.contact.el_radius)) / max(float(np.abs(dz).max()), 1e-300))
        if ev.mult is not None:
            problem.multiplier_trial(s)
        H1 = problem.update(H, s * dz.reshape(-1, 6))
        problem.evaluate(H1, 1.0, tangent=ev.mult is None or not newton.FORCES_ONLY_TRIALS)
        t = time.process_time() - t0
        if best is None or t < best[0]:
            best = (t, dict(TIMES))
    solver.close()
    return best


def _bundle(name):
    import scaling_scenes
    from scaling import bundle_model
    return _one_iteration(bundle_model(scaling_scenes.PER_WIRE, n_layers=scaling_scenes.LAYERS[name])[0])


def bundle19():
    return _bundle("19")


def bundle37():
    return _bundle("37")


def bundle61():
    return _bundle("61")


def strand19():
    import scaling_scenes
    return _one_iteration(scaling_scenes.strand_model("19")[0])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="+", default=["twisted_pair", "bundle19", "strand19"])
    ap.add_argument("--stick", nargs="+", default=["penalty", "exact"])
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--fresh", action="store_true", help="bundles, strands: a factorisation per iteration")
    a = ap.parse_args()
    LAGGED[0] = False if a.fresh else "auto"
    cols = []
    for scene in a.scenes:
        for stick in a.stick:
            orig, add = stick_mode(stick)
            bs.Model.add_contact = add
            try:
                if scene.startswith("twisted_pair"):
                    n_el = int(scene[len("twisted_pair"):] or 0) or None
                    twisted_pair(n_el)                  # warm-up
                    install()
                    best = None
                    for _ in range(a.repeat):
                        TIMES.clear()
                        r = twisted_pair(n_el)
                        if best is None or r[0] < best[0][0]:
                            best = (r, dict(TIMES))
                    uninstall()
                    (t, solves, evals, its), times = best
                    scale = 1e3 / solves
                    label = f"{scene} {stick}: ms per linear solve ({its} it., {solves} solves, {evals / solves:.2f} evaluations a solve)"
                else:
                    fn = globals()[scene]
                    install()
                    t, times = fn()
                    uninstall()
                    scale = 1e3
                    label = f"{scene} {stick}: ms per iteration"
            finally:
                bs.Model.add_contact = orig
            cols.append((label, t * scale, times, scale))
            print(f"{label}: total {t * scale:.3f}", flush=True)
    print("\n| part | " + " | ".join(c[0] for c in cols) + " |")
    print("|---|" + "---:|" * len(cols))
    for part in ORDER:
        row = []
        for _, _, times, scale in cols:
            tg, tr = times.get((part, False), 0.0) * scale, times.get((part, True), 0.0) * scale
            row.append(f"{tg:.3f}" + (f" + {tr:.3f} trials" if tr > 5e-4 * scale / 1e3 else ""))
        print(f"| {part} | " + " | ".join(row) + " |")
    row = []
    for _, total, times, scale in cols:
        rest = total - sum(times.values()) * scale
        row.append(f"{rest:.3f}")
    print("| other (not timed) | " + " | ".join(row) + " |")
    print("| **total** | " + " | ".join(f"**{c[1]:.3f}**" for c in cols) + " |")


if __name__ == "__main__":
    main()
