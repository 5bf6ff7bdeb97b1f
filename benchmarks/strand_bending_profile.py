"""Where the strand bending example's CPU goes (issue 27): per part, per step, failed attempts apart.

Runs ``examples/strand_bending.py``'s cyclic history and its two stiffness checks (frictionless, tied) with
``time.process_time`` counters wrapped around the solver's parts: the problem's evaluation (its contact share from
``Evaluation.timings``), the Newton direction (system, factorisation and solve), the line search (with its
evaluations); every Newton attempt (a step try) is timed and counted, failed ones apart.  Prints the parts table,
the steps table (t, dt, iterations, failed tries) and the answer-quality table of ``compare``.

    python benchmarks/strand_bending_profile.py [--lays 4] [--elements 48] [--steps 4] [--check-steps 1] [--no-checks]
"""
import argparse
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import strand_bending as sb  # noqa: E402
from beamsolver.nonlinear import newton as newton_mod, problem as problem_mod  # noqa: E402

CPU = defaultdict(float)          # part -> CPU s
COUNT = defaultdict(int)          # part -> calls
ATTEMPTS = []                     # (run, t, ok, iterations, CPU s)
_STATE = dict(run="", depth=0, attempt_its=0)


def _timed(owner, name, part):
    """Wrap ``owner.name`` to add its CPU time to ``CPU[part]`` (outermost call only per part)."""
    f = getattr(owner, name)
    active = {"n": 0}

    def wrapper(*a, **k):
        if active["n"]:
            return f(*a, **k)
        active["n"] += 1
        t0 = time.process_time()
        try:
            return f(*a, **k)
        finally:
            CPU[part] += time.process_time() - t0
            COUNT[part] += 1
            active["n"] -= 1
    setattr(owner, name, wrapper)


def install():
    """The counters around evaluation, Newton system, factorisation, solves, line search and attempts."""
    P, N = problem_mod.Problem, newton_mod.Newton
    ev_orig = P.evaluate

    def evaluate(self, H, t, tangent=True):
        t0 = time.process_time()
        ev = ev_orig(self, H, t, tangent=tangent)
        dt = time.process_time() - t0
        CPU["evaluation"] += dt
        COUNT["evaluation"] += 1
        # split by the problem's own (wall) timings, scaled to the CPU measured
        tot = sum(ev.timings.values())
        if tot > 0:
            for name, s in ev.timings.items():
                CPU[f"  of which {name} (wall share)"] += dt * min(1.0, s / max(tot, 1e-30)) * min(1.0, tot / max(dt, 1e-30))
        return ev
    P.evaluate = evaluate
    _timed(N, "direction", "Newton direction (system, factorisation, solve)")
    _timed(N, "backtrack", "line search (residual backtracking)")
    _timed(N, "_damped", "line search (damped trial)")
    step_orig = N.step

    def step(self, H, t, H_target, t_prev=None):
        t0 = time.process_time()
        n0 = COUNT["Newton direction (system, factorisation, solve)"]
        try:
            out = step_orig(self, H, t, H_target, t_prev)
        except Exception:
            ATTEMPTS.append((_STATE["run"], t, False, COUNT["Newton direction (system, factorisation, solve)"] - n0,
                             time.process_time() - t0))
            raise
        ATTEMPTS.append((_STATE["run"], t, True, out[2]["iterations"], time.process_time() - t0))
        return out
    N.step = step


def solve_cpu(run, **kw):
    _STATE["run"] = run
    t0 = time.process_time()
    res = sb.run(**kw)
    return res, time.process_time() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lays", type=float, default=4)
    ap.add_argument("--elements", type=int, default=48)
    ap.add_argument("--steps", type=int, default=sb.STEPS)
    ap.add_argument("--amplitude", type=float, default=sb.AMPLITUDE)
    ap.add_argument("--no-checks", action="store_true")
    ap.add_argument("--check-steps", type=int, default=sb.CHECK_STEPS, help="steps per unit t of the checks")
    a = ap.parse_args()
    install()
    runs = [("cyclic", dict(lays=a.lays, elements_per_lay=a.elements, amplitude=a.amplitude, steps=a.steps))]
    if not a.no_checks:
        cs = a.steps if a.check_steps is None else a.check_steps
        runs += [("frictionless", dict(lays=a.lays, elements_per_lay=a.elements, amplitude=a.amplitude,
                                       steps=cs, t_end=2.0, mu=0.0)),
                 ("tied", dict(lays=a.lays, elements_per_lay=a.elements, amplitude=a.amplitude, steps=cs,
                               t_end=2.0, tied=True))]
    total, results = {}, {}
    for name, kw in runs:
        res, cpu = solve_cpu(name, lay=sb.LAY_UJ, **kw)      # the Utting & Jones lay of the recorded profiles
        total[name], results[name] = cpu, res
        print(f"{name}: {cpu:.1f} CPU s, {res['iterations']} iterations, {res['cutbacks']} cut-backs", flush=True)
    print(f"\nstrand {a.lays} lays, {a.elements} el/lay, {a.steps} steps per unit t; CPU s (time.process_time)\n")
    print("| part | CPU s | calls |")
    print("|---|---:|---:|")
    for part in sorted(CPU, key=lambda p: -CPU[p]):
        print(f"| {part} | {CPU[part]:.1f} | {COUNT.get(part, '')} |")
    fail = [x for x in ATTEMPTS if not x[2]]
    print(f"| failed attempts (all parts) | {sum(x[4] for x in fail):.1f} | {len(fail)} |")
    ok = [x for x in ATTEMPTS if x[2]]
    print(f"| converged attempts (all parts) | {sum(x[4] for x in ok):.1f} | {len(ok)} |")
    for name in total:
        print(f"| run {name} (whole) | {total[name]:.1f} | |")
    print("\n| run | t | ok | iterations | CPU s |")
    print("|---|---:|---|---:|---:|")
    for run, t, ok, its, cpu in ATTEMPTS:
        print(f"| {run} | {t:.4f} | {'yes' if ok else 'FAILED'} | {its} | {cpu:.1f} |")
    res = results["cyclic"]
    th, rows = sb.compare(res)
    if not a.no_checks:
        for name, key in (("frictionless", "EI_min"), ("tied", "EI_max")):
            r = results[name]
            j = np.flatnonzero(r["times"] > 1.0)[-1]
            EI = r["M"][j] / r["kappa"][j]
            ref = sb.theory(r["F"], lay=sb.LAY_UJ)[key]
            rows.append((f"EI {name} [N m^2]", ref, EI, EI / ref - 1))
    print("\n| quantity | theory | model | model / theory - 1 |")
    print("|---|---:|---:|---:|")
    for name, x, y, e in rows:
        print(f"| {name} | {x:.5g} | {y:.5g} | {e:+.3g} |")


if __name__ == "__main__":
    main()
