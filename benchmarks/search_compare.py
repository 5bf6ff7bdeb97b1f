"""The contact search (``ContactSystem.pairs``) of this tree against a git revision's, in one process.

The revision's package is exported (``git archive``) under ``<tmp>/beamsolver_search_ref/<sha>/`` as
``beamsolver_ref`` (its imports are relative; kept, so that numba's cache of it is reused) and both
searches run interleaved on the scene of ``contact_throughput.py`` (two parallel beams in line
contact, 5 Gauss points per slave element).  Per size: least CPU time of ``repeat`` searches of
each, in us per slave point, split as ``ContactSystem.timings`` splits it (search = twists, spheres
and broad phase; rules; projection = the compiled Gauss-point projections, not this work's), and
whether the pair sets (every field, dtype included), the owners remembered and the kernel inputs
(``kernel_inputs``) are bit-identical; then the rest of ``evaluate`` (refusals, active set,
parameters, blocks) the same way.

``python benchmarks/search_compare.py [--ref main] [--max 100000]``
"""
import argparse
import importlib
import subprocess
import sys
import tarfile
import tempfile
import time
from dataclasses import fields
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import single_thread  # noqa: E402

single_thread()
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def reference_package(ref):
    """``beamsolver_ref``: the package of git revision ``ref``, exported once per commit."""
    sha = subprocess.run(["git", "rev-parse", ref], cwd=ROOT, check=True, capture_output=True,
                         text=True).stdout.strip()
    where = Path(tempfile.gettempdir()) / "beamsolver_search_ref" / sha[:12]     # outside the tree (source scans)
    if not (where / "beamsolver_ref").is_dir():
        with tempfile.TemporaryDirectory() as tmp:
            archive = Path(tmp) / "tree.tar"
            subprocess.run(["git", "archive", "-o", str(archive), sha, "beamsolver"], cwd=ROOT, check=True)
            with tarfile.open(archive) as tf:
                tf.extractall(tmp, filter="data")
            where.mkdir(parents=True, exist_ok=True)
            (Path(tmp) / "beamsolver").rename(where / "beamsolver_ref")
    sys.path.insert(0, str(where))
    return importlib.import_module("beamsolver_ref"), sha[:12]


def scene(bs, n_points, gauss_points=5, mu=0.3):
    """``contact_throughput.scene`` built with the package ``bs``: the contact system and poses."""
    from contact_throughput import line_model
    problem = importlib.import_module(bs.__name__ + ".nonlinear.problem")
    m = line_model(bs, max(1, n_points // gauss_points), gauss_points, mu)
    contact = problem.Problem.from_model(m, check_rigid_modes=False).contact
    H = contact.sys.poses0.copy()
    contact.commit(H)
    return contact, H


def _timed_search(c, H):
    """CPU time of one search and its parts (``ContactSystem.timings``)."""
    c.timings = dict.fromkeys(c.timings, 0.0)
    t0 = time.process_time()
    c.pairs(H)
    t = time.process_time() - t0
    return dict(c.timings, total=t)


def _timed_evaluate(c, H):
    """CPU time of one ``evaluate`` after ``begin_step`` (no kept evaluation) and its parts."""
    c.begin_step(H, 0.0)
    c.timings = dict.fromkeys(c.timings, 0.0)
    t0 = time.process_time()
    c.evaluate(H, tangent=True)
    t = time.process_time() - t0
    return dict(c.timings, total=t)


def _least(runs):
    return {k: min(r[k] for r in runs) for k in runs[0]}


def _bits(a, b):
    """Same dtype, shape and bytes (nan and -0.0 included)."""
    a, b = np.ascontiguousarray(a), np.ascontiguousarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def _memory(c, name):
    """The search's memory ``name`` of a contact system (``history.<name>``; ``_<name>`` before
    ``ContactHistory``)."""
    return getattr(c.history, name) if hasattr(c, "history") else getattr(c, "_" + name)


def identical(old, new, H):
    """Pair sets (every field), owners and point pairs remembered, kernel inputs: the same bits."""
    P, Q = old.pairs(H), new.pairs(H)
    same = [f.name for f in fields(P)] == [f.name for f in fields(Q)]
    same = same and all(_bits(getattr(P, f.name), getattr(Q, f.name)) for f in fields(P))
    same = same and all(_bits(_memory(old, k), _memory(new, k)) for k in ("prev_owners", "prev_points"))
    (X, p), (Y, q) = old.kernel_inputs(H), new.kernel_inputs(H)
    return same and _bits(X, Y) and sorted(p) == sorted(q) and all(_bits(p[k], q[k]) for k in p)


def measure(old_bs, new_bs, n_points):
    old, H = scene(old_bs, n_points)
    new, H2 = scene(new_bs, n_points)
    assert np.array_equal(H, H2)
    same = identical(old, new, H)
    # the same poses moved by noise: other pairs, owners remembered from the first poses
    Hm = H.copy()
    Hm[:, :3, 3] += 2e-4 * np.random.default_rng(0).standard_normal((len(H), 3))
    same = same and identical(old, new, Hm)
    repeat = 7 if n_points <= 10_000 else 3
    runs = {"old": [], "new": []}
    evals = {"old": [], "new": []}
    for _ in range(repeat):                   # interleaved: both see the same machine load
        for name, c in (("old", old), ("new", new)):
            runs[name].append(_timed_search(c, H))
            evals[name].append(_timed_evaluate(c, H))
    n = len(new.pairs(H))
    return n, same, {k: _least(v) for k, v in runs.items()}, {k: _least(v) for k, v in evals.items()}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", default="main", help="git revision of the old search (default main)")
    ap.add_argument("--max", type=float, default=1e5, help="largest scene, slave points")
    a = ap.parse_args()
    old_bs, sha = reference_package(a.ref)
    import beamsolver as new_bs
    sizes = [n for n in (100, 1_000, 10_000, 100_000) if n <= a.max]
    us = lambda t, n: f"{1e6 * t / n:.3f}"      # noqa: E731
    rows = []
    for size in sizes:
        n, same, s, e = measure(old_bs, new_bs, size)
        rest = {k: s[k]["total"] - s[k]["projection"] for k in s}
        ev = {k: e[k]["total"] - e[k]["search"] - e[k]["rules"] - e[k]["projection"] - e[k]["kernel"] for k in e}
        rows.append(f"| {n} | {us(s['old']['total'], n)} | {us(s['new']['total'], n)} | "
                    f"{s['old']['total'] / s['new']['total']:.2f} | {us(s['old']['projection'], n)} | "
                    f"{us(s['new']['projection'], n)} | {us(rest['old'], n)} | {us(rest['new'], n)} | "
                    f"{us(rest['old'] - rest['new'], n)} | {us(ev['old'], n)} | {us(ev['new'], n)} | "
                    f"{'yes' if same else 'NO'} |")
    print(f"contact search, this tree ({new_bs.__file__}) against {a.ref} ({sha}); us per slave point, "
          "least CPU time, interleaved\n")
    print("| slave points | search old | search new | ratio | projection old | projection new | "
          "search - projection old | new | saved | rest of evaluate old | new | bit-identical |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
