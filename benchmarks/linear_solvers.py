"""Sparse direct solvers on the tangents of the 19-, 37- and 61-wire bundles (issue 30, item 1).

``python benchmarks/linear_solvers.py [--wires 19,37,61] [--timeout 120]``

The matrices: one Newton tangent of the strands of ``benchmarks/scaling.py`` (1+6+12,
1+6+12+18, 1+6+12+18+24 wires; 158 elements per wire, as in the issue; lay 0.1 m, 24
elements per lay, layers overlapping by 0.5 % of R, 5 Gauss points, mu = 0.3) at the
reference poses, with every contact point active.  Each solver runs in its own child
process on the same saved matrix (one thread: BLAS/OpenMP/MKL pools pinned), which
measures:

- ``analyse``: ordering + symbolic analysis (the part a ``linsolve.Solver`` reuses while
  the pattern holds; SuperLU in scipy has no separate symbolic phase: its ordering only);
- ``factor``: the numerical factorisation (for SuperLU the whole ``splu`` call after the
  ordering), ``refactor``: again with new values on the same pattern (what a Newton
  iteration pays when the contact set is unchanged), ``solve``: one right-hand side;
- ``fill``: non-zeros of the factors (L + U; PARDISO's ``iparm[17]``); ``flops`` of the
  factorisation: counted from the factors' structure for SuperLU (``sum_k 2 l_k u_k + l_k``),
  reported by PARDISO (``iparm[18]``), not available from UMFPACK;
- ``peak MB``: the child's peak resident memory (``VmHWM``, reset after loading the matrix) above its
  resident memory then;
- ``residual``: ``|K x - b| / |b|``.

Candidates (a candidate whose package is missing is listed as such): scipy SuperLU with
its orderings ``COLAMD`` (scipy's default) and ``MMD_AT_PLUS_A`` (``linsolve``'s ``splu``),
``splu-rcm`` (``linsolve``: reverse Cuthill-McKee, threshold pivoting), SuperLU after a
METIS nested-dissection ordering (``pymetis``, on the graph of ``K + K^T`` with identical
columns merged), PARDISO (``pypardiso``, MKL; through ``linsolve.Solver``, analysis
reused), UMFPACK (``kvxopt``'s SuiteSparse; symbolic object reused).  MUMPS
(``python-mumps``) and CHOLMOD (``scikit-sparse``) are reported with the reason they were
not run.  A child that exceeds its wall-clock time-out (``--timeout`` s for SuperLU's own
orderings, which fill in badly on bundles, six times that for the others) is reported as such.

Markdown table on stdout and in the section ``linear_solvers`` of ``docs/benchmarks.md``,
CSV in ``benchmarks/results/linear_solvers.csv``.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_thread, table, write_csv, write_section  # noqa: E402

single_thread()

import json  # noqa: E402
import os  # noqa: E402
import resource  # noqa: E402
import subprocess  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
import scipy.sparse as sp  # noqa: E402

PER_WIRE = 158              # elements per wire (the 3002 / 5846 / 9638 elements)
LAYERS = {19: 2, 37: 3, 61: 4}
CANDIDATES = ("splu-colamd", "splu-mmd", "splu-rcm", "splu-nd", "pardiso", "umfpack")
SLOW = ("splu-colamd", "splu-mmd")     # given --timeout (wall-clock s); the others 6 times as long
NOT_RUN = {
    "mumps": "python-mumps: the only wheel for CPython 3.11 on PyPI (0.0.2) is built against numpy 1.x and "
             "fails to import under numpy 2 (`numpy.core.multiarray failed to import`); later versions are "
             "source only (need a MUMPS library)",
    "cholmod": "scikit-sparse: no wheel (source build against SuiteSparse); and CHOLMOD factors symmetric "
               "matrices only, while the tangents are not symmetric (column `asym`), even frictionless",
}
clock = time.process_time


def rss_mb():
    """Peak resident memory of this process so far (MB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def resident_mb():
    """Resident memory of this process now (MB); resets the peak (``VmHWM``, Linux's ``clear_refs``)."""
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2.0 ** 20


def peak_mb():
    """Peak resident memory since the last ``resident_mb`` (``VmHWM``, MB)."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    return rss_mb()


# ------------------------------------------------------------------ matrices
def build(wires, folder):
    """Tangent and residual of the ``wires`` bundle at the reference poses, saved in ``folder``."""
    from scaling import bundle_model

    from beamsolver.nonlinear.problem import Problem
    m, _ = bundle_model(PER_WIRE, n_layers=LAYERS[wires])
    problem = Problem.from_model(m)
    H = problem.system.poses0.copy()
    problem.begin_step(H, 0.0)
    ev = problem.evaluate(H, 1.0, tangent=True)
    K = problem.tangent(ev).tocsc()
    K.sort_indices()
    b = -ev.r[problem.system.free_dofs]
    sp.save_npz(os.path.join(folder, f"K{wires}.npz"), K)
    np.save(os.path.join(folder, f"b{wires}.npy"), b)
    return dict(wires=wires, elements=problem.system.n_elements, unknowns=K.shape[0], nnz=K.nnz,
                contact_points=int(ev.details["contact"].get("n_active", -1)),
                asym=float(abs(K - K.T).max() / abs(K).max()))


# ------------------------------------------------------------------ candidates (child process)
def lu_flops(L, U):
    """Flops of an LU factorisation with these factors: ``sum_k 2 l_k u_k + l_k`` (``l_k``, ``u_k``:
    off-diagonal entries of column ``k`` of ``L`` and row ``k`` of ``U``)."""
    lk = np.diff(sp.csc_matrix(L).indptr) - 1
    uk = np.diff(sp.csr_matrix(U).indptr) - 1
    return float(np.sum(2.0 * lk * uk + lk))


def nd_ordering(K):
    """METIS nested dissection (pymetis) of the graph of ``K + K^T``, columns of identical pattern merged."""
    import pymetis
    P = sp.csr_matrix((np.ones(K.nnz), K.indices, K.indptr), shape=K.shape).T.tocsr()
    G = (P + P.T).tocsr()
    n = G.shape[0]
    w = np.random.default_rng(0).integers(1, 2 ** 61, n, dtype=np.int64).astype(np.uint64)
    h = np.add.reduceat(w[G.indices], G.indptr[:-1])
    _, inv = np.unique(np.stack([h, np.diff(G.indptr).astype(np.uint64)], 1), axis=0, return_inverse=True)
    inv = inv.ravel()
    m = int(inv.max()) + 1
    C = sp.csr_matrix((np.ones(G.nnz), (inv[np.repeat(np.arange(n), np.diff(G.indptr))], inv[G.indices])),
                      shape=(m, m))
    C.setdiag(0)
    C.eliminate_zeros()
    C.sort_indices()
    order, _ = pymetis.nested_dissection(xadj=C.indptr.astype(np.int64), adjncy=C.indices.astype(np.int64))
    rank = np.empty(m, dtype=np.int64)
    rank[np.asarray(order)] = np.arange(m)
    return np.argsort(rank[inv], kind="stable")


def run_candidate(name, K, b):
    import scipy.sparse.linalg as spla

    from beamsolver.nonlinear import linsolve
    K2 = K.copy()
    K2.data *= 1.0 + 1e-3 * np.cos(np.arange(K2.nnz))          # new values, same pattern
    out = dict(candidate=name)
    if name in ("splu-colamd", "splu-mmd"):
        spec = "COLAMD" if name == "splu-colamd" else "MMD_AT_PLUS_A"
        t0 = clock()
        lu = spla.splu(K, permc_spec=spec)
        out.update(analyse=np.nan, factor=clock() - t0)
        t0 = clock()
        spla.splu(K2, permc_spec=spec)
        out["refactor"] = clock() - t0
        t0 = clock()
        x = lu.solve(b)
        out["solve"] = clock() - t0
        out.update(fill=lu.L.nnz + lu.U.nnz, flops=lu_flops(lu.L, lu.U))
    elif name == "splu-nd":
        t0 = clock()
        perm = nd_ordering(K)
        out["analyse"] = clock() - t0

        def fac(A):
            return spla.splu(sp.csc_matrix(A[perm][:, perm]), permc_spec="NATURAL",
                             diag_pivot_thresh=linsolve.RCM_PIVOT_THRESHOLD, options=dict(SymmetricMode=True))
        t0 = clock()
        lu = fac(K)
        out["factor"] = clock() - t0
        t0 = clock()
        fac(K2)
        out["refactor"] = clock() - t0
        t0 = clock()
        y = lu.solve(b[perm])
        x = np.empty_like(y)
        x[perm] = y
        out["solve"] = clock() - t0
        out.update(fill=lu.L.nnz + lu.U.nnz, flops=lu_flops(lu.L, lu.U))
    elif name == "splu-rcm":
        t0 = clock()
        linsolve._rcm(K)
        out["analyse"] = clock() - t0
        t0 = clock()
        f = linsolve.factorize(K, "splu-rcm")
        out["factor"] = clock() - t0
        t0 = clock()
        linsolve.factorize(K2, "splu-rcm")
        out["refactor"] = clock() - t0
        t0 = clock()
        x = f.solve(b)
        out["solve"] = clock() - t0
        out.update(fill=f.factor_nnz, flops=lu_flops(f._lu.L, f._lu.U))
    elif name == "pardiso":
        if "pardiso" not in linsolve.available():
            return dict(candidate=name, missing="pypardiso not installed")
        s = linsolve.Solver("pardiso")
        ps = s._pardiso = linsolve._Pardiso(linsolve._pypardiso())
        ps.ps.set_iparm(19, -1)                                  # report the factorisation's Mflops
        t0 = clock()
        f = s.factorize(K)                                       # phase 12: analysis + factorisation
        first = clock() - t0
        out["flops"] = 1e6 * float(ps.ps.iparm[18])
        t0 = clock()
        f2 = s.factorize(K2)                                     # phase 22: analysis reused
        out["refactor"] = clock() - t0
        out.update(analyse=max(first - out["refactor"], 0.0), factor=out["refactor"])
        f = s.factorize(K)
        t0 = clock()
        x = f.solve(b)
        out["solve"] = clock() - t0
        out.update(fill=f.factor_nnz, analyses=s.stats["analyses"])
        del f2
    elif name == "umfpack":
        try:
            from kvxopt import matrix, spmatrix, umfpack
        except ImportError:
            return dict(candidate=name, missing="kvxopt not installed")

        def convert(A):
            C = A.tocoo()
            return spmatrix(C.data, C.row.astype(int), C.col.astype(int), A.shape)
        t0 = clock()
        A = convert(K)
        Fs = umfpack.symbolic(A)
        out["analyse"] = clock() - t0
        t0 = clock()
        Fn = umfpack.numeric(A, Fs)
        out["factor"] = clock() - t0
        t0 = clock()
        umfpack.numeric(convert(K2), Fs)
        out["refactor"] = clock() - t0
        t0 = clock()
        B = matrix(b)
        umfpack.solve(A, Fn, B)
        x = np.array(B).ravel()
        out["solve"] = clock() - t0
        out.update(fill=np.nan, flops=np.nan)
    else:
        raise SystemExit(f"unknown candidate {name}")
    out["residual"] = float(np.linalg.norm(K @ x - b) / np.linalg.norm(b))
    return out


def child(argv):
    name, kfile, bfile = argv
    from scaling import warm_up
    warm_up()                  # compiled ordering helpers loaded, MKL initialised: not in the timings
    K = sp.load_npz(kfile).tocsc()
    K.sort_indices()
    b = np.load(bfile)
    base = resident_mb()
    out = run_candidate(name, K, b)
    out["peak_mb"] = peak_mb() - base
    print("JSON " + json.dumps(out, default=float))


def run_child(name, kfile, bfile, timeout):
    try:
        p = subprocess.run([sys.executable, __file__, "--child", name, kfile, bfile], capture_output=True,
                           text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return dict(candidate=name, missing=f"over {timeout:.0f} s wall-clock")
    lines = [ln for ln in p.stdout.splitlines() if ln.startswith("JSON ")]
    if p.returncode != 0 or not lines:
        last = (p.stderr.strip().splitlines() or ["?"])[-1]
        return dict(candidate=name, missing=f"failed: {last[:120]}")
    return json.loads(lines[-1][5:])


# ------------------------------------------------------------------ report
def fmt_s(v):
    return "-" if v is None or not np.isfinite(v) else f"{v:.3g}"


def fmt_e(v, scale=1.0):
    return "-" if v is None or not np.isfinite(v) else f"{v / scale:.3g}"


def main(argv):
    if argv and argv[0] == "--child":
        return child(argv[1:])
    import argparse
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--wires", default="19,37,61")
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--candidates", default=",".join(CANDIDATES))
    a = ap.parse_args(argv)
    t_start = time.perf_counter()
    rows, mats = [], []
    with tempfile.TemporaryDirectory() as folder:
        for wires in (int(w) for w in a.wires.split(",")):
            info = build(wires, folder)
            mats.append(info)
            print(f"  {wires} wires: {info}", file=sys.stderr, flush=True)
            kf, bf = os.path.join(folder, f"K{wires}.npz"), os.path.join(folder, f"b{wires}.npy")
            for name in a.candidates.split(","):
                r = run_child(name, kf, bf, a.timeout if name in SLOW else 6.0 * a.timeout)
                r.update(wires=wires)
                rows.append(r)
                print(f"    {name}: {r}", file=sys.stderr, flush=True)
    wall = time.perf_counter() - t_start
    lines = [f"`python benchmarks/linear_solvers.py` ({machine()}; one thread; whole run {wall:.0f} s). "
             "One Newton tangent of each bundle at the reference poses (158 elements per wire, every contact "
             "point active); CPU seconds; `refactor`: new values on the same pattern, analysis reused where the "
             "back-end allows; `peak MB`: the child's peak resident memory above its resident memory with the "
             "matrix loaded (`VmHWM` reset then); `asym`: `max |K - K^T| / max |K|`.\n",
             table(["wires", "elements", "unknowns", "nnz", "contact points", "asym"],
                   [[m["wires"], m["elements"], m["unknowns"], m["nnz"], m["contact_points"], f"{m['asym']:.2g}"]
                    for m in mats]), ""]
    body = []
    for r in rows:
        if "missing" in r:
            body.append([r["wires"], r["candidate"], r["missing"]] + ["-"] * 7)
            continue
        body.append([r["wires"], r["candidate"], fmt_s(r.get("analyse")), fmt_s(r["factor"]), fmt_s(r["refactor"]),
                     fmt_s(r["solve"]), fmt_e(r.get("fill"), 1e6), fmt_e(r.get("flops"), 1e9),
                     f"{r['peak_mb']:.0f}", f"{r['residual']:.1e}"])
    lines.append(table(["wires", "solver", "analyse s", "factor s", "refactor s", "solve s", "fill (1e6)",
                        "flops (1e9)", "peak MB", "residual"], body))
    lines.append("\nNot run: " + "; ".join(f"**{k}**: {v}" for k, v in NOT_RUN.items()) + ".")
    text = "\n".join(lines)
    print(text)
    write_csv("linear_solvers", rows, keys=["wires", "candidate", "analyse", "factor", "refactor", "solve", "fill",
                                            "flops", "peak_mb", "residual", "missing"])
    write_section("linear_solvers", "## Linear solvers on the bundles' tangents (issue 30)\n\n" + text)
    return rows


if __name__ == "__main__":
    main(sys.argv[1:])
