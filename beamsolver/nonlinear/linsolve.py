"""Sparse direct solvers for the Newton loop: ``factorize(K, backend)`` -> object with ``.solve(b)``.

Back-ends (``backend=`` here, ``linear_solver=`` in ``beamsolver.solve``):

- ``"splu"``: scipy's SuperLU, ``permc_spec="MMD_AT_PLUS_A"`` (less fill than
  scipy's default ordering on beam matrices); fine for
  beam-like matrices (cables, frames, a few wires).  SuperLU has no
  "re-factorise with the same pattern" entry point in scipy, so every Newton
  iteration re-orders and re-factorises from scratch.
- ``"pardiso"``: Intel MKL PARDISO through ``pypardiso`` (a dependency where it has wheels:
  x86-64 Linux and Windows; ~0.9 GB with MKL; elsewhere ``pip install pypardiso`` if available).
  A supernodal LU with a METIS nested-dissection ordering and weighted matching.  A
  ``Solver`` keeps PARDISO's handle: while the sparsity pattern stays the
  same (no contact pair appearing or vanishing) only the numerical
  factorisation is redone (PARDISO phase 22), the ordering and symbolic
  analysis (phase 11) are reused.  (``pypardiso``'s own ``solve``
  re-analyses every new matrix; it only skips work for an identical one.)
  Timings against the SuperLU back-ends: docs/benchmarks.md (``benchmarks/scaling.py``).
- ``"splu-rcm"``: SuperLU after a reverse Cuthill-McKee symmetric
  permutation (``scipy.sparse.csgraph``), natural column order.  On long
  bundles of wires in contact SuperLU's MMD ordering fills in superlinearly;
  the RCM band's fill stays linear in the length (docs/benchmarks.md,
  ``benchmarks/scaling.py``).  On a single beam both give the same factor.
- ``"dense"``: LAPACK's LU with partial pivoting (``dgetrf``/``dgetrs``) of the matrix made dense.
  The condensed tangents of small scenes (the main job: 180-230 unknowns, 5-25 % non-zeros) fill in
  anyway: SuperLU spends 0.86 ms on one where ``dgetrf`` takes 0.33 ms (docs/benchmarks.md, session 14,
  branch bF); at ~500 unknowns SuperLU is 2x faster again.  ``"auto"`` takes it for saddle-point systems of
  at most ``DENSE_MAX_UNKNOWNS`` (256) unknowns only (on a slender beam's band its accuracy is below SuperLU's).
- ``"auto"`` (default): the rule of ``Solver.backend_for``.

Evaluated on the bundles' tangents and not used (``benchmarks/linear_solvers.py``, numbers in
docs/benchmarks.md): SuperLU with COLAMD or MMD_AT_PLUS_A (9-20x the fill of RCM); SuperLU after
a METIS nested dissection (``pymetis``: 1.4-1.6x RCM's fill, 3x its flops: a bundle is long and
thin, and RCM's band is near optimal for it); UMFPACK (``kvxopt``: GPL, 3-6x PARDISO's time); MUMPS
(``python-mumps``: its one CPython 3.11 wheel is built against numpy 1.x and does not import under
numpy 2); CHOLMOD and PARDISO's symmetric modes: Newton tangents are not symmetric, not even
frictionless ones (``max |K - K^T| / max |K|`` 1e-3 .. 9e-3 on the bundles: SE(3) beams off
equilibrium, contact).  Saddle-point systems (multiplier contact: a zero diagonal block) go to
the same unsymmetric back-ends, which pivot (SuperLU: threshold partial pivoting; PARDISO:
weighted matching and pivot perturbation, its solutions checked by ``_poor``).  Exact stick's condensed saddle
systems from ``augmented.MIN_UNKNOWNS`` unknowns are not factorised as such: ``augmented`` solves them by GMRES
preconditioned by a (lagged) factorisation of ``A = K' + Kq E Kl``, a non-saddle matrix of the tangent's pattern.

Lagged solves (``Solver(lagged="auto")``, the default; ``lagged.py``): while a factorisation is
expensive (``Solver.lag_budget``), ``Solver.factorize`` returns a factor that solves the new matrix
by GMRES preconditioned by the last fresh factorisation, to ``lagged.LAG_RTOL`` of the right-hand
side, and factorises afresh when that does not get there within its budget (docs/benchmarks.md:
2-19 % less CPU per Newton iteration on the strands' loaded steps; no lagging for small scenes).

A singular matrix raises ``SingularMatrixError`` (a ``RuntimeError``), from
``factorize`` (splu: exactly zero pivot) or from ``solve`` (pardiso perturbs
tiny pivots instead of failing, so its ``solve`` checks the solution with
one sparse product, see ``_poor``, and re-analyses once before giving up).

Threads: PARDISO uses MKL's OpenMP threads (``MKL_NUM_THREADS``), SuperLU one.
"""
import copy
import os
import weakref

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .._jit import jit
from ..errors import InputError
from ..failures import SingularTangent
from .lagged import LaggedFactor

__all__ = ["factorize", "factorize_tangent", "Solver", "SingularMatrixError", "available", "permutation_sign",
           "BACKENDS", "DEFAULT"]

BACKENDS = ("splu", "splu-rcm", "pardiso", "dense", "auto")
DEFAULT = "auto"          # splu for beams and small scenes; pardiso (else splu-rcm) for coupled ones
SADDLE_PERTURB = 8        # PARDISO on saddle-point systems: pivots perturbed to 1e-8 |K| (iparm(10))
SADDLE_REFINE = 20        # ... and up to 20 steps of iterative refinement (iparm(8)); ``Solver.factorize``
SADDLE_SPLU_ORDERING = "MMD_AT_PLUS_A"   # splu on saddle-point systems; "COLAMD" factorises the main job's bordered
                                  # tangents in 0.40 ms against 0.63 (20 % less fill), but its round-off took the
                                  # plectoneme's five-turn run into a crawl at t = 0.6553 (docs/benchmarks.md, session 8)
DENSE_MAX_UNKNOWNS = 256       # "auto": saddle-point systems up to this size "dense" (LAPACK getrf); 0: none.  The main
#                                job's condensed / bordered multiplier systems (180-230 unknowns) in 0.33 ms against
#                                SuperLU's 0.86, the main job 13 % faster, poses 2e-13 off; plain tangents never (a
#                                slender beam's band: the roll-up of slenderness 1e3 1.2e-9 off its closed form against
#                                6.5e-11).  docs/benchmarks.md, session 14, branch bF, and session 15 (the plectoneme's
#                                five-turn run passes with it: its stall in session 14 was exact stick's tail rule)
AUTO_MIN_UNKNOWNS = 1_500      # "auto": below this size the default splu is as fast as any
AUTO_COUPLED_NNZ = 24.0        # "auto": non-zeros per column above which contact couples the beams
BACKWARD_ERROR = 1e-9          # pardiso, splu-rcm: |K x - b| / (|K| |x| + |b|) above this -> re-analyse / pivot fully
RCM_PIVOT_THRESHOLD = 1e-3     # splu-rcm: keep the diagonal pivot unless below this fraction of the column's largest
SINGULAR_RESIDUAL = 1e-6       # pardiso, with perturbed pivots: |K x - b| / |b| above this -> singular
ONE_BASED = True               # PARDISO called with its 1-based index arrays kept per pattern (``_Pardiso._call``)
FREE_DROPPED = True            # PARDISO's numerical factor freed (phase 0) once the caller drops its factorisation
MATCHING_OFF_MIN = 50_000      # int: PARDISO analyses non-saddle matrices of at least this many unknowns without its
#                                weighted matching (iparm(13) = 0: half of the analysis on the rope pieces, the same
#                                fill, solutions within 4e-9; a rope's new pattern 1.45-1.56 -> 1.11-1.31 x a repeated
#                                iteration, docs/benchmarks.md "Scaling, session 9"); None: MKL's default (on) everywhere
                               # (``_Pardiso._dropped``; the analysis is kept: 1 GB on the 0.6 m rope between iterations)
LAGGED = "auto"                # Solver(lagged=None): the previous factor as GMRES preconditioner where it pays
LAG_MAX_ITERATIONS = 30        # GMRES iterations of a lagged solve at most
LAG_MIN_ITERATIONS = 4         # "auto": no lagging where the budget is smaller (cheap factorisations)
LAG_MIN_FLOPS = 1e8            # "auto": no lagging below (factorisations of ~10 ms: GMRES' Python overheads weigh)
LAG_COST_SHARE = 0.5           # "auto": a lagged solve may cost this share of a re-factorisation
LAG_FLOPS_PER_ENTRY = 20.0     # "auto": a GMRES iteration costs a re-factorisation's time at this many flops/entry
LAG_ANALYSIS_ITERATIONS = 16   # "auto": PARDISO's symbolic analysis costs this many GMRES iterations
LAG_MAX_BACKOFF = 8            # failed lagged solves in a row: 0, 1, 2, 4, .. this many fresh factorisations between tries
LAG_REFRESH_SHARE = 0.5        # a lagged solve over this share of its budget: the next tangent is factorised afresh
DROP_BASE_AT_COMMIT = True     # the stepping drops the lagged solves' base at every accepted step (``Solver.drop_base``:
#                                PARDISO's numerical factor not held through the commit and the next step's first
#                                evaluations; that step's first tangent is then factorised afresh, not lagged)


class SingularMatrixError(RuntimeError):
    """The tangent is (numerically) singular."""


_PYPARDISO = []


def _mkl_rt():
    """Where MKL's ``mkl_rt`` library is, looked up in ``lib`` (``Library/bin``) of ``sys.prefix`` and of the
    user base without recursion (None if not there).  pypardiso's own look-up, when ``PYPARDISO_MKL_RT`` is not
    set and ``find_library`` fails (pip installs), globs ``sys.prefix/lib*/**`` recursively, site-packages
    included, twice per process (its import makes a solver, ``_pardiso_handle`` another): 0.6-0.9 s of start-up
    here (``benchmarks/jit_startup.py``)."""
    import glob
    import site
    import sys
    for base in (sys.prefix, getattr(site, "USER_BASE", None) or ""):
        for sub, pattern in (("lib", "libmkl_rt.so*"), ("lib", "libmkl_rt*.dylib"), ("Library/bin", "mkl_rt*.dll")):
            found = sorted(glob.glob(os.path.join(base, sub, pattern)), key=len)
            if found:
                return found[0]
    return None


def _pypardiso():
    """The pypardiso module, or None if it is not installed (looked up once; MKL's library found for it,
    ``_mkl_rt``, unless ``PYPARDISO_MKL_RT`` says where)."""
    if not _PYPARDISO:
        if not os.environ.get("PYPARDISO_MKL_RT"):
            path = _mkl_rt()
            if path is not None:
                os.environ["PYPARDISO_MKL_RT"] = path
        try:
            import pypardiso
        except ImportError:
            pypardiso = None
        _PYPARDISO.append(pypardiso)
    return _PYPARDISO[0]


def available():
    """The back-ends usable here (``"auto"`` always is)."""
    return [b for b in BACKENDS if b != "pardiso" or _pypardiso() is not None]


def _check(backend):
    backend = DEFAULT if backend is None else backend
    if backend not in BACKENDS:
        raise InputError(f"linear_solver: unknown back-end {backend!r}; known: {', '.join(BACKENDS)}")
    if backend == "pardiso" and _pypardiso() is None:
        raise InputError("linear_solver='pardiso': the pardiso back-end needs the package pypardiso, "
                         "which is not installed (pip install \"beamsolver[fast]\" or pip install pypardiso; "
                         "x86-64 only)")
    return backend


def factorize(K, backend=None):
    """Factorise the square sparse matrix ``K``; returns an object with ``solve(b)``.

    A one-shot call: for repeated factorisations of matrices with the same
    pattern (Newton iterations) keep a ``Solver`` instead, which reuses
    PARDISO's symbolic analysis.
    """
    return Solver(backend).factorize(K)


def factorize_tangent(K, solver=None, what="singular tangent", saddle=False, fresh=False, kind=None):
    """``solver.factorize(K)`` (default a fresh ``Solver()``) as a factor whose singularity, found
    by the factorisation or by a solve (pardiso), is the typed step failure
    ``failures.SingularTangent(f"{what} ({error})")``: the one wrapper of the Newton loop, the
    arc-length solves and the branch switch.  The factor keeps the back-end's ``det_sign`` and
    ``factor_nnz`` where it has them.  ``saddle``: ``K`` is a saddle-point system (``Solver.factorize``);
    ``fresh``: not lagged (``Solver.fresh``); ``kind``: ``Solver.factorize``'s."""
    solver = solver if solver is not None else Solver()
    try:
        if fresh:
            return _Typed(solver.fresh(K), what)
        return _Typed(solver.factorize(K, saddle=saddle, **({} if kind is None else dict(kind=kind))), what)
    except SingularMatrixError as e:
        raise SingularTangent(f"{what} ({e})") from None


class _Typed:
    """A back-end factor whose ``solve`` raises ``SingularTangent`` (``factorize_tangent``)."""

    def __init__(self, lu, what):
        self.lu, self.what = lu, what

    def solve(self, b):
        try:
            return self.lu.solve(b)
        except SingularMatrixError as e:       # pardiso reports singularity at the solve
            raise SingularTangent(f"{self.what} ({e})") from None

    def __getattr__(self, name):               # det_sign, factor_nnz of the back-end, if it has them
        if name == "lu":
            raise AttributeError(name)
        return getattr(self.lu, name)


class Solver:
    """A linear-solver back-end kept across Newton iterations (``factorize(K)`` per iteration)."""

    def __init__(self, backend=None, lagged=None):
        self.requested = _check(backend)
        self.lagged = LAGGED if lagged is None else lagged
        if self.lagged not in ("auto", True, False):
            raise InputError(f"linsolve: lagged must be 'auto', True or False, got {self.lagged!r}")
        self._pardiso = None            # _Pardiso handle, created on first use
        self._base = None               # the last fresh factor, the lagged solves' preconditioner
        self._base_shape = None
        self._base_kind = None          # ``factorize(kind=)`` of the base: lagging only between matrices of one kind
        self._refresh = False           # the next factorize is a fresh one
        self._skip = 0                  # fresh factorisations before the next lagged try (``lagged_done``)
        self._backoff = 0               # the skip after the next failed lagged solve
        self.stats = dict(factorizations=0, analyses=0, lagged=0, krylov_iterations=0, lag_failures=0)

    def backend_for(self, K, saddle=False):
        """The back-end ``factorize`` uses for ``K`` (resolves ``"auto"``).

        The rule of ``"auto"``, by size and coupling (symmetry plays no part: Newton tangents are
        unsymmetric, module docstring):

        - a saddle-point system (``saddle``) of at most ``DENSE_MAX_UNKNOWNS`` (256; 0: none) unknowns: ``"dense"``;
        - fewer than ``AUTO_MIN_UNKNOWNS`` unknowns, or at most ``AUTO_COUPLED_NNZ`` non-zeros per
          column (a beam or a frame: about 18; no contact coupling many beams): ``"splu"``.  A
          beam's matrix is a band, SuperLU's MMD ordering finds it, and neither PARDISO's analysis
          nor an RCM pass pays (a 60 000-unknown cable factorises in 0.06-0.19 s);
        - coupled (bundles, ropes): ``"pardiso"`` when pypardiso imports (a dependency on x86-64
          Linux and Windows), else ``"splu-rcm"``, the pure-scipy fallback.  PARDISO does the
          same work as SuperLU after RCM 2x faster at 37 wires and 4x at 61 (1.6 s against 6.3 s,
          0.6 GB against 2.4 GB), and ties on a re-factorisation at 19 wires (0.09 s).
        """
        if self.requested != "auto":
            return self.requested
        n = K.shape[0]
        if saddle and n <= DENSE_MAX_UNKNOWNS:
            return "dense"
        if n >= AUTO_MIN_UNKNOWNS and K.nnz > AUTO_COUPLED_NNZ * n:
            return "pardiso" if _pypardiso() is not None else "splu-rcm"
        return "splu"

    def lag_budget(self, f, analysis=False):
        """GMRES iterations a lagged solve preconditioned by the fresh factor ``f`` may take (0: no
        lagging); ``analysis``: whether a fresh factorisation of the new matrix would redo the
        symbolic analysis (its pattern differs from ``f``'s).

        ``lagged=True``: ``LAG_MAX_ITERATIONS``.  ``"auto"``: ``LAG_COST_SHARE`` of a fresh
        factorisation counted in GMRES iterations (one triangular solve with ``f``, one product with
        the matrix), at most ``LAG_MAX_ITERATIONS``, none below ``LAG_MIN_ITERATIONS`` (cheap
        factorisations: small scenes, beams).  Measured with PARDISO on bundles, strands and their
        loaded steps of 19..61 wires (docs/benchmarks.md, issue 30): a re-factorisation costs
        ``flops / (LAG_FLOPS_PER_ENTRY fill)`` iterations (PARDISO reports both; 18-22 flops per
        factor entry measured), an analysis ``LAG_ANALYSIS_ITERATIONS`` more (14-18 measured);
        back-ends without flops and factorisations under ``LAG_MIN_FLOPS`` (the twisted pair of
        128 elements per wire with PARDISO: 10 % slower per Newton iteration when lagged): no lagging.
        """
        if self.lagged is False:
            return 0
        if self.lagged is True:
            return LAG_MAX_ITERATIONS
        flops = float(getattr(f, "flops", np.nan))
        if not (np.isfinite(flops) and flops >= LAG_MIN_FLOPS):     # (before ``factor_nnz``: SuperLU's builds L, U)
            return 0
        fill = float(f.factor_nnz)
        if fill <= 0:
            return 0
        fresh = flops / (LAG_FLOPS_PER_ENTRY * fill) + (LAG_ANALYSIS_ITERATIONS if analysis else 0.0)
        its = int(min(LAG_COST_SHARE * fresh, LAG_MAX_ITERATIONS))
        return its if its >= LAG_MIN_ITERATIONS else 0

    def factorize(self, K, saddle=False, kind=None):
        """A factor of ``K`` with ``solve(b)``: fresh, or lagged (``lagged.LaggedFactor``: GMRES
        preconditioned by the last fresh factor, while ``lag_budget`` allows, the shape holds and
        the previous lagged solve took at most ``LAG_REFRESH_SHARE`` of its budget).  ``saddle``: ``K`` is
        a saddle-point system (multiplier unknowns, ``Problem.bordered``), always factorised afresh: PARDISO
        perturbs tiny pivots to ``SADDLE_PERTURB`` (not 1e-13) and refines the solution up to
        ``SADDLE_REFINE`` steps, which its static pivoting needs there (19-wire bundle, exact stick, 55 000
        unknowns: 709 perturbed pivots, a residual 7.6e3 |b| with the defaults, 2.4e-9 |b| so); SuperLU
        pivots by rows itself.  ``kind``: a label of the matrix family (``augmented``'s ``A`` against a plain
        tangent of the same shape): a factor of another kind does not precondition it."""
        if K.shape[0] != K.shape[1]:
            raise InputError(f"linsolve: the matrix must be square, got shape {K.shape}")
        if saddle:
            return self.fresh(K, saddle=True)
        if kind != self._base_kind:
            self._refresh = True
        self._base_kind = kind
        base = self._base
        if self._skip > 0:
            self._skip -= 1
        elif (base is not None and not self._refresh and self._base_shape == K.shape
                and self.backend_for(K) == base.backend):
            budget = self.lag_budget(base, analysis=not _same_pattern(base, K))
            if budget > 0:
                self.stats["lagged"] += 1
                return LaggedFactor(self, K, budget)
        return self.fresh(K)

    def fresh(self, K, saddle=False):
        """A new factorisation of ``K`` (``factorize`` without lagging); it preconditions the next
        lagged solves if ``lag_budget`` may allow them (not for saddle-point systems)."""
        self._base = None                       # (its matrix freed before the new factorisation)
        f = self._factorize(K, saddle)
        self._base = f if not saddle and self.lag_budget(f, analysis=True) > 0 else None
        self._base_shape = K.shape
        self._refresh = False
        return f

    def lagged_done(self, iterations, budget, converged):
        """Bookkeeping of a lagged solve (``LaggedFactor``): its GMRES ``iterations`` of ``budget``;
        the next ``factorize`` is fresh if it took more than ``LAG_REFRESH_SHARE`` of the budget."""
        self.stats["krylov_iterations"] += iterations
        if converged:
            self._backoff = 0
        else:
            self.stats["lag_failures"] += 1
            self._skip, self._backoff = self._backoff, min(max(2 * self._backoff, 1), LAG_MAX_BACKOFF)
        self._refresh = iterations > LAG_REFRESH_SHARE * budget

    def drop_base(self):
        """Let the lagged solves' base go (PARDISO frees its numerical factor, ``FREE_DROPPED``, the analysis kept):
        the next ``factorize`` is fresh."""
        self._base = None
        self._refresh = True

    def _factorize(self, K, saddle=False):
        self.stats["factorizations"] += 1
        backend = self.backend_for(K, saddle)
        if backend == "splu":
            return _SpluFactor(K, SADDLE_SPLU_ORDERING if saddle else "MMD_AT_PLUS_A")
        if backend == "splu-rcm":
            return _SpluRcmFactor(K)
        if backend == "dense":
            return _DenseFactor(K)
        if self._pardiso is None:
            self._pardiso = _Pardiso(_pypardiso())
        return self._pardiso.factorize(K, self.stats, saddle)

    def close(self):
        """Release PARDISO's memory now (it is also released when the ``Solver`` is collected)."""
        self._base = None
        if self._pardiso is not None:
            self._pardiso.release()
            self._pardiso = None


class _SpluFactor:
    backend = "splu"

    def __init__(self, K, ordering="MMD_AT_PLUS_A"):
        if not (sp.issparse(K) and K.format == "csc"):
            K = sp.csc_matrix(K)
        try:
            self._lu = spla.splu(K, permc_spec=ordering)
        except RuntimeError as e:          # "Factor is exactly singular"
            raise SingularMatrixError(str(e)) from None

    @property
    def factor_nnz(self):
        return int(self._lu.L.nnz + self._lu.U.nnz)

    def solve(self, b):
        return self._lu.solve(np.asarray(b, dtype=float))

    apply = solve          # as a preconditioner (``lagged``): the same solve

    def det_sign(self):
        """Sign of ``det(K)`` (1, -1; 0 for a zero pivot): SuperLU factors ``Pr K Pc = L U`` with a
        unit diagonal in ``L``, so it is the sign of ``prod diag(U)`` times the parities of the
        two permutations."""
        d = self._lu.U.diagonal()
        return int(np.prod(np.sign(d))) * permutation_sign(self._lu.perm_r) * permutation_sign(self._lu.perm_c)


class _DenseFactor:
    """LAPACK's ``dgetrf`` of ``K`` made dense (``P K = L U``, partial pivoting); ``solve`` by ``dgetrs``."""
    backend = "dense"

    def __init__(self, K):
        from scipy.linalg.lapack import dgetrf
        A = K.toarray() if sp.issparse(K) else np.array(K, dtype=float)
        self._lu, self._piv, info = dgetrf(np.asfortranarray(A, dtype=float), overwrite_a=1)
        if info > 0 or not np.all(np.isfinite(self._lu.diagonal())):
            raise SingularMatrixError("Factor is exactly singular")
        if info < 0:
            raise ValueError(f"dgetrf: illegal argument {-info}")

    @property
    def factor_nnz(self):
        return int(self._lu.size)

    def solve(self, b):
        from scipy.linalg.lapack import dgetrs
        x, info = dgetrs(self._lu, self._piv, np.asarray(b, dtype=float))
        if info != 0:
            raise ValueError(f"dgetrs: illegal argument {-info}")
        return x

    apply = solve          # as a preconditioner (``lagged``): the same solve

    def det_sign(self):
        """Sign of ``det(K)`` (1, -1; 0 for a zero pivot): that of ``prod diag(U)`` times ``(-1)`` per row
        interchange (``piv[i] != i``, LAPACK's 0-based pivots in scipy)."""
        swaps = int(np.count_nonzero(self._piv != np.arange(len(self._piv))))
        return int(np.prod(np.sign(self._lu.diagonal()))) * (-1 if swaps % 2 else 1)


def _same_pattern(f, K):
    """Whether ``K`` has the pattern of the matrix of the factor ``f`` (if ``f`` keeps it)."""
    A = getattr(f, "K", None)
    return (A is not None and A.format == K.format and A.shape == K.shape and A.nnz == K.nnz
            and np.array_equal(A.indptr, K.indptr) and np.array_equal(A.indices, K.indices))


def permutation_sign(p):
    """Sign (1 or -1) of the permutation ``p`` of ``0..n-1``: ``(-1)^(n - cycles)`` (compiled cycle count)."""
    p = np.ascontiguousarray(p, dtype=np.int64)
    return -1 if (len(p) - _cycles(p)) % 2 else 1


@jit
def _cycles(p):
    """Number of cycles of the permutation ``p``."""
    seen = np.zeros(len(p), dtype=np.bool_)
    count = 0
    for i in range(len(p)):
        if not seen[i]:
            count += 1
            j = i
            while not seen[j]:
                seen[j] = True
                j = p[j]
    return count


class _SpluRcmFactor:
    """SuperLU on the matrix symmetrically permuted by reverse Cuthill-McKee, natural column order.

    For long bundles of wires in contact SuperLU's own orderings give much more
    fill (docs/benchmarks.md); the RCM band (``scipy.sparse.csgraph``, O(nnz)) is near
    optimal for long, thin structures.  ``SymmetricMode`` prefers the diagonal, and threshold partial
    pivoting (``RCM_PIVOT_THRESHOLD``) keeps it unless it is smaller than that fraction of
    the column's largest entry: the band stays a band.  A solution whose backward
    error exceeds ``BACKWARD_ERROR`` is recomputed with full partial pivoting.  The ordering
    and the permuted pattern are kept for the next matrix of the same pattern (``_rcm``).
    """
    backend = "splu-rcm"

    def __init__(self, K):
        if not sp.issparse(K) or K.format not in ("csc", "csr"):
            K = sp.csc_matrix(K)
        if not K.has_canonical_format:          # no duplicates: the entries map one to one
            K = K.copy()
            K.sum_duplicates()
        perm, where, indices, indptr = _rcm(K)
        self.perm, self._K = perm, K
        self._Kp = sp.csc_matrix((np.asarray(K.data)[where], indices, indptr), shape=K.shape)
        self._lu = self._splu(RCM_PIVOT_THRESHOLD)

    def _splu(self, threshold):
        try:
            return spla.splu(self._Kp, permc_spec="NATURAL", diag_pivot_thresh=threshold,
                             options=dict(SymmetricMode=True))
        except RuntimeError as e:
            raise SingularMatrixError(str(e)) from None

    @property
    def factor_nnz(self):
        return int(self._lu.L.nnz + self._lu.U.nnz)

    def _solve(self, b):
        y = self._lu.solve(b[self.perm])
        x = np.empty_like(y)
        x[self.perm] = y
        return x

    def apply(self, b):
        """The solve without its accuracy check (as a preconditioner, ``lagged``)."""
        return self._solve(np.asarray(b, dtype=float))

    def solve(self, b):
        b = np.asarray(b, dtype=float)
        x = self._solve(b)
        if not np.all(np.isfinite(x)) or _backward_error(self._K, x, b) > BACKWARD_ERROR:   # a small pivot grew
            self._lu = self._splu(1.0)
            x = self._solve(b)
        return x


_RCM_LAST = []      # the last (pattern, ordering) of ``_rcm``


def _rcm(K):
    """RCM ordering of ``K``'s pattern and the symmetrically permuted CSC pattern:
    ``(perm, where, indices, indptr)`` with ``K_p.data = K.data[where]``.  Kept for the last
    pattern (Newton iterations with the same active contact pairs).  A CSC ``K`` (what
    ``System.matrix`` gives) takes the compiled ``_rcm_csc``, others scipy's ``_rcm_scipy``:
    the same arrays (both canonical, the same graph for the ordering)."""
    key = (K.format, K.shape)
    if _RCM_LAST:
        k, ptr, ind, out = _RCM_LAST[0]
        if k == key and np.array_equal(ptr, K.indptr) and np.array_equal(ind, K.indices):
            return out
    fast = K.format == "csc" and K.nnz < np.iinfo(np.int32).max and K.has_canonical_format
    out = _rcm_csc(K) if fast else _rcm_scipy(K)
    _RCM_LAST[:] = [(key, K.indptr.copy(), K.indices.copy(), out)]
    return out


def _rcm_scipy(K):
    """``_rcm`` by scipy: the entry numbers (1..nnz, exact as floats) travel through the same
    permutation as the values."""
    from scipy.sparse.csgraph import reverse_cuthill_mckee
    numbers = K.__class__((np.arange(1.0, K.nnz + 1.0), K.indices, K.indptr), shape=K.shape)
    A = sp.csr_matrix(numbers)
    pattern = sp.csr_matrix((np.ones(A.nnz), A.indices, A.indptr), shape=A.shape)
    perm = reverse_cuthill_mckee((pattern + pattern.T).tocsr(), symmetric_mode=True)
    Ap = A[perm][:, perm].tocsc()
    return perm, Ap.data.astype(np.int64) - 1, Ap.indices, Ap.indptr


def _rcm_csc(K):
    """``_rcm_scipy`` of a canonical CSC ``K`` in compiled passes, no sparse temporaries: the
    transposed pattern (``_transpose``), the graph ``pattern + pattern^T`` (``_union``) and the
    permuted pattern (``_permuted``), the canonical arrays scipy builds."""
    from scipy.sparse.csgraph import reverse_cuthill_mckee
    n = K.shape[0]
    ptr, ind = np.asarray(K.indptr, dtype=np.int64), np.asarray(K.indices, dtype=np.int32)
    t_ptr = np.empty(n + 1, dtype=np.int64)
    t_ind = np.empty(len(ind), dtype=np.int32)
    t_pos = np.empty(len(ind), dtype=np.int64)
    _transpose(ptr, ind, t_ptr, t_ind, t_pos)
    s_ptr = np.empty(n + 1, dtype=np.int32)
    s_ind = np.empty(2 * len(ind), dtype=np.int32)
    m = _union(ptr, ind, t_ptr, t_ind, s_ptr, s_ind)
    perm = reverse_cuthill_mckee(sp.csr_matrix((np.ones(m), s_ind[:m], s_ptr), shape=K.shape), symmetric_mode=True)
    where = np.empty(len(ind), dtype=np.int64)
    indices = np.empty(len(ind), dtype=np.int32)
    indptr = np.empty(n + 1, dtype=np.int32)
    _permuted(ptr, t_ptr, t_ind, t_pos, perm, where, indices, indptr)
    return perm, where, indices, indptr


@jit
def _transpose(ptr, ind, t_ptr, t_ind, t_pos):
    """The transpose of the compressed pattern ``(ptr, ind)`` (square): sorted, with each entry's
    position ``t_pos`` in the input (a stable counting sort)."""
    n = len(ptr) - 1
    t_ptr[:] = 0
    for p in range(len(ind)):
        t_ptr[ind[p] + 1] += 1
    for i in range(n):
        t_ptr[i + 1] += t_ptr[i]
    nxt = t_ptr[:-1].copy()
    for j in range(n):
        for p in range(ptr[j], ptr[j + 1]):
            i = ind[p]
            t_ind[nxt[i]] = j
            t_pos[nxt[i]] = p
            nxt[i] += 1


@jit
def _union(ptr, ind, t_ptr, t_ind, s_ptr, s_ind):
    """The union of two sorted patterns (a pattern and its transpose), sorted; returns its size."""
    m = 0
    s_ptr[0] = 0
    for j in range(len(ptr) - 1):
        a, a_end, b, b_end = ptr[j], ptr[j + 1], t_ptr[j], t_ptr[j + 1]
        while a < a_end or b < b_end:
            if b >= b_end or (a < a_end and ind[a] < t_ind[b]):
                s_ind[m] = ind[a]
                a += 1
            elif a >= a_end or t_ind[b] < ind[a]:
                s_ind[m] = t_ind[b]
                b += 1
            else:
                s_ind[m] = ind[a]
                a += 1
                b += 1
            m += 1
        s_ptr[j + 1] = m
    return m


@jit
def _permuted(ptr, t_ptr, t_ind, t_pos, perm, where, indices, indptr):
    """CSC pattern of ``K[perm][:, perm]`` and the position in ``K`` of each entry (``where``), from
    ``K``'s column starts ``ptr`` and its transpose ``(t_ptr, t_ind, t_pos)``: the rows taken in the
    new order fill each new column in ascending row order."""
    n = len(ptr) - 1
    inv = np.empty(n, dtype=np.int64)
    indptr[0] = 0
    for j in range(n):
        inv[perm[j]] = j
        indptr[j + 1] = indptr[j] + (ptr[perm[j] + 1] - ptr[perm[j]])
    nxt = np.empty(n, dtype=np.int64)
    for j in range(n):
        nxt[j] = indptr[j]
    for i in range(n):
        r = perm[i]
        for q in range(t_ptr[r], t_ptr[r + 1]):
            j = inv[t_ind[q]]
            indices[nxt[j]] = i
            where[nxt[j]] = t_pos[q]
            nxt[j] += 1


def _backward_error(K, x, b):
    """``|K x - b| / (|K| |x| + |b|)`` in the max norm."""
    r = np.abs(K @ x - b).max(initial=0.0)
    scale = np.asarray(abs(K).sum(axis=1)).max(initial=0.0) * np.abs(x).max(initial=0.0) + np.abs(b).max(initial=0.0)
    return r / scale if scale > 0 else r



def _NONE():
    """A dead weak reference's call: ``None``."""
    return None


class _Pardiso:
    """One PARDISO handle (``pypardiso.PyPardisoSolver``), driven phase by phase.

    Uses pypardiso's ``_check_A`` / ``_call_pardiso`` / ``set_phase`` to run
    phase 11 (ordering + symbolic analysis) only when the pattern changes,
    22 (numerical factorisation) per matrix and 33 (solve) per right-hand
    side; falls back to pypardiso's public ``factorize`` / ``solve`` (an
    analysis per matrix) if those helpers are missing.
    """

    def __init__(self, pypardiso):
        self.ps = _pardiso_handle(pypardiso)
        self._phased = all(hasattr(self.ps, a) for a in ("_check_A", "_check_b", "_call_pardiso", "set_phase"))
        # PARDISO called with the analysed pattern's 1-based index arrays, made once (``_call``)
        self._direct = ONE_BASED and self._phased and all(
            hasattr(self.ps, a) for a in ("_mkl_pardiso", "pt", "_pt_type", "mtype", "phase", "perm", "iparm", "msglvl"))
        self.pattern = None           # (indptr + 1, indices + 1 as int32, format) of the analysed matrix
        # the factorisation whose values PARDISO holds, as a weak reference: the caller's last factor
        # (and its matrix) is freed as soon as the caller drops it, before the next tangent is built
        self.current = _NONE
        self.flops = float("nan")     # of the numerical factorisation, from the last analysis
        self._defaults = None         # iparm(8), iparm(10) of the handle (refinement steps, pivot perturbation)
        self._matching_default = None  # iparm(13) of the handle (``_matching``)

    def factorize(self, K, stats, saddle=False):
        K = K.tocsr() if K.format not in ("csr", "csc") else K
        if K.dtype != np.float64:
            K = K.astype(np.float64)
        if K.shape[0] and not np.diff(K.indptr).all():
            raise SingularMatrixError("the matrix has an empty row or column")
        f = _PardisoFactor(self, K)
        f.saddle = bool(saddle)
        self._factor(f, stats)
        return f

    def _factor(self, f, stats=None, fresh=False):
        K, ps = f.K, self.ps
        set_ = self._saddle(f.saddle)
        if not self._phased:
            ps.factorize(K)
            f.reused = False
        else:
            ps._check_A(K)                     # sorts indices, sets the CSR/CSC (transposed) flag
            same = (not fresh and self.pattern is not None and self.pattern[2] == K.format
                    and _same_shifted(self.pattern[0], K.indptr) and _same_shifted(self.pattern[1], K.indices))
            zero = np.zeros((K.shape[0], 1))
            if not same:                       # ordering + symbolic analysis (phase 11), then phase 22 alone
                self.pattern = (_one_based(K.indptr), _one_based(K.indices), K.format)
                self._matching(K.shape[0], f.saddle)
                ps.iparm[18] = -1              # report the factorisation's Mflops (MKL iparm(19))
                if stats is not None:
                    stats["analyses"] += 1
                ps.set_phase(11)
                self._call(K, zero)
                self.flops = 1e6 * float(ps.iparm[18])
                if f.saddle and not set_:
                    self._saddle(True)         # MKL's defaults were filled in by that call
            ps.set_phase(22)
            self._call(K, zero)
            f.reused = same
        self.current = weakref.ref(f, _dropped_callback(self)) if FREE_DROPPED and self._phased else weakref.ref(f)
        iparm = ps.iparm
        f.perturbed = int(iparm[13])
        f.factor_nnz = int(iparm[17])
        f.peak_kb = int(max(iparm[14], iparm[15] + iparm[16]))
        f.flops = self.flops

    def _matching(self, n, saddle):
        """Before an analysis: PARDISO's weighted matching off for a non-saddle matrix of ``n >= MATCHING_OFF_MIN``
        unknowns (MKL's defaults written first on a fresh handle, ``pardisoinit``), else back to MKL's default."""
        ps = self.ps
        off = MATCHING_OFF_MIN is not None and not saddle and n >= MATCHING_OFF_MIN
        if off and ps.iparm[0] == 0 and hasattr(ps, "libmkl"):
            import ctypes
            transposed = int(ps.iparm[11])        # (pypardiso's ``_check_A``: CSC handed over as the CSR of K^T)
            ps.libmkl.pardisoinit(ps.pt.ctypes.data_as(ctypes.POINTER(ps._pt_type[0])),
                                  ctypes.byref(ctypes.c_int32(ps.mtype)),
                                  ps.iparm.ctypes.data_as(ctypes.POINTER(ctypes.c_int32)))
            ps.iparm[11] = transposed
        if ps.iparm[0] == 0:
            return
        if self._matching_default is None:
            self._matching_default = int(ps.iparm[12])
        ps.iparm[12] = 0 if off else self._matching_default

    def _saddle(self, saddle):
        """Set the pivot perturbation and refinement steps for a saddle-point system (``Solver.factorize``) or
        back to the handle's own; False while MKL's defaults are not filled in (before the first call,
        ``iparm(1) = 0``: MKL ignores the other entries then)."""
        ps = self.ps
        if ps.iparm[0] == 0:
            return False
        if self._defaults is None:
            self._defaults = (int(ps.iparm[7]), int(ps.iparm[9]))
        ps.iparm[7], ps.iparm[9] = (SADDLE_REFINE, SADDLE_PERTURB) if saddle else self._defaults
        return True

    def solve(self, f, b):
        if self.current() is not f:           # another matrix was factorised since: redo this one
            self._factor(f)
        b = np.asarray(b, dtype=float)
        x = self._solve(f, b)
        # PARDISO perturbs tiny pivots instead of stopping at a singular matrix, and a
        # reused analysis (pivot order and scaling from older values) may lose accuracy:
        # check the solution (one product with K) and re-analyse once if it is poor
        bad = _poor(f, x, b)
        if bad and f.reused:
            self._factor(f, fresh=True)
            x = self._solve(f, b)
            bad = _poor(f, x, b)
        if bad:
            raise SingularMatrixError(f"pardiso: singular matrix ({bad}, {f.perturbed} perturbed pivots)")
        return x

    def apply(self, f, b):
        """``solve`` without the check (``_poor``) and without PARDISO's iterative refinement (two
        steps by default, ``iparm(8)``: three triangular solves and two products): a
        preconditioner's solve, a third of the time."""
        if self.current() is not f:
            self._factor(f)
        steps = self.ps.iparm[7]
        self.ps.iparm[7] = 0
        try:
            return self._solve(f, np.asarray(b, dtype=float))
        finally:
            self.ps.iparm[7] = steps

    def _solve(self, f, b):
        ps, K = self.ps, f.K
        if not self._phased:
            return ps.solve(K, b)
        ps._check_A(K)
        bb = ps._check_b(K, b)
        ps.set_phase(33)
        return self._call(K, bb).reshape(b.shape)

    def _call(self, K, b):
        """pypardiso's ``_call_pardiso(K, b)`` for the analysed pattern (``self.pattern``: ``K``'s) with its 1-based
        int32 index arrays made once per pattern, not twice at every call (two copies of ``K.indices`` a call:
        0.3 GB at a time on the rope of 0.6 m, and the time of the copies at every preconditioner solve)."""
        ps = self.ps
        if not self._direct:
            return ps._call_pardiso(K, b)
        import ctypes
        ia, ja = self.pattern[0], self.pattern[1]
        x = np.zeros_like(b)
        err = ctypes.c_int32(0)
        i32, f64 = ctypes.POINTER(ctypes.c_int32), ctypes.POINTER(ctypes.c_double)
        ps._mkl_pardiso(ps.pt.ctypes.data_as(ctypes.POINTER(ps._pt_type[0])), ctypes.byref(ctypes.c_int32(1)),
                        ctypes.byref(ctypes.c_int32(1)), ctypes.byref(ctypes.c_int32(ps.mtype)),
                        ctypes.byref(ctypes.c_int32(ps.phase)), ctypes.byref(ctypes.c_int32(K.shape[0])),
                        K.data.ctypes.data_as(f64), ia.ctypes.data_as(i32), ja.ctypes.data_as(i32),
                        ps.perm.ctypes.data_as(i32), ctypes.byref(ctypes.c_int32(1 if b.ndim == 1 else b.shape[1])),
                        ps.iparm.ctypes.data_as(i32), ctypes.byref(ctypes.c_int32(ps.msglvl)),
                        b.ctypes.data_as(f64), x.ctypes.data_as(f64), ctypes.byref(err))
        if err.value != 0:
            from pypardiso.pardiso_wrapper import PyPardisoError
            raise PyPardisoError(err.value)
        return np.ascontiguousarray(x)

    def _dropped(self, ref):
        """The factorisation PARDISO holds (``current``, the weak reference ``ref``) was dropped by its caller (a
        lagged ``Solver`` keeps its own): free PARDISO's numerical factor (phase 0), keep the analysis (the next
        matrix of the pattern runs phase 22 only: the same factor, the same bits)."""
        if self.current is not ref:
            return
        self.current = _NONE
        try:
            self.ps.free_memory(everything=False)
        except Exception:    # noqa: BLE001  (a weak reference's callback: nothing to raise to)
            pass

    def release(self):
        try:
            self.ps.free_memory(everything=True)
        except Exception:    # noqa: BLE001  (interpreter shutdown: the library may be gone)
            pass
        self.pattern, self.current = None, _NONE

    def __del__(self):
        self.release()


_TEMPLATE = []


def _dropped_callback(owner):
    """``weakref.ref``'s callback calling ``owner._dropped(ref)`` (``owner`` held weakly: no cycle)."""
    o = weakref.ref(owner)

    def dropped(ref):
        p = o()
        if p is not None:
            p._dropped(ref)
    return dropped


def _one_based(a):
    """``a + 1`` as int32 (PARDISO's 1-based index arrays)."""
    out = a.astype(np.int32)
    out += 1
    return out


@jit
def _shifted_equal(one, a):
    for i in range(len(a)):
        if one[i] != a[i] + 1:
            return False
    return True


def _same_shifted(one, a):
    """Whether the 1-based ``one`` is ``a + 1`` (no temporaries)."""
    return len(one) == len(a) and _shifted_equal(one, a)


def _pardiso_handle(pypardiso):
    """A fresh ``PyPardisoSolver`` (own PARDISO handle ``pt``) sharing one loaded MKL library.

    ``PyPardisoSolver()`` looks MKL up with ``ctypes.util.find_library``, which
    runs a subprocess: that is done once, later handles are copies
    of the first with new ``pt``/``iparm``/``perm`` arrays.
    """
    if not _TEMPLATE:
        _TEMPLATE.append(pypardiso.PyPardisoSolver())
    t = _TEMPLATE[0]
    if not all(hasattr(t, a) for a in ("pt", "iparm", "perm", "factorized_A")):
        return pypardiso.PyPardisoSolver()
    ps = copy.copy(t)
    ps.pt, ps.iparm, ps.perm = np.zeros_like(t.pt), np.zeros_like(t.iparm), np.zeros_like(t.perm)
    ps.factorized_A = sp.csr_matrix((0, 0))
    return ps


class _PardisoFactor:
    backend = "pardiso"

    def __init__(self, owner, K):
        self._owner = owner
        self.K = K
        self.perturbed = 0
        self.saddle = False        # a saddle-point system (``Solver.factorize``)
        self.reused = False
        self.norm = None           # |K|_inf, computed on the first check
        self.factor_nnz = 0
        self.peak_kb = 0
        self.flops = float("nan")

    def solve(self, b):
        return self._owner.solve(self, b)

    def apply(self, b):
        """The solve without its accuracy check (as a preconditioner, ``lagged``)."""
        return self._owner.apply(self, b)


def _poor(f, x, b):
    """Why the PARDISO solution ``x`` of ``K x = b`` is not acceptable ('' if it is).

    Normwise backward error ``|K x - b| / (|K| |x| + |b|)`` (infinity norms)
    above ``BACKWARD_ERROR`` (a stable solve gives ~1e-15 however ill-conditioned
    ``K`` is); and, when pivots were perturbed (a zero pivot replaced by a tiny
    one: the matrix is singular to working precision, where splu raises), a
    residual above ``SINGULAR_RESIDUAL |b|``.
    """
    if not np.all(np.isfinite(x)):
        return "non-finite solution"
    r = np.abs(f.K @ x - b).max(initial=0.0)
    nb = np.abs(b).max(initial=0.0)
    if f.norm is None:
        f.norm = float(np.abs(f.K).sum(axis=1).max()) if f.K.nnz else 0.0
    eta = r / (f.norm * np.abs(x).max(initial=0.0) + nb) if r > 0 else 0.0
    if eta > BACKWARD_ERROR:
        return f"backward error {eta:.3g}"
    if f.perturbed and r > SINGULAR_RESIDUAL * nb:
        return f"relative residual {r / nb if nb > 0 else np.inf:.3g}"
    return ""
