"""The compiled contact kernel of the working tree against that of a git revision, in one process.

Loads ``beamsolver/contact/kernel_jit.py`` as of ``REF`` (``git show``) next to the working
tree's module, runs both on the scene of ``contact_throughput.py`` (two parallel beams in line
contact, friction on, history stored) and prints

- whether the outputs are the same bits (forces, tangent with the signs of its zeros, point data),
- the kernel + tangent time per point of each (least CPU time of ``repeats`` alternating calls:
  the machine is shared, so only the ratio within one run means much).

The old module compiles into a temporary numba cache (first run: about half a minute).
Prints only (no section of ``docs/benchmarks.md``).

``python benchmarks/kernel_jit_vs_ref.py [REF=main] [points=10000] [repeats=7]``
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


def main(ref="main", points=10_000, repeats=7):
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
        best = dict.fromkeys(mods, np.inf)
        for _ in range(repeats):
            for name, m in mods.items():
                t0 = time.process_time()
                m.kernel_and_tangent(X, p, K=K[name])
                best[name] = min(best[name], time.process_time() - t0)
    rows = [(name, f"{1e6 * t / P:.2f}", f"{best[ref] / t:.3f}") for name, t in best.items()]
    print(f"{P} contact points, least CPU time of {repeats}; outputs bit-identical: {same}")
    print(table(["kernel_jit", "kernel + tangent (us/point)", f"speed-up over {ref}"], rows))
    return same, best


if __name__ == "__main__":
    args = sys.argv[1:]
    main(args[0] if args else "main", *(int(a) for a in args[1:]))
