"""Digests of every step's poses: does a change keep the results bit for bit?

``python benchmarks/pose_digests.py [scenes]`` (default ``tp,three_wires,strand-19``) solves each scene with
its default options and prints its Newton iterations per step and a SHA-1 digest (16 hex digits) of the
poses of every recorded step, in order.  Two trees give the same digest only if every pose of every step is
the same float; a change meant to keep the results (a faster path to the same numbers) shows it here, a
change of the round-off shows a new digest and then needs its pose differences and iterations reported.

Scenes: ``tp`` (the main job's model, ``examples/twisted_pair.py``, 16 steps; ``tpN``: it at N el/wire),
``strand-N`` (the overlap-free N-wire strand of ``benchmarks/scaling_scenes.py``, one loaded step), or the
name of a module of ``examples/`` with a ``build()`` (its ``solve_options`` if it has them); a run that stops with
``ConvergenceError`` gives the digest of the steps that converged and says where.  CPU time per scene on stderr.
"""
import hashlib
import importlib
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "examples"), str(ROOT / "benchmarks")]

import beamsolver as bs  # noqa: E402


def digest(sol):
    """SHA-1 (16 hex digits) of the poses of every step of ``sol``, in order."""
    h = hashlib.sha1()
    for k in range(len(sol.times)):
        h.update(np.ascontiguousarray(sol.poses[k]).tobytes())
    return h.hexdigest()[:16]


def solve(scene):
    """The scene's solution with its default options."""
    if scene == "tp" or scene[:2] == "tp" and scene[2:].isdigit():
        import twisted_pair
        kw = dict(n_elements=int(scene[2:])) if scene[2:] else {}
        return bs.solve(twisted_pair.build(**kw)[0], steps=16, verbose=False)
    if scene.startswith("strand-"):
        import scaling_scenes as ss
        model, wires, length = ss.strand_model(scene.split("-", 1)[1])
        for w in wires:
            model.prescribe(w.last, bs.motion.translation(lambda t: (0.0, 0.0, ss.STRAIN * length * t)))
        return bs.solve(model, steps=1, verbose=False, min_step_ratio=ss.STEP_FLOOR)
    mod = importlib.import_module(scene)
    return bs.solve(mod.build()[0], **dict(dict(verbose=False), **getattr(mod, "solve_options", {})))


def main(scenes):
    for scene in scenes:
        t0 = time.process_time()
        stop = ""
        try:
            sol = solve(scene)
        except bs.ConvergenceError as e:       # the steps that converged, and where it stopped
            sol, stop = e.solution, f", stopped at t = {e.solution.times[-1]:.6g}"
        its = [s["iterations"] for s in sol.stats]
        print(f"{scene}: iterations {its} (total {sum(its)}), digest {digest(sol)}{stop}", flush=True)
        print(f"{scene}: {time.process_time() - t0:.2f} s CPU", file=sys.stderr)


if __name__ == "__main__":
    main((sys.argv[1] if len(sys.argv) > 1 else "tp,three_wires,strand-19").split(","))
