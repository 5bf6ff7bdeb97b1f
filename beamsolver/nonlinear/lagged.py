"""The previous factorisation as a preconditioner (a lagged factorisation, Newton-Krylov).

While Newton converges the tangent changes less and less from one iteration to the next
(relative change ~0.5, 0.25, 0.1, 2e-2, 1e-3, 1e-6 on the 61-wire strand's loaded step,
docs/benchmarks.md), and the factorisation of the last one is an excellent preconditioner of the
next: right-preconditioned GMRES (``gmres``) then reaches the Newton step to ``LAG_RTOL`` of the
right-hand side in a few iterations, each one triangular solve and one product with the new matrix,
instead of a new factorisation.  ``linsolve.Solver`` decides when (``Solver.lag_budget``); a solve
that does not reach the tolerance within its budget falls back to a fresh factorisation of the
same matrix: the true residual ``|K x - b| <= LAG_RTOL |b|`` is checked after the iterations, so a
lagged Newton step is as good as a direct one for Newton's rate (solutions within ~1e-8 of the
direct ones on the bundles), at worst slower.
"""
import weakref

import numpy as np

__all__ = ["gmres", "LaggedFactor", "LAG_RTOL"]

LAG_RTOL = 1e-10        # |K x - b| / |b| a lagged solve must reach (a direct solve: 1e-15 .. 1e-10)
GIVE_UP_AFTER = 3       # GMRES iterations after which a hopeless solve stops (``_hopeless``)
GIVE_UP_FACTOR = 1.0    # hopeless: the mean rate so far needs this many times the budget


def _hopeless(reduction, k, rtol, m):
    """Whether ``k`` iterations that reduced the residual by ``reduction`` in all, at that mean rate,
    would need more than ``GIVE_UP_FACTOR`` times the ``m`` iterations allowed to reach ``rtol``: a
    preconditioner from a tangent too far away (a new load step, a changed contact set) costs
    ``GIVE_UP_AFTER`` iterations, not the budget (GMRES may speed up later: 2.0 gave up later and
    saved nothing on the recorded sequences of docs/benchmarks.md)."""
    if reduction <= 0.0:
        return False
    if reduction >= 1.0:
        return True
    return k * np.log(rtol) / np.log(reduction) > GIVE_UP_FACTOR * m


def _norm(x):
    """``|x|`` by einsum's own loop, not BLAS: OpenBLAS' threads next to PARDISO's spinning MKL threads turned a
    10 000-entry norm into 7 ms (2 cores; exact stick's outer GMRES, ``augmented``: 100 -> 45 ms a solve)."""
    return float(np.sqrt(np.einsum("i,i->", x, x)))


def gmres(matvec, precondition, b, rtol, max_iterations):
    """Right-preconditioned GMRES (Saad 2003, alg. 9.5, no restart) of ``K x = b`` from ``x = 0``.

    ``matvec(v)``: ``K v``; ``precondition(v)``: ``M^-1 v`` (``(n,)`` arrays); stops when the
    residual (GMRES' estimate, Givens rotations) is at most ``rtol |b|`` or after ``max_iterations``.
    Gram-Schmidt twice (CGS2; products and norms by einsum, not BLAS: ``_norm``); gives up early when the rate so
    far is hopeless
    (``_hopeless``).  Returns ``(x, iterations, converged)``, ``converged``
    from the true residual ``|b - K x| <= rtol |b|`` (one more product), ``x`` the last iterate.
    """
    b = np.asarray(b, dtype=float)
    n, m = len(b), int(max_iterations)
    beta = _norm(b)
    if beta == 0.0:
        return np.zeros(n), 0, True
    if m < 1:
        return np.zeros(n), 0, False
    V = np.empty((m + 1, n))
    Z = np.empty((m, n))
    Hh = np.zeros((m + 1, m))
    cs, sn = np.zeros(m), np.zeros(m)
    g = np.zeros(m + 1)
    g[0] = beta
    V[0] = b / beta
    k = 0
    while k < m:
        Z[k] = precondition(V[k])
        w = matvec(Z[k])
        h = np.einsum("ij,j->i", V[:k + 1], w)
        w -= np.einsum("i,ij->j", h, V[:k + 1])
        h2 = np.einsum("ij,j->i", V[:k + 1], w)
        w -= np.einsum("i,ij->j", h2, V[:k + 1])
        Hh[:k + 1, k] = h + h2
        w_norm = _norm(w)
        Hh[k + 1, k] = w_norm
        for i in range(k):                                   # the previous rotations on the new column
            a, c = Hh[i, k], Hh[i + 1, k]
            Hh[i, k], Hh[i + 1, k] = cs[i] * a + sn[i] * c, -sn[i] * a + cs[i] * c
        r = float(np.hypot(Hh[k, k], Hh[k + 1, k]))
        if r == 0.0:                                          # K M^-1 singular on the Krylov space
            break
        cs[k], sn[k] = Hh[k, k] / r, Hh[k + 1, k] / r
        Hh[k, k], Hh[k + 1, k] = r, 0.0
        g[k], g[k + 1] = cs[k] * g[k], -sn[k] * g[k]
        k += 1
        if abs(g[k]) <= rtol * beta or w_norm == 0.0:        # converged, or the exact solution (breakdown)
            break
        if k >= GIVE_UP_AFTER and _hopeless(abs(g[k]) / beta, k, rtol, m):
            break
        V[k] = w / w_norm
    if k == 0:
        return np.zeros(n), 0, False
    y = np.linalg.solve(np.triu(Hh[:k, :k]), g[:k])
    x = np.einsum("i,ij->j", y, Z[:k])
    converged = bool(_norm(b - matvec(x)) <= rtol * beta)
    return x, k, converged


class LaggedFactor:
    """``K`` solved by ``gmres`` preconditioned by the last fresh factor of ``solver``
    (``linsolve.Solver``), within ``budget`` iterations (``Solver.lag_budget``); otherwise (or for
    ``det_sign``) by a fresh factorisation of ``K`` (``Solver.fresh``), the next preconditioner.

    ``backend``, ``flops``, ``factor_nnz``: those of the preconditioner; ``iterations``: GMRES
    iterations of the last lagged solve (also when it fell back to a fresh factorisation)."""

    lagged = True

    def __init__(self, solver, K, budget):
        self.solver, self.K, self.budget = solver, K, budget
        base = solver._base
        self._preconditioner = weakref.ref(base)      # (for ``factor_nnz``; not kept alive)
        self.backend, self.flops = base.backend, getattr(base, "flops", float("nan"))
        self.direct = None            # the fresh factor of ``K``, once needed
        self.iterations = 0

    def solve(self, b):
        if self.direct is not None:
            return self.direct.solve(b)
        solver = self.solver
        base = solver._base
        if base is not None:
            x, its, ok = gmres(self.K.__matmul__, base.apply, b, LAG_RTOL, self.budget)
            self.iterations = its
            solver.lagged_done(its, self.budget, ok)
            if ok:
                return x
        self.direct = solver.fresh(self.K)
        return self.direct.solve(b)

    def apply(self, b):
        """The preconditioner's solve (the last fresh factor's ``apply``): an outer iteration that uses this
        factor as its own preconditioner (``augmented``) reports back with ``done``."""
        base = self.solver._base
        if base is None:                      # (a saddle system was factorised since: no preconditioner kept)
            if self.direct is None:
                self.direct = self.solver.fresh(self.K)
            return self.direct.apply(b)
        return base.apply(b)

    def done(self, iterations, converged):
        """Bookkeeping of an outer iteration preconditioned by ``apply`` (``Solver.lagged_done``)."""
        self.iterations = iterations
        self.solver.lagged_done(iterations, self.budget, converged)

    @property
    def factor_nnz(self):
        """Entries of the preconditioner's factor (0 once it is gone)."""
        base = self._preconditioner()
        return base.factor_nnz if base is not None else 0

    def __getattr__(self, name):
        """``det_sign`` (and any other attribute of a factor): from a fresh factorisation of ``K``."""
        if name in ("direct", "solver", "K", "budget", "_preconditioner", "iterations") or name.startswith("__"):
            raise AttributeError(name)
        if self.direct is None:
            base = self.solver._base
            if base is None or not hasattr(base, name):
                raise AttributeError(name)
            self.direct = self.solver.fresh(self.K)
        return getattr(self.direct, name)
