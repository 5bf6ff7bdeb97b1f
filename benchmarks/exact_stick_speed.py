"""Exact stick's cost per Newton iteration against the penalty stick (issue 26, speed): the main job
(``examples/twisted_pair.py``, 16 steps: Newton iterations, linear solves (every Newton iteration, those of failed
attempts too), warm solve CPU time, ms per linear solve; its parts: the evaluations (line-search trials and tangents)
and their mean CPU time, the Newton systems, the factorisations and solves) and one Newton iteration of the 19-wire
bundle (``scaling.bundle_model`` at ``scaling_scenes.PER_WIRE``) and of its overlap-free twin, the 19-wire strand
(``scaling_scenes.strand_model``), at their reference poses: evaluation, Newton system (bordered with the multipliers,
or the augmented matrix, for exact stick), factorisation and solve (the solver's lagged solves allowed, as in Newton;
and without lagging: ``not lagged``), CPU s, and these parts.

    python benchmarks/exact_stick_speed.py [--scenes twisted_pair bundle19 strand19 kernel19] [--repeat 3] [--profile]
        [--modes penalty "exact (direct saddle)" exact ...] [--tree ../main]

Modes: ``penalty``; ``exact (before)``, the exact path on the numpy/scipy oracles that were its code
before the compiled parts (``mortar.use_numpy_scatter``: ``np.add.at`` scatters and the numpy trial rows;
``kernel_jit.mortar_terms_four``: four point-kernel calls; ``bordered.use_bmat``: COO/CSC constructors and ``sp.bmat``
every iteration) and without the switches below; ``exact (eager, full)``, the current code with the switches
off
(``newton.FORCES_ONLY_TRIALS``: the line search's full-step trial with its tangent; ``system.LAZY_MORTAR``: the
multiplier blocks at every trial; ``condense.ENABLED``: the full bordered system, 3 unknowns a group;
``augmented.ENABLED``); ``exact (direct saddle)``, the current code with the saddle-point system factorised directly
(``augmented.ENABLED`` off: session 5's path); ``exact (augmented)``, through ``A = K' + Kq E Kl`` at any size
(``augmented.MIN_UNKNOWNS`` 0); and ``exact``, the current path (the augmented solve from ``MIN_UNKNOWNS`` unknowns).
Each mode runs once to warm up (compilation, caches), then ``--repeat`` times: the best CPU time
(``time.process_time``: the machine is shared) is reported.  The twisted pair's Newton iterations move with round-off
(224-362 over variants that differ at round-off only, docs/benchmarks.md): compare the ms per linear solve.
``--profile``: a cProfile table of one warm exact run per scene (tottime).  ``--modes``: the modes to run (default
all).  ``--tree PATH`` (repeatable): the same rows, each run in a child process against the beamsolver of the
source tree ``PATH`` (e.g. the main branch's worktree), interleaved with this tree's rows mode by mode, so that a
before/after comparison is one run on one (shared) machine: its rows are labelled with the tree.  ``kernel19``: the
kernels alone on the bundle's points (``kernel19``), a table of its own, printed first.
"""
import argparse
import cProfile
import contextlib
import os
import pstats
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parents[0] / "examples"))

import beamsolver as bs  # noqa: E402
from beamsolver.contact import kernel_jit, mortar, system  # noqa: E402
from beamsolver.nonlinear import augmented, bordered, condense, linsolve, newton  # noqa: E402
from beamsolver.nonlinear.problem import Problem  # noqa: E402


@contextlib.contextmanager
def mode(name):
    """Every ``add_contact`` with the stick of ``name``; ``exact (before)``: the oracles' code paths."""
    stick = "penalty" if name == "penalty" else "exact"
    orig, terms = bs.Model.add_contact, kernel_jit.mortar_terms

    def add_contact(self, *a, **options):
        options.setdefault("stick", stick)
        return orig(self, *a, **options)

    bs.Model.add_contact = add_contact
    before = name == "exact (before)"
    mortar.use_numpy_scatter(before)
    bordered.use_bmat(before)
    if before:
        kernel_jit.mortar_terms = lambda X, p, law=None, **_: kernel_jit.mortar_terms_four(X, p, law)
    eager = name in ("exact (before)", "exact (eager, full)")
    newton.FORCES_ONLY_TRIALS = system.LAZY_MORTAR = condense.ENABLED = not eager
    augmented.ENABLED = name in ("exact", "exact (augmented)")
    min_unknowns = augmented.MIN_UNKNOWNS
    if name == "exact (augmented)":
        augmented.MIN_UNKNOWNS = 0
    try:
        yield
    finally:
        bs.Model.add_contact, kernel_jit.mortar_terms = orig, terms
        mortar.use_numpy_scatter(False)
        bordered.use_bmat(False)
        newton.FORCES_ONLY_TRIALS = system.LAZY_MORTAR = condense.ENABLED = True
        augmented.ENABLED, augmented.MIN_UNKNOWNS = True, min_unknowns


SOLVES = [0]     # linear solves (``Newton.direction`` calls) of the last run


SPLIT = {}       # the last twisted_pair run by parts: evaluations (count, CPU s), Newton systems and solves (CPU s)


def twisted_pair():
    """``(Newton iterations, CPU s)`` of the main job's solve; its linear solves in ``SOLVES``, its parts in ``SPLIT``:
    ``evaluations`` (``Problem.evaluate`` calls: line-search trials and tangents), ``evaluate`` (their CPU s),
    ``system`` (``Problem.linear_system``) and ``direction`` (``Newton.direction``: the Newton system, its
    factorisation and solve)."""
    import twisted_pair as tp
    model = tp.build()[0]
    direction, evaluate, linear_system = newton.Newton.direction, Problem.evaluate, Problem.linear_system
    SPLIT.update(evaluations=0, evaluate=0.0, system=0.0, direction=0.0)

    def timed(f, key, count=None):
        def g(*a, **k):
            t = time.process_time()
            try:
                return f(*a, **k)
            finally:
                SPLIT[key] += time.process_time() - t
                if count:
                    SPLIT[count] += 1
        return g

    def counted(self, *a, **k):
        SOLVES[0] += 1
        return direction(self, *a, **k)
    newton.Newton.direction, SOLVES[0] = timed(counted, "direction"), 0
    Problem.evaluate, Problem.linear_system = timed(evaluate, "evaluate", "evaluations"), timed(linear_system, "system")
    try:
        t0 = time.process_time()
        sol = bs.solve(model, steps=16)
        return int(sum(s["iterations"] for s in sol.stats)), time.process_time() - t0
    finally:
        newton.Newton.direction, Problem.evaluate, Problem.linear_system = direction, evaluate, linear_system


PARTS = {}       # the last bundle19 / strand19 iteration by parts (CPU s)


def _iteration(problem, H, solver):
    """CPU s of one Newton iteration at ``H`` by parts: ``[t0, evaluated, Newton system, solved]`` and the matrix
    factorised (``A`` of ``augmented``, else the bordered one)."""
    problem.begin_step(H, 0.0)
    t = [time.process_time()]
    ev = problem.evaluate(H, 1.0, tangent=True)
    t.append(time.process_time())
    if problem.augments(ev):
        aug = problem.augmented_system(ev)
        K = aug.A
        t.append(time.process_time())
        aug.solve(solver)
    else:
        K, rhs = problem.linear_system(ev)
        t.append(time.process_time())
        linsolve.factorize_tangent(K, solver, saddle=ev.mult is not None).solve(rhs)
    t.append(time.process_time())
    return t, K


def _one_iteration(model):
    """``(1, CPU s)`` of one Newton iteration of ``model`` at its reference poses (the best of three: patterns and
    the solver's analysis in place; lagged solves where ``linsolve`` lags); its parts in ``PARTS``, with
    ``fresh``: the factorisation and solve of one more iteration with a solver that does not lag."""
    problem = Problem.from_model(model)
    H = problem.system.poses0.copy()
    solver = linsolve.Solver()
    best = np.inf
    for _ in range(3):
        t, K = _iteration(problem, H, solver)
        if t[-1] - t[0] < best:
            best = t[-1] - t[0]
            PARTS.update(evaluate=t[1] - t[0], matrix=t[2] - t[1], solve=t[3] - t[2], unknowns=K.shape[0],
                         nnz=K.nnz, stats=dict(solver.stats))
    fresh = linsolve.Solver(lagged=False)
    _iteration(problem, H, fresh)           # (the analysis)
    t, _ = _iteration(problem, H, fresh)
    PARTS["fresh"] = t[3] - t[2]
    solver.close()
    fresh.close()
    return 1, best


def bundle19():
    """One Newton iteration of the 19-wire bundle (``scaling.bundle_model``) at its reference poses
    (``_one_iteration``)."""
    import scaling_scenes
    from scaling import bundle_model
    return _one_iteration(bundle_model(scaling_scenes.PER_WIRE, n_layers=2)[0])


def strand19():
    """One Newton iteration of the 19-wire strand (``scaling_scenes.strand_model``, the bundle's overlap-free twin)
    at its reference poses (``_one_iteration``)."""
    import scaling_scenes
    return _one_iteration(scaling_scenes.strand_model("19")[0])



def kernel19(label="", repeat=3):
    """Rows of the kernels alone on the 19-wire bundle's points at its reference poses (the exact path's first
    evaluation): the point kernel (``kernel_and_tangent`` with friction) on the points exact stick evaluates (every
    point of the overlap) against the mortar kernel (``mortar_terms`` at the points' tractions, whole tangent) and its
    compiled pass alone; the penalty's own evaluation has the points of the normal law only (its count printed)."""
    import scaling_scenes
    from scaling import bundle_model
    counts, cap = {}, {}
    for stick in ("penalty", "exact"):
        with mode(stick):
            m, _ = bundle_model(scaling_scenes.PER_WIRE, n_layers=2)
        problem = Problem.from_model(m)
        H = problem.system.poses0.copy()
        problem.begin_step(H, 0.0)
        spied = {}
        for name in ("kernel_and_tangent", "mortar_terms"):
            f = getattr(kernel_jit, name)

            def spy(X, p, *a, _f=f, _n=name, **k):
                spied[_n] = (X.copy(), dict(p), a, k)
                return _f(X, p, *a, **k)
            spied[name + "_orig"] = f
            setattr(kernel_jit, name, spy)
        try:
            problem.evaluate(H, 1.0, tangent=True)
        finally:
            for name in ("kernel_and_tangent", "mortar_terms"):
                setattr(kernel_jit, name, spied.pop(name + "_orig"))
        key = "kernel_and_tangent" if stick == "penalty" else "mortar_terms"
        counts[stick] = len(spied[key][0])
        if stick == "exact":
            cap = spied[key]
    X, p, a, k = cap
    law = a[0] if a and a[0] is not None else k.get("law") or kernel_jit.PENALTY_COULOMB
    T = k.get("T")
    P = len(X)

    def best(fn):
        out = np.inf
        fn()
        for _ in range(repeat):
            t0 = time.process_time()
            fn()
            out = min(out, time.process_time() - t0)
        return out
    K = np.empty((P, 24, 24))
    kind, par, has, (HCL, HFK, HLKp), _ = kernel_jit._table(X, p)
    kern = kernel_jit.make_kernel(law, mortar=True)
    f, Kq = np.empty((4, P, 4, 6)), np.empty((1, P, 24, 24))
    sc, vec, two = np.empty((P, 4)), np.empty((P, 6, 3)), np.empty((P, 2, 2))
    flags, frames, rows = np.empty((P, 2), dtype=np.bool_), np.empty((P, 4, 4, 4)), np.empty((P, kernel_jit.N_ROWS, 24))
    t_point = best(lambda: kernel_jit.kernel_and_tangent(X, p, friction=True, law=law, K=K))
    t_terms = best(lambda: kernel_jit.mortar_terms(X, p, law, T=T, whole=True))
    t_raw = best(lambda: kern(X, kind, par, has, HCL, HFK, HLKp, f, Kq, sc, vec, two, flags, frames, rows,
                              np.ascontiguousarray(T)))
    print(f"| bundle19 kernels{label} | {counts['penalty']} (penalty) / {P} (exact) | {1e3 * t_point:.1f} | "
          f"{1e3 * t_terms:.1f} ({t_terms / t_point:.2f}x) | {1e3 * t_raw:.1f} ({t_raw / t_point:.2f}x) |", flush=True)
    return 1, t_terms


SCENES = dict(twisted_pair=twisted_pair, bundle19=bundle19, strand19=strand19)
MODES = ("penalty", "exact (before)", "exact (eager, full)", "exact (direct saddle)", "exact (augmented)", "exact")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="+", default=list(SCENES) + ["kernel19"])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--profile", action="store_true")
    ap.add_argument("--modes", nargs="+", default=list(MODES), choices=MODES)
    ap.add_argument("--tree", action="append", default=[], help="another source tree to run the same rows against")
    ap.add_argument("--label", default="", help=argparse.SUPPRESS)      # (a child's rows: the tree's label)
    ap.add_argument("--no-header", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if "kernel19" in a.scenes:
        if not a.no_header:
            print("\n| kernels | points evaluated | point kernel [ms] | mortar_terms [ms] | its compiled pass [ms] |")
            print("|---|---|---:|---:|---:|", flush=True)
        for tree in a.tree:
            env = dict(os.environ, PYTHONPATH=str(Path(tree).resolve()))
            subprocess.run([sys.executable, __file__, "--scenes", "kernel19", "--repeat", str(a.repeat),
                            "--label", f" ({Path(tree).resolve().name})", "--no-header"], env=env, check=False)
        kernel19(a.label, a.repeat)
    if not a.no_header and set(a.scenes) - {"kernel19"}:
        print("\n| scene | stick | Newton it. | linear solves | time [s] | ms per linear solve | ratio to penalty |")
        print("|---|---|---:|---:|---:|---:|---:|", flush=True)
    for scene in (s for s in a.scenes if s != "kernel19"):
        ref = None
        for name in a.modes:
            for tree in a.tree:         # the other trees' row first, in a child process (its own imports)
                env = dict(os.environ, PYTHONPATH=str(Path(tree).resolve()))
                subprocess.run([sys.executable, __file__, "--scenes", scene, "--modes", name, "--repeat", str(a.repeat),
                                "--label", f" ({Path(tree).resolve().name})", "--no-header"], env=env, check=False)
            try:
                with mode(name):
                    SCENES[scene]()                             # warm-up
                    runs = []
                    for _ in range(a.repeat):
                        runs.append(SCENES[scene]() + (SOLVES[0] if scene == "twisted_pair" else 1,
                                                       dict(SPLIT) if scene == "twisted_pair" else dict(PARTS)))
            except Exception as e:      # noqa: BLE001  (a singular bordered matrix: a row of the table)
                print(f"| {scene} | {name}{a.label} | failed: {type(e).__name__}: {e} | | | | |", flush=True)
                continue
            best = min(runs, key=lambda r: r[1])
            its, solves, t = runs[0][0], runs[0][2], best[1]
            ms = 1e3 * t / max(solves, 1)
            ref = ms if name == "penalty" and ref is None else ref      # (this process's penalty row)
            q = best[3]
            st = q.get("stats", {})
            saddle = "" if not st.get("saddle_augmented") else (
                f"; GMRES {st['saddle_iterations'] / st['saddle_augmented']:.1f} it. a solve, "
                f"{st['saddle_fallbacks']} fallbacks")
            parts = (f" ({q['evaluations']} evaluations, {1e3 * q['evaluate'] / max(q['evaluations'], 1):.2f} ms each; "
                     f"Newton systems {q['system']:.3f}, factorisations and solves {q['direction'] - q['system']:.3f})") \
                if scene == "twisted_pair" else (
                f" (evaluation {q['evaluate']:.3f}, Newton system {q['matrix']:.3f}, factorisation and "
                f"solve {q['solve']:.3f}, not lagged {q['fresh']:.3f}; {q['unknowns']} unknowns, "
                f"{q['nnz']} non-zeros{saddle})")
            print(f"| {scene} | {name}{a.label} | {its} | {solves} | {t:.3f}{parts} | {ms:.2f} | "
                  f"{'' if ref is None else f'{ms / ref:.2f}'} |", flush=True)
        if a.profile:
            with mode("exact"):
                pr = cProfile.Profile()
                pr.enable()
                SCENES[scene]()
                pr.disable()
            pstats.Stats(pr, stream=sys.stdout).sort_stats("tottime").print_stats(25)


if __name__ == "__main__":
    main()
