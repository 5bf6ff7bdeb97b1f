"""Peak resident memory of a real loaded step, stage by stage (issue 30: where a strand's peak is).

``python benchmarks/step_memory.py [--scene strand-61] [--hold True] [--tracemalloc]``

Runs the step of ``step_parts.py`` (the scene of ``scaling_scenes``, stretched in one step, ``bs.solve(steps=1)``, or ``--steps N``, each loaded step its own phase,
``linsolve.LAGGED = False``, or ``--lagged auto`` (the default solver's), ``System.hold_pattern`` ``--hold``; ``strand-N``: the overlap-free strands, the whole
step; ``19``/``37``/``61``: the bundles' first ``step_parts.BUNDLE_ITERATIONS`` iterations) with its stages wrapped:
``Problem.evaluate`` (with tangent / residual only), ``Problem.augmented_system`` (``K'``, ``A``),
``Problem.tangent`` / ``linear_system`` (other paths), PARDISO's phases (``linsolve._Pardiso._call``: 11 analysis,
22 factorisation, 33 solve), ``Augmented.solve`` outside them (GMRES), ``Problem.commit`` / ``begin_step``, parts of ``ContactSystem`` (``CONTACT_STAGES``); the rest
is ``other``.  The peak of ``/proc/self/status`` ``VmHWM`` (reset by writing ``5`` to ``/proc/self/clear_refs``) is
charged to the innermost stage running, separately for step 0 (``t = 0``; its second attempt, without exact stick's friction, apart) and the loaded
step (``t > 0``); the table
gives, per stage, its largest peak, the resident memory ``VmRSS`` at its start then, and how often it ran.  With
``--tracemalloc``: numpy's (Python's) traced peak per stage too (slow: ~2x).  ``--set module.NAME=VALUE``: a knob of
``beamsolver`` for the run (before / after).  (The resets of ``VmHWM`` reset ``ru_maxrss`` too: the run's peak is the
largest of the stages'.)  One thread (MKL pinned).  Linux only.
"""
import math
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, memory_status, reset_peak, single_thread, table  # noqa: E402

single_thread()

import numpy as np  # noqa: E402


class _Meter:
    """Peaks charged to the innermost running stage, per (phase, stage)."""

    def __init__(self, traced):
        self.stack = ["other"]
        self.phase = "step 0"
        self.peak = {}
        self.traced = traced
        self.rss_at_start = 0.0
        if traced:
            import tracemalloc
            tracemalloc.start()
            self.tm = tracemalloc

    def charge(self):
        s = memory_status()
        key = (self.phase, self.stack[-1])
        row = self.peak.setdefault(key, dict(peak=0.0, rss=0.0, n=0, traced=0.0))
        if s["VmHWM"] > row["peak"]:
            row["peak"], row["rss"] = s["VmHWM"], self.rss_at_start
        if self.traced:
            row["traced"] = max(row["traced"], self.tm.get_traced_memory()[1] / 2 ** 20)
            self.tm.reset_peak()
        reset_peak()
        return s["VmRSS"]

    def enter(self, name):
        self.rss_at_start = self.charge()
        self.stack.append(name)
        self.peak.setdefault((self.phase, name), dict(peak=0.0, rss=0.0, n=0, traced=0.0))["n"] += 1

    def leave(self):
        self.rss_at_start = self.charge()
        self.stack.pop()

    def wrap(self, obj, attr, name):
        orig = getattr(obj, attr)
        meter = self

        def wrapped(*a, **k):
            label = name(*a, **k) if callable(name) else name
            meter.enter(label)
            try:
                return orig(*a, **k)
            finally:
                meter.leave()
        setattr(obj, attr, wrapped)


CONTACT_STAGES = ("commit", "results", "nodal_results", "pairs", "_local_blocks", "_mortar", "_kernels",
                  "_params", "_open_points")
PHASE_NAMES = {11: "PARDISO analysis (11)", 22: "PARDISO factorisation (22)", 33: "PARDISO solve (33)",
               0: "PARDISO release (0)", -1: "PARDISO release (-1)"}


def main(argv):
    import argparse
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="strand-61")
    ap.add_argument("--hold", default="True", choices=("True", "False", "auto"))
    ap.add_argument("--tracemalloc", action="store_true")
    ap.add_argument("--lagged", default="off", choices=("off", "auto", "on"),
                    help="linsolve.LAGGED for the run (off: step_parts' mode, the issue-30 target's; auto: the default)")
    ap.add_argument("--steps", type=int, default=1,
                    help="loaded steps of the stretch (bs.solve(steps=)); with more than one, each its own phase")
    ap.add_argument("--set", action="append", default=[], metavar="MODULE.NAME=VALUE",
                    help="a knob of beamsolver for the run (A/B), e.g. model.buffers.RELEASE_AT_COMMIT=False")
    a = ap.parse_args(argv)
    import importlib
    for item in a.set:
        name, value = item.split("=", 1)
        mod, attr = name.rsplit(".", 1)
        setattr(importlib.import_module("beamsolver." + mod), attr, eval(value, {}))
    import beamsolver as bs
    import scaling_scenes as ss
    from scaling import warm_up
    from step_parts import BUNDLE_ITERATIONS
    from beamsolver.assembly import system as system_mod
    from beamsolver.nonlinear import augmented, linsolve
    from beamsolver.nonlinear.problem import Problem
    warm_up()
    system_mod.HOLD_PATTERN = {"True": True, "False": False, "auto": "auto"}[a.hold]
    linsolve.LAGGED = {"off": False, "auto": "auto", "on": True}[a.lagged]
    strand = a.scene.startswith("strand")
    m, wires, length = ss.strand_model(a.scene.split("-")[1]) if strand else ss.scene_model(a.scene)
    for w in wires:
        m.prescribe(w.last, bs.motion.translation(lambda t: (0.0, 0.0, ss.STRAIN * length * t)))
    meter = _Meter(a.tracemalloc)       # (the peak so far: imports, warm-up, the model; charged to ``other``)

    friction = [True]
    exact_friction = Problem.exact_friction

    def exact_friction_(self, flag):       # step 0's second attempt (without exact stick's friction): its own phase
        friction[0] = bool(flag)
        return exact_friction(self, flag)
    Problem.exact_friction = exact_friction_

    def on_t(t):
        if t == 0.0:
            meter.phase = "step 0" if friction[0] else "step 0, no exact friction"
        else:
            meter.phase = "loaded step" if a.steps == 1 else f"loaded step {max(1, math.ceil(t * a.steps - 1e-9))}"

    def ev_name(self, H, t, tangent=True):
        on_t(t)
        return "evaluate (tangent)" if tangent else "evaluate (residual)"
    meter.wrap(Problem, "evaluate", ev_name)
    meter.wrap(Problem, "augmented_system", "augmented_system (K', A)")
    meter.wrap(Problem, "tangent", "tangent (other paths)")
    meter.wrap(Problem, "linear_system", "linear_system (other paths)")
    meter.wrap(Problem, "commit", "commit")
    meter.wrap(Problem, "begin_step", "begin_step")
    meter.wrap(augmented.Augmented, "solve", "Augmented.solve (GMRES, outside PARDISO)")
    from beamsolver.contact.system import ContactSystem
    for f in CONTACT_STAGES:
        meter.wrap(ContactSystem, f, f"ContactSystem.{f}")
    meter.wrap(linsolve._Pardiso, "_call", lambda handle, A, b: PHASE_NAMES.get(int(handle.ps.phase), "PARDISO other"))
    calls = []

    class _Stop(Exception):
        pass

    def callback(d):
        calls.append(d["t"])
        if not strand and len(calls) >= BUNDLE_ITERATIONS + 1:
            raise _Stop
    status = "ok"
    try:
        bs.solve(m, steps=a.steps, verbose=False, callback=callback, min_step_ratio=ss.STEP_FLOOR)
    except _Stop:
        status = f"first {BUNDLE_ITERATIONS}"
    meter.enter("end")
    meter.leave()
    top = max(r["peak"] for r in meter.peak.values())
    rows = []
    for (phase, stage), r in sorted(meter.peak.items(), key=lambda kv: -kv[1]["peak"]):
        if r["peak"] == 0.0:
            continue
        row = [phase, stage, r["n"], f"{r['rss']:.0f}", f"{r['peak']:.0f}"]
        if a.tracemalloc:
            row.append(f"{r['traced']:.0f}")
        rows.append(row)
    head = ["phase", "stage", "calls", "VmRSS at its start (MB)", "peak VmHWM (MB)"]
    if a.tracemalloc:
        head.append("traced peak (MB)")
    sets = "".join(f" --set {x}" for x in a.set)
    lag = f" --lagged {a.lagged}" if a.lagged != "off" else ""
    lag += f" --steps {a.steps}" if a.steps != 1 else ""
    print(f"`python benchmarks/step_memory.py --scene {a.scene} --hold {a.hold}{lag}{sets}"
          f"{' --tracemalloc' if a.tracemalloc else ''}` ({machine()}; status {status}, "
          f"{sum(1 for t in calls if t > 0)} callbacks in the loaded step; peak of the run {top:.0f} MB)\n")
    print(table(head, rows))


if __name__ == "__main__":
    main(sys.argv[1:])
