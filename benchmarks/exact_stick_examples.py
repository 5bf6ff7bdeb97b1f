"""Exact stick (semi-smooth Newton, ``stick="exact"``) against the penalty stick on the contact examples:
Newton iterations, cut-backs and wall time of each (issue 26: at most 1.5 times the penalty's iterations).

    python benchmarks/exact_stick_examples.py [--c 1e-3 1] [--scenes twisted_pair three_wires ...]
        [--integration points segments] [--saddle auto direct augmented]

``--c``: ``penalty_t`` of the exact runs as a fraction of each declaration's normal penalty (default: the
library's default, ``EXACT_C``).  Every ``add_contact`` of a scene gets the mode through a wrapper of
``Model.add_contact``, as does ``--integration`` (line contact's, each scene run with each).  ``--saddle``: how the
exact runs solve their saddle-point Newton systems (``auto``: the library's rule, through ``A = K' + Kq E Kl`` from
``augmented.MIN_UNKNOWNS`` free unknowns, directly below; ``augmented``: through ``A`` at any size; ``direct``:
PARDISO / SuperLU on the bordered system, before; ``nonlinear/augmented.py``), each run with each.  Rows
print as they finish (markdown table); CPU time by ``time.process_time`` (the machine is shared).
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import beamsolver as bs  # noqa: E402


def _twisted_pair():
    import twisted_pair
    return bs.solve(twisted_pair.build()[0], steps=16)


def _three_wires():
    import three_wires
    return three_wires.main()[0]


def _shear_lag():
    import shear_lag
    return shear_lag.main(n_wire=20)[0]


def _contact_patch():
    import contact_patch
    model = contact_patch.build()[0]
    return bs.solve(model, **contact_patch.solve_options)


def _rolling():
    import rolling
    return rolling.main()[-1]


def _capstan():
    import capstan
    return capstan.main()[-1]


def _twisted_pair_extreme():
    import twisted_pair_extreme
    return bs.solve(twisted_pair_extreme.build()[0], steps=16)


def _plectoneme():
    import plectoneme
    return bs.solve(plectoneme.build()[0], **plectoneme.solve_options)


SCENES = dict(twisted_pair=_twisted_pair, three_wires=_three_wires, shear_lag=_shear_lag,
              contact_patch=_contact_patch, rolling=_rolling, capstan=_capstan,
              twisted_pair_extreme=_twisted_pair_extreme, plectoneme=_plectoneme)


def run(scene, stick, c=None, integration=None, saddle="auto"):
    """``(iterations, cut-backs, wall s, message, CPU s)`` of ``scene`` with every declaration's ``stick`` (and
    ``penalty_t = c x`` its normal penalty when given; ``saddle``: ``--saddle``)."""
    from beamsolver.nonlinear import augmented
    orig = bs.Model.add_contact

    def add_contact(self, slave, master, mu=0.0, penalty=None, **options):
        options.setdefault("stick", stick)
        if integration is not None:
            options.setdefault("integration", integration)
        if c is not None and stick == "exact":
            from beamsolver.contact.law import default_penalty
            secs = [b.section for b in (list(slave) if isinstance(slave, (list, tuple)) else [slave])
                    + (list(master) if isinstance(master, (list, tuple)) else [master])]
            pen = penalty if penalty is not None else min(default_penalty(a, b) for a in secs for b in secs)
            options.setdefault("penalty_t", c * pen)
        return orig(self, slave, master, mu=mu, penalty=penalty, **options)

    bs.Model.add_contact = add_contact
    augmented.ENABLED, min_unknowns = saddle != "direct", augmented.MIN_UNKNOWNS
    if saddle == "augmented":
        augmented.MIN_UNKNOWNS = 0
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        sol = SCENES[scene]()
        stats = sol.stats
        its = int(sum(s["iterations"] for s in stats))
        cuts = int(sum(s.get("cutbacks", 0) for s in stats))
        return its, cuts, time.perf_counter() - t0, "t = %.3g" % sol.times[-1], time.process_time() - c0
    except bs.ConvergenceError as e:
        sol = e.solution
        its = int(sum(s["iterations"] for s in sol.stats)) if sol is not None else 0
        return (its, 0, time.perf_counter() - t0, "failed at t = %.3g" % (sol.times[-1] if sol is not None else np.nan),
                time.process_time() - c0)
    finally:
        bs.Model.add_contact = orig
        augmented.ENABLED, augmented.MIN_UNKNOWNS = True, min_unknowns


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="+", default=list(SCENES))
    ap.add_argument("--exact-c", type=float, nargs="+", default=[None],
                    help="contact.system.EXACT_C of the exact runs (the default c's factor of EI / L_e^4)")
    ap.add_argument("--c", type=float, nargs="+", default=[0.0],
                    help="penalty_t / normal penalty of the exact runs (0: the default, EXACT_C)")
    ap.add_argument("--integration", nargs="+", default=[None], choices=["points", "segments"],
                    help="add_contact(integration=...) of every declaration (default: the library's)")
    ap.add_argument("--saddle", nargs="+", default=["auto"], choices=["auto", "direct", "augmented"],
                    help="how exact stick solves its saddle-point systems (default: auto, the library's rule)")
    a = ap.parse_args()
    a.c = [None if c is None or c <= 0 else c for c in a.c]      # 0: the default
    print("| scene | integration | stick | c / penalty | Newton it. | cut-backs | wall [s] | CPU [s] | end "
          "| ratio to penalty |")
    print("|---|---|---|---|---:|---:|---:|---:|---|---:|")
    for scene in a.scenes:
        for integ in a.integration:
            label = integ or "default"
            ref = run(scene, "penalty", integration=integ)
            print(f"| {scene} | {label} | penalty | | {ref[0]} | {ref[1]} | {ref[2]:.1f} | {ref[4]:.1f} | {ref[3]} "
                  "| 1 |", flush=True)
            for c in a.c:
                for saddle in a.saddle:
                    for k in a.exact_c:
                        r = _with_exact_c(k, run, scene, "exact", c, integration=integ, saddle=saddle)
                        name = dict(auto="exact", direct="exact (direct saddle)", augmented="exact (augmented)")[saddle]
                        cname = ('default' if c is None else f'{c:g}') + ('' if k is None else f', EXACT_C {k:g}')
                        print(f"| {scene} | {label} | {name} | {cname} | {r[0]} | {r[1]} | "
                              f"{r[2]:.1f} | {r[4]:.1f} | {r[3]} | {r[0] / max(ref[0], 1):.2f} |", flush=True)


def _with_exact_c(k, f, *args, **kw):
    """``f(*args, **kw)`` with ``contact.system.EXACT_C = k`` (None: unchanged)."""
    from beamsolver.contact import system
    old = system.EXACT_C
    system.EXACT_C = old if k is None else k
    try:
        return f(*args, **kw)
    finally:
        system.EXACT_C = old


if __name__ == "__main__":
    main()
