"""PARDISO's options on the bundles' tangents (issue 30, item 1): fill, flops, time and memory per choice.

``python benchmarks/pardiso_options.py [--wires 19,37,61] [--choices default,no-matching,...]``

The matrices are those of ``benchmarks/linear_solvers.py`` (one Newton tangent of the 19-, 37-,
61-wire bundles at the reference poses, every contact point active, ``linear_solvers.build``).
Each wire count runs in its own child process (one thread: MKL pinned), which calls MKL's
``pardiso`` through ctypes phase by phase on the matrix (CSC handed over as the CSR of ``K^T``
with ``iparm[11] = 1``, zero-based indices ``iparm[34] = 1``) and reports per choice:

- ``analyse`` (phase 11: ordering + symbolic factorisation), ``factor`` (phase 22, first numerical
  factorisation), ``refactor`` (phase 22 again, new values on the same pattern: what a Newton
  iteration pays while the contact set holds), ``solve`` (phase 33, one right-hand side), CPU s;
- ``fill``: factor entries (``iparm[17]``), ``flops`` of the factorisation (``iparm[18]``, Mflop),
  ``peak MB``: PARDISO's own peak memory (``max(iparm[14], iparm[15] + iparm[16])``, kB);
- ``residual`` ``|K x - b| / |b|``, perturbed pivots ``iparm[13]``, refinement steps ``iparm[6]``.

Choices (``iparm`` 0-based as in MKL's C interface; ``default`` is what ``linsolve`` runs, MKL's
defaults for ``mtype = 11``):

- ``default``: METIS nested dissection (``iparm[1] = 2``), scaling and weighted matching on
  (``iparm[10] = iparm[12] = 1``), pivot perturbation ``1e-13`` (``iparm[9] = 13``);
- ``no-matching`` (``iparm[12] = 0``), ``no-scaling`` (``iparm[10] = iparm[12] = 0``);
- ``parallel-nd`` (``iparm[1] = 3``), ``min-degree`` (``iparm[1] = 0``);
- ``two-level`` (``iparm[23] = 1``), ``two-level-10`` (``iparm[23] = 10``);
- ``struct-sym``: ``mtype = 1`` (structurally symmetric), on the pattern of ``K + K^T`` (its
  ``nnz`` grows by the few entries whose mirror is missing, stored as 1e-300);
- ``node-nd``: METIS (``pymetis``) nested dissection of the node graph (6 unknowns per node, in
  the free numbering of ``System``), given as the ordering (``iparm[4] = 1``), no matching;
- ``single``: the factorisation in single precision (``iparm[27] = 1``) with up to 5 steps of
  iterative refinement (``iparm[7] = 5``).

Then ``pypardiso``'s public ``solve`` (``spsolve``) on new values with the same pattern, timed:
it runs phase 13 (analysis + factorisation + solve) for every new matrix, while
``linsolve.Solver`` runs phase 22 + 33 (``linsolve._Pardiso``).

Markdown table on stdout and in the section ``pardiso_options`` of ``docs/benchmarks.md``, CSV in
``benchmarks/results/pardiso_options.csv``.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_thread, table, write_csv, write_section  # noqa: E402

single_thread()

import ctypes  # noqa: E402
import json  # noqa: E402
import os  # noqa: E402
import subprocess  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
import scipy.sparse as sp  # noqa: E402

CHOICES = {
    "default": {},
    "no-matching": {12: 0},
    "no-scaling": {10: 0, 12: 0},
    "parallel-nd": {1: 3},
    "min-degree": {1: 0},
    "two-level": {23: 1},
    "two-level-10": {23: 10},
    "struct-sym": {"mtype": 1},
    "node-nd": {4: 1, 12: 0},
    "single": {27: 1, 7: 5},
}
clock = time.process_time


def _pardiso():
    """MKL's ``pardiso`` function with its ctypes signature (the library ``pypardiso`` loads)."""
    import pypardiso
    fn = pypardiso.PyPardisoSolver().libmkl.pardiso
    i32 = ctypes.POINTER(ctypes.c_int32)
    fn.argtypes = [ctypes.POINTER(ctypes.c_int64)] + [i32] * 5 + [ctypes.c_void_p, i32, i32, i32, i32, i32, i32,
                                                                   ctypes.c_void_p, ctypes.c_void_p, i32]
    fn.restype = None
    return fn


def _iparm(mtype, extra):
    """MKL's defaults for ``mtype`` written out (``iparm[0] = 1``), then ``extra``."""
    ip = np.zeros(64, dtype=np.int32)
    ip[0], ip[1], ip[9] = 1, 2, 13 if mtype == 11 else 8
    ip[10] = ip[12] = 1 if mtype == 11 else 0
    ip[11] = 1                        # the CSC arrays of K are the CSR arrays of K^T: solve the transpose
    ip[17] = ip[18] = -1              # report fill and Mflops
    ip[34] = 1                        # zero-based indices: scipy's arrays as they are
    for k, v in extra.items():
        ip[k] = v
    return ip


def node_nd(K):
    """Nested dissection (METIS via ``pymetis``) of the node graph of ``K`` (6 unknowns per node),
    as PARDISO's ``perm`` (``perm[i]``: the new position of unknown ``i``)."""
    import pymetis
    n = K.shape[0] // 6
    cols = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
    G = sp.csr_matrix((np.ones(K.nnz), (K.indices // 6, cols // 6)), shape=(n, n))
    G = (G + G.T).tocsr()
    G.setdiag(0)
    G.eliminate_zeros()
    order, _ = pymetis.nested_dissection(xadj=G.indptr.astype(np.int64), adjncy=G.indices.astype(np.int64))
    return (6 * np.asarray(order)[:, None] + np.arange(6)).ravel().astype(np.int32)


def run_choice(fn, name, K, b):
    spec = dict(CHOICES[name])
    mtype = spec.pop("mtype", 11)
    if mtype == 1:                   # K + K^T's pattern, the new entries 1e-300 (scipy drops stored zeros)
        U = (abs(K) + abs(K.T)).tocsc()
        U.data[:] = 1e-300
        K = (K + U).tocsc()
    K.sort_indices()
    n = K.shape[0]
    ip = _iparm(mtype, spec)
    perm = node_nd(K) if ip[4] == 1 else np.zeros(n, dtype=np.int32)
    ia, ja = K.indptr.astype(np.int32), K.indices.astype(np.int32)
    x, err, pt = np.zeros(n), ctypes.c_int32(0), np.zeros(64, dtype=np.int64)
    i32p = ctypes.POINTER(ctypes.c_int32)

    def call(phase, data):
        fn(pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)), ctypes.byref(ctypes.c_int32(1)),
           ctypes.byref(ctypes.c_int32(1)), ctypes.byref(ctypes.c_int32(mtype)), ctypes.byref(ctypes.c_int32(phase)),
           ctypes.byref(ctypes.c_int32(n)), data.ctypes.data, ia.ctypes.data_as(i32p), ja.ctypes.data_as(i32p),
           perm.ctypes.data_as(i32p), ctypes.byref(ctypes.c_int32(1)), ip.ctypes.data_as(i32p),
           ctypes.byref(ctypes.c_int32(0)), b.ctypes.data, x.ctypes.data, ctypes.byref(err))
        if err.value:
            raise RuntimeError(f"pardiso error {err.value} in phase {phase}")

    out = dict(choice=name, nnz=int(K.nnz))
    try:
        t0 = clock()
        call(11, K.data)
        out["analyse"] = clock() - t0
        t0 = clock()
        call(22, K.data)
        out["factor"] = clock() - t0
        out.update(fill=float(ip[17]), flops=1e6 * float(ip[18]), peak_mb=max(ip[14], ip[15] + ip[16]) / 1024.0)
        data2 = K.data * (1.0 + 1e-3 * np.cos(np.arange(K.nnz)))
        t0 = clock()
        call(22, data2)
        out["refactor"] = clock() - t0
        call(22, K.data)
        t0 = clock()
        call(33, K.data)
        out["solve"] = clock() - t0
        out.update(residual=float(np.linalg.norm(K @ x - b) / np.linalg.norm(b)), perturbed=int(ip[13]),
                   refinement=int(ip[6]))
    except RuntimeError as e:
        out["error"] = str(e)
    call(-1, K.data)                 # release PARDISO's memory
    return out


def pypardiso_public(K, b):
    """CPU s of ``pypardiso.spsolve`` on new values with the same pattern (its re-analysis)."""
    import pypardiso
    s = pypardiso.PyPardisoSolver()
    s.solve(K, b)
    K2 = K.copy()
    K2.data *= 1.0 + 1e-3 * np.cos(np.arange(K2.nnz))
    t0 = clock()
    s.solve(K2, b)
    t = clock() - t0
    s.free_memory(everything=True)
    return dict(choice="pypardiso.solve (public)", refactor=t)


def child(argv):
    kfile, bfile, choices = argv[0], argv[1], argv[2].split(",")
    from scaling import warm_up
    warm_up()
    K = sp.load_npz(kfile).tocsc()
    K.sort_indices()
    b = np.load(bfile)
    fn = _pardiso()
    rows = [run_choice(fn, c, K, b) for c in choices]
    rows.append(pypardiso_public(K, b))
    print("JSON " + json.dumps(rows, default=float))


def main(argv):
    if argv and argv[0] == "--child":
        return child(argv[1:])
    import argparse

    from linear_solvers import build
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--wires", default="19,37,61")
    ap.add_argument("--choices", default=",".join(CHOICES))
    a = ap.parse_args(argv)
    t_start = time.perf_counter()
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for wires in (int(w) for w in a.wires.split(",")):
            info = build(wires, folder)
            print(f"  {wires} wires: {info}", file=sys.stderr, flush=True)
            kf, bf = os.path.join(folder, f"K{wires}.npz"), os.path.join(folder, f"b{wires}.npy")
            p = subprocess.run([sys.executable, __file__, "--child", kf, bf, a.choices], capture_output=True,
                               text=True)
            lines = [ln for ln in p.stdout.splitlines() if ln.startswith("JSON ")]
            if p.returncode != 0 or not lines:
                raise RuntimeError(f"child for {wires} wires failed:\n{p.stderr[-3000:]}")
            for r in json.loads(lines[-1][5:]):
                r.update(wires=wires, unknowns=info["unknowns"])
                rows.append(r)
                print(f"    {r}", file=sys.stderr, flush=True)
    wall = time.perf_counter() - t_start

    def g(r, k, scale=1.0, f="{:.3g}"):
        v = r.get(k)
        return "-" if v is None or not np.isfinite(v) else f.format(v / scale)
    body = [[r["wires"], r["choice"], r.get("error", "")[:40] or g(r, "analyse"), g(r, "factor"), g(r, "refactor"),
             g(r, "solve"), g(r, "fill", 1e6), g(r, "flops", 1e9), g(r, "peak_mb", 1.0, "{:.0f}"),
             g(r, "residual", 1.0, "{:.1e}"), r.get("perturbed", "-"), r.get("refinement", "-")] for r in rows]
    text = (f"`python benchmarks/pardiso_options.py --wires {a.wires}` ({machine()}; one thread; whole run "
            f"{wall:.0f} s). MKL PARDISO called phase by phase on one tangent of each bundle "
            "(`linear_solvers.build`), CPU s; `refactor`: new values on the same pattern (a Newton "
            "iteration with the contact set unchanged); peak MB: PARDISO's own report.\n\n"
            + table(["wires", "choice", "analyse", "factor", "refactor", "solve", "fill (1e6)", "flops (1e9)",
                     "peak MB", "residual", "perturbed", "refinement"], body))
    print(text)
    write_csv("pardiso_options", rows)
    write_section("pardiso_options", "## PARDISO's options on the bundles (issue 30)\n\n" + text)
    return rows


if __name__ == "__main__":
    main(sys.argv[1:])
