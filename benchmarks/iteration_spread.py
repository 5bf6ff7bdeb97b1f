"""Newton iterations of the contact examples under round-off: the spread over inputs changed by a few ulps.

The total Newton iteration count of a frictional contact solve is round-off chaotic: the
twisted pair's damped first steps and its stick/slip and active-set decisions amplify a
change in the last bit of one input into a different sequence of iterates (same equilibria,
different path).  One count is therefore one sample; code that changes round-off (a
restructured kernel) is compared by the distribution of counts over an ensemble of inputs,
each changed by 1 or 2 ulps (pull, Young's modulus, friction coefficient, length, radius;
``np.nextafter``), not by the count of one run.

For each example (``examples/twisted_pair.py``: 2 turns in 16 steps; ``examples/three_wires.py``:
1 turn in 8 steps) prints the unperturbed count and the ensemble's min / median / mean (with its
standard error) / max, and writes the ``iteration_spread`` section of ``docs/benchmarks.md``.
With ``--ref REV`` the same ensemble also runs on the code of the git revision ``REV`` (its tree
exported to a temporary directory, run in a subprocess; its numba kernels compile first) and the
table compares the two: the working tree's mean is "not more" when it is at most the reference's
mean plus twice the standard error of the difference.

``python benchmarks/iteration_spread.py [--ref REV] [--quick] [--examples twisted_pair,three_wires]``
"""
import argparse
import json
import os
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import ROOT, machine, single_thread, table, write_section  # noqa: E402

single_thread()
import numpy as np  # noqa: E402

EXAMPLES = {"twisted_pair": dict(steps=16), "three_wires": dict(steps=8)}
PARAMETERS = ("pull", "E", "mu", "length", "radius")
ULPS = (1, -1, 2, -2)


def nudged(x, ulps):
    """``x`` moved by ``ulps`` units in the last place (``np.nextafter`` repeated)."""
    for _ in range(abs(ulps)):
        x = np.nextafter(x, np.inf if ulps > 0 else -np.inf)
    return float(x)


def variants(quick=False):
    """``(name, keyword overrides)`` of the ensemble: the unperturbed inputs first."""
    out = [("base", {})]
    for k in ULPS[:2] if quick else ULPS:
        out += [(f"{name}{k:+d}ulp", {name: k}) for name in PARAMETERS]
    return out


def counts(example, quick=False):
    """Total Newton iterations of every variant of ``example`` (run with the code on ``sys.path``)."""
    import inspect
    import beamsolver as bs
    sys.path.insert(0, str(Path(bs.__file__).resolve().parents[1] / "examples"))
    build = __import__(example).build
    defaults = {k: v.default for k, v in inspect.signature(build).parameters.items()}
    out = {}
    for name, nudge in variants(quick):
        kw = {k: nudged(defaults[k], u) for k, u in nudge.items()}
        sol = bs.solve(build(**kw)[0], steps=EXAMPLES[example]["steps"])
        if not sol.converged:
            raise RuntimeError(f"{example} {name}: not converged")
        out[name] = int(sum(s["iterations"] for s in sol.stats))
    return out


def summary(c):
    """``base, min, median, mean, standard error of the mean, max`` of the counts ``c`` (a dict)."""
    v = np.array(list(c.values()), dtype=float)
    return c["base"], v.min(), np.median(v), v.mean(), v.std(ddof=1) / np.sqrt(len(v)), v.max()


def run_revision(ref, examples, quick):
    """``{example: counts}`` of the git revision ``ref``: its tree exported and run in a subprocess."""
    with tempfile.TemporaryDirectory() as tmp:
        archive = Path(tmp) / "tree.tar"
        subprocess.run(["git", "archive", "-o", str(archive), ref], cwd=ROOT, check=True)
        with tarfile.open(archive) as tf:
            tf.extractall(Path(tmp) / "tree", filter="data")
        tree = Path(tmp) / "tree"
        env = dict(os.environ, PYTHONPATH=str(tree))
        args = [sys.executable, str(Path(__file__).resolve()), "--json", "--examples", ",".join(examples)]
        res = subprocess.run(args + (["--quick"] if quick else []), cwd=tree, env=env, check=True,
                             capture_output=True, text=True)
        return json.loads(res.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", help="git revision to compare with (its ensemble runs in a subprocess)")
    ap.add_argument("--quick", action="store_true", help="1-ulp changes only (11 runs per example)")
    ap.add_argument("--examples", default=",".join(EXAMPLES))
    ap.add_argument("--json", action="store_true", help=argparse.SUPPRESS)     # the subprocess of --ref
    a = ap.parse_args()
    examples = a.examples.split(",")
    t0 = time.perf_counter()
    ours = {ex: counts(ex, a.quick) for ex in examples}
    if a.json:
        print(json.dumps(ours))
        return
    theirs = run_revision(a.ref, examples, a.quick) if a.ref else {}
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                          text=True).stdout.strip()
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT,
                           capture_output=True, text=True).stdout.strip()
    label = f"working tree ({head}{' + changes' if dirty else ''})"
    rows = []
    for ex in examples:
        for name, c in ((label, ours[ex]),) + (((a.ref, theirs[ex]),) if a.ref else ()):
            base, lo, med, mean, se, hi = summary(c)
            rows.append((ex, name, len(c), base, int(lo), f"{med:g}", f"{mean:.1f} +- {se:.1f}", int(hi)))
    text = [f"## Newton iterations under round-off (contact examples)\n",
            f"`python benchmarks/iteration_spread.py{' --ref ' + a.ref if a.ref else ''}"
            f"{' --quick' if a.quick else ''}` ({machine()})\n",
            "Total Newton iterations of each example with its default inputs (base) and with one input "
            f"({', '.join(PARAMETERS)}) changed by {'1' if a.quick else '1 or 2'} ulps (np.nextafter): "
            "the count is round-off chaotic, so code that changes round-off is judged by the ensemble "
            "(mean +- standard error of the mean), not by one run.\n",
            table(["example", "code", "runs", "base", "min", "median", "mean", "max"], rows)]
    if a.ref:
        verdict = []
        for ex in examples:
            m0, s0 = summary(theirs[ex])[3:5]
            m1, s1 = summary(ours[ex])[3:5]
            band = 2.0 * np.hypot(s0, s1)
            ok = m1 <= m0 + band
            verdict.append(f"- {ex}: mean {m1:.1f} vs {m0:.1f} ({m1 - m0:+.1f}; twice the standard error of the "
                           f"difference {band:.1f}): {'not more' if ok else 'MORE'} iterations")
        text.append("\n" + "\n".join(verdict))
    text.append(f"\nWhole run {time.perf_counter() - t0:.0f} s.")
    out = "\n".join(text)
    print(out)
    write_section("iteration_spread", out)


if __name__ == "__main__":
    main()
