"""Exact stick's Newton iterations and cut-backs on the six contact examples, also under round-off perturbations
of the initial poses (issue 26: a gain must not be luck; the twisted pair's count moved 224-314 at round-off).

    python benchmarks/exact_stick_iterations.py [--scenes twisted_pair shear_lag ...] [--perturb 0 1e-12 ...]
        [--stick exact] [--option NAME=VALUE ...]

``--perturb d``: every beam's node positions' x and y scaled by ``1 + d`` (default 0, +-1e-12, +-3e-12) (``Model.add_beam`` wrapped; z kept:
the rolling beam rests on its master along z): the same scene to round-off.  ``--option``: a module attribute of ``beamsolver.contact.system`` or
``beamsolver.nonlinear.newton`` set before the runs (``system.SSN_FREEZE=0``: the experiments' switches).
Prints one markdown row per scene and perturbation with Newton iterations, cut-backs, the CPU time
(``time.process_time``: the machine is shared) and a digest of the final node positions (the same bits: the same digest).
"""
import argparse
import contextlib
import hashlib
import io
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import beamsolver as bs  # noqa: E402
from exact_stick_examples import SCENES  # noqa: E402


def run(scene, stick="exact", perturb=0.0):
    """``(iterations, cut-backs, CPU s, end)`` of ``scene`` with every declaration's ``stick`` and the beams'
    x, y scaled by ``1 + perturb`` (the scene's own printing silenced)."""
    add_contact, add_beam = bs.Model.add_contact, bs.Model.add_beam

    def contact(self, slave, master, mu=0.0, penalty=None, **options):
        options.setdefault("stick", stick)
        return add_contact(self, slave, master, mu=mu, penalty=penalty, **options)

    def beam(self, poses, section, *a, **k):
        P = np.array(poses, dtype=float)
        P[:, :2, 3] *= 1.0 + perturb
        return add_beam(self, P, section, *a, **k)

    bs.Model.add_contact, bs.Model.add_beam = contact, beam
    t0 = time.process_time()
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            sol = SCENES[scene]()
        its = int(sum(s["iterations"] for s in sol.stats))
        cuts = int(sum(s.get("cutbacks", 0) for s in sol.stats))
        X = np.ascontiguousarray(np.asarray(sol.poses[-1])[..., :3, 3])
        return its, cuts, time.process_time() - t0, "t = %.3g, end poses %s" % (
            sol.times[-1], hashlib.sha1(X.tobytes()).hexdigest()[:10])
    except bs.ConvergenceError as e:
        sol = e.solution
        its = int(sum(s["iterations"] for s in sol.stats)) if sol is not None else 0
        return its, -1, time.process_time() - t0, "failed at t = %.3g" % (sol.times[-1] if sol is not None else np.nan)
    finally:
        bs.Model.add_contact, bs.Model.add_beam = add_contact, add_beam


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", nargs="+", default=["twisted_pair", "three_wires", "shear_lag", "rolling", "capstan",
                                                    "contact_patch"])
    ap.add_argument("--perturb", type=float, nargs="+", default=[0.0, 1e-12, -1e-12, 3e-12, -3e-12],
                    help="positions' x, y scaled by 1 + each (default: 0 +-1e-12 +-3e-12; argparse takes -1e-12 for "
                         "an option: write negative ones as -0.000000000001)")
    ap.add_argument("--stick", default="exact")
    ap.add_argument("--option", nargs="*", default=[])
    a = ap.parse_args()
    from beamsolver.contact import mortar, system
    from beamsolver.nonlinear import condense, newton
    for o in a.option:
        name, value = o.split("=")
        mod = next((m for m in (system, newton, mortar, condense) if hasattr(m, name)), None)
        if mod is None:
            raise SystemExit(f"no option {name}")
        old = getattr(mod, name)
        setattr(mod, name, value.lower() in ("1", "true") if isinstance(old, bool) else
                value if isinstance(old, str) else type(old)(float(value)))
    print("| scene | stick | perturbation | Newton it. | cut-backs | CPU [s] | end |")
    print("|---|---|---:|---:|---:|---:|---|")
    for scene in a.scenes:
        for d in a.perturb:
            r = run(scene, a.stick, d)
            print(f"| {scene} | {a.stick} | {d:g} | {r[0]} | {r[1]} | {r[2]:.1f} | {r[3]} |", flush=True)


if __name__ == "__main__":
    main()
