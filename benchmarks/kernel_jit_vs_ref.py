"""The compiled contact kernel of the working tree against that of a git revision, in one process.

Loads ``beamsolver/contact/kernel_jit.py`` as of ``REF`` (``git show``) next to the working
tree's module, runs both on the scene of ``contact_throughput.py`` (two parallel beams in line
contact, friction on, history stored) and prints

- whether the outputs are the same bits (forces, tangent with the signs of its zeros, point data),
- the largest relative deviation of forces and tangent (max abs difference / max abs value of the
  batch) on that scene and on the contact points of a short run of ``examples/twisted_pair_extreme.py``
  (half a turn in 4 steps: twisted wires, sliding and sticking points, every kernel call of the run),
  and whether it is within ``tol`` (a kernel that may change round-off),
- the kernel + tangent time per point of each (least CPU time of ``repeats`` alternating calls:
  the machine is shared, so only the ratio within one run means much).

The old module compiles into a temporary numba cache (first run: about half a minute).
Prints only (no section of ``docs/benchmarks.md``).

``python benchmarks/kernel_jit_vs_ref.py [REF=main] [points=10000] [repeats=7] [tol=1e-12]``
"""
import importlib.util
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import ROOT, single_thread, table  # noqa: E402

single_thread()
import numpy as np  # noqa: E402

import beamsolver.contact  # noqa: E402,F401
from beamsolver.contact import kernel_jit  # noqa: E402
from contact_throughput import scene  # noqa: E402


def load_ref(ref, directory):
    """``kernel_jit`` as of the git revision ``ref``, imported as ``beamsolver.contact.kernel_jit_ref``."""
    src = subprocess.run(["git", "show", f"{ref}:beamsolver/contact/kernel_jit.py"], cwd=ROOT, check=True,
                         capture_output=True, text=True).stdout
    # revisions before _jit.jit_callee imported _jit's jit_inline (numba-level inlining): give them theirs
    src = src.replace("from .._jit import jit, jit_inline\n", "from .._jit import jit\nfrom numba import njit as _njit\n"
                      "jit_inline = _njit(cache=True, error_model=\"numpy\", inline=\"always\")\n")
    path = Path(directory) / "kernel_jit_ref.py"
    path.write_text(src)
    spec = importlib.util.spec_from_file_location("beamsolver.contact.kernel_jit_ref", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


def same_bits(a, b):
    """``a`` and ``b`` hold the same floats, zeros' signs included."""
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and np.array_equal(a, b, equal_nan=a.dtype.kind == "f") and \
        np.array_equal(np.signbit(a), np.signbit(b))


def deviation(a, b):
    """Largest ``|a - b|`` over the largest ``|a|``."""
    return float(np.max(np.abs(a - b)) / np.max(np.abs(a)))


def twisted_pair_calls(turns=0.5, steps=4):
    """Kernel inputs ``(X, p, friction)`` of every tangent evaluation of a short twisted-pair solve."""
    sys.path.insert(0, str(ROOT / "examples"))
    import beamsolver as bs
    from twisted_pair_extreme import build
    calls, compiled = [], kernel_jit.kernel_and_tangent     # the contact systems' kernel (``ContactSystem.kernel``)

    def record(X, p, friction=True, **kw):
        calls.append((np.array(X), {k: np.copy(v) for k, v in p.items()}, friction))
        return compiled(X, p, friction=friction, **kw)

    kernel_jit.kernel_and_tangent = record
    try:
        bs.solve(build(turns=turns)[0], steps=steps)
    finally:
        kernel_jit.kernel_and_tangent = compiled
    return calls


def deviations(mods, calls):
    """Largest relative deviations of forces and tangent between the two modules over ``calls``."""
    df = dK = 0.0
    for X, p, friction in calls:
        (f0, K0, _), (f1, K1, _) = (m.kernel_and_tangent(X, p, friction=friction) for m in mods.values())
        df, dK = max(df, deviation(f0, f1)), max(dK, deviation(K0, K1))
    return df, dK


def main(ref="main", points=10_000, repeats=7, tol=1e-12):
    contact, H = scene(points)
    X, p = contact.kernel_inputs(H)
    P = len(X)
    with tempfile.TemporaryDirectory() as tmp:
        old = load_ref(ref, tmp)
        mods = {ref: old, "working tree": kernel_jit}
        K = {name: np.empty((P, 24, 24)) for name in mods}
        out = {name: m.kernel_and_tangent(X, p, K=K[name]) for name, m in mods.items()}      # compiles
        (f0, _, o0), (f1, _, o1) = out.values()
        same = same_bits(f0, f1) and same_bits(*K.values()) and all(same_bits(o0[k], o1[k]) for k in o0)
        dev = {"benchmark scene": (deviation(f0, f1), deviation(*K.values()))}
        calls = twisted_pair_calls()
        dev[f"twisted pair ({len(calls)} calls)"] = deviations(mods, calls)
        best = dict.fromkeys(mods, np.inf)
        for _ in range(repeats):
            for name, m in mods.items():
                t0 = time.process_time()
                m.kernel_and_tangent(X, p, K=K[name])
                best[name] = min(best[name], time.process_time() - t0)
    rows = [(name, f"{1e6 * t / P:.2f}", f"{best[ref] / t:.3f}") for name, t in best.items()]
    print(f"{P} contact points, least CPU time of {repeats}; outputs bit-identical: {same}")
    print(table(["kernel_jit", "kernel + tangent (us/point)", f"speed-up over {ref}"], rows))
    rows = [(name, f"{a:.2e}", f"{b:.2e}", str(max(a, b) <= tol)) for name, (a, b) in dev.items()]
    print(table(["points", "forces: max rel. deviation", "tangent: max rel. deviation", f"within {tol:g}"], rows))
    return same, best, dev


if __name__ == "__main__":
    args = sys.argv[1:]
    main(args[0] if args else "main", *(int(a) for a in args[1:3]), *(float(a) for a in args[3:4]))
