"""Newton iterations of a real loaded step by parts, held tangent pattern on and off (issue 30).

For ``benchmarks/scaling.py --step-parts 19,37,61,strand-61 [--threads 1,2]``.  Each row is one child process
(``scaling.py --child step-parts NAME HOLD THREADS``): the scene of ``scaling_scenes`` stretched by
``scaling_scenes.STRAIN`` in one step (``bs.solve(steps=1)``), every wire end at the top moved along ``e_z``:

- ``19``, ``37``, ``61``: the bundles of ``scaling.bundle_model`` (issue 30's targets: 3002 / 5846 / 9638
  elements); their design overlap (a pre-stress, ~3e7 N at 19 wires) makes the solve's step 0 (the
  equilibrium at ``t = 0`` that releases it) a Newton sequence that does not converge (121 iterations at
  19 wires), with contact points entering and leaving at every iteration: its first ``BUNDLE_ITERATIONS``
  Newton iterations are run (the loop stopped from its callback), the sequence ``lagged_solves.py`` records;
- ``strand-19`` .. ``strand-61``: their overlap-free twins (``scaling_scenes.strand_model``), the whole step.

The linear solver is ``linsolve.Solver(lagged=False)`` (a factorisation per Newton iteration: the parts below
are then those of every iteration; the default lagged solves skip some factorisations, ``lagged_solves.py``),
the back-end ``auto`` (PARDISO at these sizes).  ``hold``: ``System.hold_pattern`` (``True``: the held
pattern, ``held_pattern.HeldPattern``; ``False``: the exact pattern of the active contact pairs, what ``main``
did).  ``threads``: MKL's/OpenMP's threads (PARDISO; the rest of the code is single-threaded).

Parts per Newton iteration: ``evaluation`` (``Problem.evaluate``: elements, contact, residual-only line-search
trials included), ``assembly`` (``Problem.tangent``, ``coupling``, ``bordered``), ``analysis`` (PARDISO phase
11), ``factorisation`` (phase 22), ``solve`` (phase 33 and its check), ``update`` and ``other`` (the rest of the
loop); CPU seconds (``time.process_time``) with one thread; with two threads CPU seconds count both threads, so
the parts are wall seconds (``time.perf_counter``) with CPU seconds in brackets (a shared machine: wall times
are noisier, and longer than the CPU time of one thread whenever the other core is busy).
``first``: the step's first iteration; ``later``: the median of the later ones.  Peak memory: ``ru_maxrss``.

Environment knobs of a child: ``STEP_PARTS_STICK=exact`` (every contact declaration's ``stick``: saddle-point
systems), ``HELD_RESET_SHARE`` (``held_pattern.RESET_SHARE``, for its tuning).
"""
import os
import time

import numpy as np

BUNDLE_ITERATIONS = 5
PARTS = ("evaluation", "assembly", "analysis", "factorisation", "solve", "update")
PHASES = {11: "analysis", 22: "factorisation", 33: "solve"}


class _Stop(Exception):
    pass


class _Clock:
    """CPU and wall seconds per part, accumulated; ``snapshot`` per Newton iteration."""

    def __init__(self):
        self.cpu = dict.fromkeys(PARTS, 0.0)
        self.wall = dict.fromkeys(PARTS, 0.0)
        self.stack = []

    def wrap(self, obj, name, part):
        orig = getattr(obj, name)
        clock = self

        def timed(*a, **k):
            if clock.stack:                       # nested (a part inside another): counted once, outside
                return orig(*a, **k)
            clock.stack.append(part)
            c0, w0 = time.process_time(), time.perf_counter()
            try:
                return orig(*a, **k)
            finally:
                clock.stack.pop()
                clock.cpu[part] += time.process_time() - c0
                clock.wall[part] += time.perf_counter() - w0
        setattr(obj, name, timed)

    def wrap_pardiso(self, cls):
        """Time PARDISO's phases: ``cls`` is ``linsolve._Pardiso`` (its ``_call``, ``self.ps.phase``)."""
        orig = cls._call
        clock = self

        def timed(handle, A, b):
            part = PHASES.get(int(handle.ps.phase), "solve")
            c0, w0 = time.process_time(), time.perf_counter()
            try:
                return orig(handle, A, b)
            finally:
                dc, dw = time.process_time() - c0, time.perf_counter() - w0
                clock.cpu[part] += dc
                clock.wall[part] += dw
                if clock.stack:                   # inside another timed part: counted here, not there
                    clock.cpu[clock.stack[-1]] -= dc
                    clock.wall[clock.stack[-1]] -= dw
        cls._call = timed


def measure(name, hold, threads, rss_mb):
    import beamsolver as bs
    import scaling_scenes as ss
    from beamsolver.assembly import system as system_mod
    from beamsolver.nonlinear import linsolve
    from beamsolver.nonlinear.problem import Problem
    from scaling import warm_up
    warm_up()
    system_mod.HOLD_PATTERN = {"True": True, "False": False, "auto": "auto"}[hold]
    if os.environ.get("HELD_RESET_SHARE"):          # (a knob of the held pattern's growth rule, for its tuning)
        from beamsolver.assembly import held_pattern
        held_pattern.RESET_SHARE = float(os.environ["HELD_RESET_SHARE"])
    linsolve.LAGGED = False
    if os.environ.get("STEP_PARTS_STICK"):          # e.g. "exact": every declaration's stick (saddle-point systems)
        add_contact = bs.Model.add_contact

        def with_stick(self, *a, **options):
            options.setdefault("stick", os.environ["STEP_PARTS_STICK"])
            return add_contact(self, *a, **options)
        bs.Model.add_contact = with_stick
    strand = name.startswith("strand")
    m, wires, length = ss.strand_model(name.split("-")[1]) if strand else ss.scene_model(name)
    for w in wires:
        m.prescribe(w.last, bs.motion.translation(lambda t: (0.0, 0.0, ss.STRAIN * length * t)))
    clock = _Clock()
    clock.wrap(Problem, "evaluate", "evaluation")
    for f in ("tangent", "coupling", "bordered"):
        clock.wrap(Problem, f, "assembly")
    clock.wrap(Problem, "update", "update")
    for f in ("solve", "apply"):
        clock.wrap(linsolve._PardisoFactor, f, "solve")
    clock.wrap_pardiso(linsolve._Pardiso)
    analyses = []
    orig_fresh = linsolve.Solver.fresh

    def fresh(self, K, saddle=False):
        out = orig_fresh(self, K, saddle)
        analyses.append((self.stats["analyses"], K.nnz))
        return out
    linsolve.Solver.fresh = fresh
    stamps = []

    def callback(d):
        stamps.append((time.process_time(), time.perf_counter(), dict(clock.cpu), dict(clock.wall), d["t"]))
        if not strand and len(stamps) >= BUNDLE_ITERATIONS + 1:
            raise _Stop
    c0, w0 = time.process_time(), time.perf_counter()
    status = "ok"
    try:
        sol = bs.solve(m, steps=1, verbose=False, callback=callback, min_step_ratio=ss.STEP_FLOOR)
        iterations = int(sol.stats[-1]["iterations"])
    except _Stop:
        status = f"first {BUNDLE_ITERATIONS}"
        iterations = BUNDLE_ITERATIONS
    except Exception as e:                      # noqa: BLE001  (reported)
        status = type(e).__name__
        iterations = len(stamps)
    total_cpu, total_wall = time.process_time() - c0, time.perf_counter() - w0
    out = dict(scene=name, hold=hold, threads=int(threads), status=status, iterations=iterations,
               step_cpu=total_cpu, step_wall=total_wall, rss_mb=rss_mb(),
               analyses=analyses[-1][0] if analyses else 0, factorisations=len(analyses),
               nnz_last=analyses[-1][1] if analyses else 0)
    # per iteration: between consecutive callbacks of the loaded step (the first callback is at its start)
    its = []
    for a, b in zip(stamps, stamps[1:]):
        if not (a[4] == b[4] and (a[4] > 0.0 or not strand)):     # the strands: the loaded step only
            continue
        row = dict(cpu=b[0] - a[0], wall=b[1] - a[1])
        for p in PARTS:
            row[p] = b[2][p] - a[2][p]
            row[p + "_wall"] = b[3][p] - a[3][p]
        row["other"] = row["cpu"] - sum(row[p] for p in PARTS)
        row["other_wall"] = row["wall"] - sum(row[p + "_wall"] for p in PARTS)
        its.append(row)
    keys = list(its[0]) if its else []
    out["first"] = its[0] if its else {}
    out["later"] = {k: float(np.median([r[k] for r in its[1:]])) for k in keys} if len(its) > 1 else {}
    out["n_timed"] = len(its)
    return out


def report(rows, table):
    """Markdown: one row per (scene, hold, threads), the first and the later iterations."""
    head = ["scene", "threads", "held pattern", "status (its)", "analyses / factorisations", "iteration",
            "evaluation", "assembly", "analysis", "factorisation", "solve", "update", "other", "total",
            "total wall", "peak MB"]
    body = []

    def g(v):
        return "-" if v is None or not np.isfinite(v) else f"{v:.3g}"
    for r in rows:
        if "error" in r:
            body.append([r["scene"], r.get("threads", "-"), r.get("hold", "-"), r["error"]] + ["-"] * (len(head) - 4))
            continue
        for which in ("first", "later"):
            it = r[which]
            if not it:
                continue
            wall = r["threads"] > 1        # wall s (CPU s of both threads)
            parts = [f"{g(it[p + '_wall'])} ({g(it[p])})" if wall else g(it[p]) for p in PARTS + ("other",)]
            body.append([r["scene"], r["threads"], r["hold"], f"{r['status']} ({r['iterations']})",
                         f"{r['analyses']} / {r['factorisations']}", which if which == "first" else
                         f"later (median of {r['n_timed'] - 1})"] + parts
                        + [g(it["cpu"]), g(it["wall"]), f"{r['rss_mb']:.0f}"])
    return table(head, body)
