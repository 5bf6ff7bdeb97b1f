"""Where the long-lay strand's bending cycle spends its Newton iterations, and the soft modes of its frictionless pull
(issue 27, session 9; docs/benchmarks.md "Strand bending, session 9").

    python benchmarks/strand_long_lay.py --phases [--lays 4] [--elements 48] [--lay 229.2] [--t-end 6] [--shift 1e-3]
    python benchmarks/strand_long_lay.py --modes [--lays 4] [--elements 24] [--lay 229.2] [--scale torsion 100]

``--phases``: the example's cycle (``strand_bending.run``, default options) with every Newton attempt counted by phase
of the history (step 0, pull, virgin branch, the two half cycles): attempts, failed ones, Newton directions (of them in
failed attempts), residual evaluations of the line searches and the iterations whose line search tried 6 or more
lengths (the crawl); ``--shift``: exact stick's Levenberg shift ``newton.LM_SHIFT`` (0: off, before session 9).
``--modes``: the frictionless strand (``mu = 0``) pulled to ``T`` in 4 steps, the stable-branch
rule off, and the 3 lowest scaled eigenvalues of its tangent at ``t = 1`` (``modes.lowest_modes``), with the lowest
mode's energy split between the elements and the contact; ``--scale what factor`` scales the sections' shear,
torsion or bending stiffness.  CPU seconds by ``time.process_time`` (the machine is shared).
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import beamsolver as bs  # noqa: E402
import strand_bending as sb  # noqa: E402
from beamsolver.nonlinear import newton  # noqa: E402

SCALES = dict(shear=(1, 2), torsion=(3,), bending=(4, 5))
PHASES = ("step 0", "pull (0, 1]", "virgin (1, 2]", "down (2, 4]", "up (4, 6]")


def _phase(t):
    return PHASES[0] if t == 0 else PHASES[1 + int(np.searchsorted([1.0, 2.0, 4.0], t - 1e-9))]


def phases(lays, elements, lay, t_end=6.0):
    """Print the table of ``--phases``."""
    attempts = []
    iterate, backtrack = newton.Newton.iterate, newton.Newton.backtrack

    def counted_iterate(self, H, t, constraint):
        attempts.append(dict(t=t, directions=0, trials=0, crawl=0, failed=False))
        try:
            return iterate(self, H, t, constraint)
        except bs.ConvergenceError:
            raise
        except Exception:
            attempts[-1]["failed"] = True
            raise

    def counted_backtrack(self, H, dz, ev0, scales, t):
        n = [0]
        evaluate = self.evaluate
        self.evaluate = lambda *a, **k: n.__setitem__(0, n[0] + 1) or evaluate(*a, **k)
        try:
            return backtrack(self, H, dz, ev0, scales, t)
        finally:
            del self.evaluate
            a = attempts[-1]
            a["directions"] += 1
            a["trials"] += n[0]
            a["crawl"] += n[0] >= 6
    newton.Newton.iterate, newton.Newton.backtrack = counted_iterate, counted_backtrack
    try:
        res = sb.run(lays, elements, lay=lay * 1e-3, t_end=t_end)
    finally:
        newton.Newton.iterate, newton.Newton.backtrack = iterate, backtrack
    print(f"{lays:g} lays, {elements} el/lay, lay {lay:g} mm: {res['iterations']} Newton iterations, {res['cutbacks']} "
          f"cut-backs, {res['cpu']:.1f} s CPU")
    print("| phase | attempts | failed | Newton directions | in failed attempts | line-search evaluations "
          "| iterations with >= 6 |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for p in PHASES:
        rows = [a for a in attempts if _phase(a["t"]) == p]
        if rows:
            print(f"| {p} | {len(rows)} | {sum(a['failed'] for a in rows)} | {sum(a['directions'] for a in rows)} "
                  f"| {sum(a['directions'] for a in rows if a['failed'])} | {sum(a['trials'] for a in rows)} "
                  f"| {sum(a['crawl'] for a in rows)} |")


def modes(lays, elements, lay, scale=None):
    """Print the line of ``--modes``."""
    from beamsolver.nonlinear.modes import lowest_modes
    from beamsolver.nonlinear.problem import Problem
    from beamsolver.stepping import stable_branch
    secs = None
    if scale is not None:
        secs = []
        for R in (sb.RC, sb.RW):
            s = bs.Section.circular(radius=R, E=sb.E, nu=sb.NU)
            for i in SCALES[scale[0]]:
                s.C[i, i] *= float(scale[1])
            secs.append(s)
    model, *_ = sb.build(lays, elements, mu=0.0, lay=lay * 1e-3, sections=None if secs is None else tuple(secs))
    c0 = time.process_time()
    enabled, stable_branch.ENABLED = stable_branch.ENABLED, False
    try:
        sol = bs.solve(model, steps=4, t_end=1.0, check_stability=False, verbose=False)
    finally:
        stable_branch.ENABLED = enabled
    pb = Problem.from_model(model)
    ev = pb.evaluate(sol.poses[-1], 1.0)
    K, Kel = pb.tangent(ev), pb.system.matrix(ev.kvals, None)
    lam, phi = lowest_modes(K, 3)
    p = phi[:, 0]
    print(f"| {lays:g} | {elements} | {lay:g} | {'-' if scale is None else ' x'.join(scale)} | "
          f"{', '.join(f'{x:.3g}' for x in lam)} | {p @ (Kel @ p):.3g} | {p @ (K @ p) - p @ (Kel @ p):.3g} | "
          f"{time.process_time() - c0:.1f} |")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--phases", action="store_true")
    ap.add_argument("--modes", action="store_true")
    ap.add_argument("--lays", type=float, default=4.0)
    ap.add_argument("--elements", type=int, default=None)
    ap.add_argument("--lay", type=float, default=229.2, help="lay length [mm]")
    ap.add_argument("--t-end", type=float, default=6.0)
    ap.add_argument("--scale", nargs=2, default=None, metavar=("WHAT", "FACTOR"))
    ap.add_argument("--shift", type=float, default=None, help="newton.LM_SHIFT (default: the library's; 0: off)")
    a = ap.parse_args()
    if a.shift is not None:
        newton.LM_SHIFT = a.shift
    if a.modes:
        print("| lays | el/lay | lay [mm] | stiffness scaled | lowest scaled eigenvalues at t = 1 | lowest mode: "
              "elements' energy | contact's | CPU [s] |")
        print("|---:|---:|---:|---|---|---:|---:|---:|")
        modes(a.lays, a.elements or 24, a.lay, a.scale)
    if a.phases or not a.modes:
        phases(a.lays, a.elements or 48, a.lay, a.t_end)
