"""Exact stick (``stick="exact"``) against the penalty stick on the contact examples: Newton
iterations, augmented-Lagrangian updates, wall time and the answer each example prints.

Each case runs in its own process with a time limit (``--limit`` seconds, default 170).
``python benchmarks/exact_stick.py [case ...]``: cases ``shear_lag10 shear_lag20 patch capstan
rolling three_wires twisted_pair`` (default all); ``--penalty-t``: the augmentation penalty of the exact
runs (default: the normal penalty); prints a markdown table.
"""
import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CASES = {
    "shear_lag10": ("shear_lag", "sol, w, a = m.main(n_wire=10, **opt); x, N = m.axial_force(sol, w); "
                    "ans = f'slip zone {m.slip_zone(sol, w):.4f} (0.5)'"),
    "shear_lag20": ("shear_lag", "sol, w, a = m.main(n_wire=20, **opt); x, N = m.axial_force(sol, w); "
                    "ans = f'slip zone {m.slip_zone(sol, w):.4f} (0.5)'"),
    "patch": ("contact_patch", "sol, s, ma = m.main(**opt); p, t, st = m.tractions(sol); "
              "ans = f'pressure spread {p.ptp() / 100:.3g} q, all stick {bool(st.all())}, "
              "slip {m.relative_slip(sol, s, ma):.2e} m'"),
    "capstan": ("capstan", "ratio, exact, sol = m.main(**opt); ans = f'ratio {ratio:.4f} (exp {exact:.4f})'"),
    "rolling": ("rolling", "sol = m.bs.solve(m.build(**opt)[0], steps=11); ans = ''"),
    "three_wires": ("three_wires", "sol = m.main(**opt)[0]; ans = ''"),
    "twisted_pair": ("twisted_pair", "model = m.build(**opt)[0]; sol = m.bs.solve(model, steps=16); ans = ''"),
}

SNIPPET = """
import sys, time, json
sys.path.insert(0, {ex!r})
import numpy as np
import {mod} as m
opt = {opt!r}
t0 = time.perf_counter()
{code}
print(json.dumps(dict(iterations=int(np.sum(sol.iterations)), steps=len(sol.stats),
                      augmentations=int(sum(s.get('augmentations') or 0 for s in sol.stats)),
                      wall=time.perf_counter() - t0, answer=ans)))
"""


def run(case, stick, limit, penalty_t=None):
    mod, code = CASES[case]
    opt = {"stick": stick}
    if case == "capstan" and stick == "exact":
        opt["penalty_t"] = None          # the example's 1e6 is a stick penalty; exact uses the normal one
    if penalty_t is not None and stick == "exact":
        opt["penalty_t"] = penalty_t
    src = SNIPPET.format(ex=str(ROOT / "examples"), mod=mod, opt=opt, code=code)
    t0 = time.perf_counter()
    try:
        p = subprocess.run([sys.executable, "-c", src], capture_output=True, text=True, timeout=limit,
                           env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    except subprocess.TimeoutExpired:
        return dict(status=f"> {limit:.0f} s")
    if p.returncode:
        return dict(status="failed: " + p.stderr.strip().splitlines()[-1][:120])
    out = json.loads(p.stdout.strip().splitlines()[-1])
    out["status"] = "ok"
    out["process"] = time.perf_counter() - t0
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("cases", nargs="*", default=list(CASES))
    ap.add_argument("--limit", type=float, default=170.0)
    ap.add_argument("--penalty-t", type=float, default=None, help="augmentation penalty of the exact runs")
    a = ap.parse_args()
    print("| case | stick | status | steps | Newton iterations | AL updates | solve wall [s] | answer |")
    print("|---|---|---|---|---|---|---|---|")
    for case in a.cases:
        for stick in ("penalty", "exact"):
            r = run(case, stick, a.limit, a.penalty_t)
            if r["status"] == "ok":
                print(f"| {case} | {stick} | ok | {r['steps']} | {r['iterations']} | {r['augmentations']} | "
                      f"{r['wall']:.1f} | {r['answer']} |", flush=True)
            else:
                print(f"| {case} | {stick} | {r['status']} | | | | | |", flush=True)


if __name__ == "__main__":
    main()
