"""Exact stick's cost per Newton iteration against the penalty stick (issue 26, speed): the main job
(``examples/twisted_pair.py``, 16 steps: Newton iterations, linear solves (every Newton iteration, those of failed
attempts too), warm solve CPU time, ms per linear solve) and one Newton iteration of the 19-wire bundle
(``scaling.bundle_model`` at ``scaling_scenes.PER_WIRE``) and of its overlap-free twin, the 19-wire strand
(``scaling_scenes.strand_model``), at their reference poses: evaluation, Newton system (bordered with the multipliers,
or the augmented matrix, for exact stick), factorisation and solve (the solver's lagged solves allowed, as in Newton;
and without lagging: ``not lagged``), CPU s, and these parts.

    python benchmarks/exact_stick_speed.py [--scenes twisted_pair bundle19 strand19] [--repeat 3] [--profile]
        [--modes penalty "exact (direct saddle)" exact ...]

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
``--profile``: a cProfile table of one warm exact run per scene (tottime).
"""
import argparse
import cProfile
import contextlib
import pstats
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


def twisted_pair():
    """``(Newton iterations, CPU s)`` of the main job's solve; its linear solves in ``SOLVES``."""
    import twisted_pair as tp
    model = tp.build()[0]
    direction = newton.Newton.direction

    def counted(self, *a, **k):
        SOLVES[0] += 1
        return direction(self, *a, **k)
    newton.Newton.direction, SOLVES[0] = counted, 0
    try:
        t0 = time.process_time()
        sol = bs.solve(model, steps=16)
        return int(sum(s["iterations"] for s in sol.stats)), time.process_time() - t0
    finally:
        newton.Newton.direction = direction


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


SCENES = dict(twisted_pair=twisted_pair, bundle19=bundle19, strand19=strand19)
MODES = ("penalty", "exact (before)", "exact (eager, full)", "exact (direct saddle)", "exact (augmented)", "exact")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="+", default=list(SCENES))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--profile", action="store_true")
    ap.add_argument("--modes", nargs="+", default=list(MODES), choices=MODES)
    a = ap.parse_args()
    print("| scene | stick | Newton it. | linear solves | time [s] | ms per linear solve | ratio to penalty |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for scene in a.scenes:
        ref = None
        for name in a.modes:
            try:
                with mode(name):
                    SCENES[scene]()                             # warm-up
                    runs = []
                    for _ in range(a.repeat):
                        runs.append(SCENES[scene]() + (SOLVES[0] if scene == "twisted_pair" else 1, dict(PARTS)))
            except Exception as e:      # noqa: BLE001  (a singular bordered matrix: a row of the table)
                print(f"| {scene} | {name} | failed: {type(e).__name__}: {e} | | | | |", flush=True)
                continue
            best = min(runs, key=lambda r: r[1])
            its, solves, t = runs[0][0], runs[0][2], best[1]
            PARTS.update(best[3])
            ms = 1e3 * t / max(solves, 1)
            ref = ms if ref is None else ref
            st = PARTS.get("stats", {})
            saddle = "" if not st.get("saddle_augmented") else (
                f"; GMRES {st['saddle_iterations'] / st['saddle_augmented']:.1f} it. a solve, "
                f"{st['saddle_fallbacks']} fallbacks")
            parts = "" if scene == "twisted_pair" else (
                f" (evaluation {PARTS['evaluate']:.3f}, Newton system {PARTS['matrix']:.3f}, factorisation and "
                f"solve {PARTS['solve']:.3f}, not lagged {PARTS['fresh']:.3f}; {PARTS['unknowns']} unknowns, "
                f"{PARTS['nnz']} non-zeros{saddle})")
            print(f"| {scene} | {name} | {its} | {solves} | {t:.3f}{parts} | {ms:.2f} | {ms / ref:.2f} |", flush=True)
        if a.profile:
            with mode("exact"):
                pr = cProfile.Profile()
                pr.enable()
                SCENES[scene]()
                pr.disable()
            pstats.Stats(pr, stream=sys.stdout).sort_stats("tottime").print_stats(25)


if __name__ == "__main__":
    main()
