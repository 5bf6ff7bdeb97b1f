"""Exact stick's condensed saddle-point system solved through a matrix of the displacement size (issue 26, speed).

After the exact block elimination (``condense``) the Newton system is ``M = [[K', Kq], [Kl, D]]``: ``n`` free
unknowns, ``u`` kept multiplier components (``Kq`` ``(n, u)``, ``Kl`` ``(u, n)`` one group's slots per column /
row), ``D`` diagonal: 0 for a sticking group's tangential components, ``d`` in ``(-0.1, 0.1)`` for a sliding group
at the cone's edge, 1 on idle rows (``bordered``: their ``Kl`` row is empty).  A direct solve of ``M`` needs
PARDISO's perturbed pivots and refinement, afresh every iteration (``linsolve.Solver.factorize(saddle=True)``).

Here (the augmented Lagrangian on the linear level, Fortin & Glowinski 1983; Benzi, Golub & Liesen 2005, sec. 10.2):
``P = [[K', Kq], [Kl, P22]]`` with ``P22_j = -1 / E_j`` (``E`` diagonal, below) is inverted exactly by one
factorisation of

    A = K' + Kq E Kl,     v -> (du, db):  du = A^-1 (v_f + Kq E v_g),   db = E (Kl du - v_g),

and ``A`` has the tangent's own pattern (a group's ``Kq E Kl`` lies in its block), so it is factorised as the
penalty path's tangent is, non-saddle and lagged (``linsolve.Solver.factorize``).  GMRES (``lagged.gmres``) on
``M`` right-preconditioned by ``P^-1`` meets ``|M x - b| <= RTOL |b|`` (its products with ``K'`` itself: nothing
cancels), then one more preconditioned step (``POLISH``: the multipliers' last digits).  ``M P^-1 - I`` lives on
the multiplier rows, of size ``1 / (E S)`` (``S = Kl K'^-1 Kq``) where ``D = 0``: two iterations, and the step does
not depend on ``E`` (against the direct solve 2e-14 .. 1e-12 for ``RATIO`` 1e4 .. 1e9).  ``A`` is singular where
``E^-1 + S`` is: on a bundle at rest ``K'`` is nearly singular (the wires' spins, held by friction alone) with an
indefinite symmetric part, and ``A`` of the 19 wires is numerically singular for ``RATIO`` 0.1 .. 1e3, regular
from 1e5 to 1e9 (docs/theory_mortar.md 3b): hence the stiff default.
``E_j``: the sign of ``sum_a Kq_aj Kl_ja / k_a`` (``Kq_j = -c_j Kl_j^T`` for exact stick: negative) so that
``Kq E Kl`` stiffens, and ``|E_j| max_a |Kq_aj Kl_ja| / k_a = RATIO`` (``k_a`` the elements' diagonal stiffness of
slot ``a``).  A row with ``E_j d_j < 0`` takes ``P22 = d - 1 / E`` (exact up to ``1 / E``: ``A`` holds
``E / (1 - E d)``, softer), one with ``E_j d_j > 0`` ``P22 = -1 / E`` (``D - P22 = d + 1 / E``, GMRES absorbs it).
Idle rows and rows without coupling: ``P22 = D`` (or 1), ``Kl`` taken as empty there: exact.

``Augmented.solve`` counts in ``Solver.stats``: ``saddle_augmented`` (solves), ``saddle_iterations`` (GMRES),
``saddle_fallbacks``: a preconditioner (lagged, then fresh) that does not get there within its iterations falls
back to the direct saddle solve of ``M`` (``Problem.linear_system``'s), without a warning.
"""
import numpy as np

from .._jit import jit
from .lagged import gmres
from .linsolve import factorize_tangent
from ..failures import SingularTangent

__all__ = ["Augmented", "weights", "RATIO", "RTOL", "MAX_ITERATIONS", "MIN_UNKNOWNS", "ENABLED"]

RATIO = 1e6            # |E| times the constraint's stiffness over the structure's (answers do not depend on it)
RTOL = 1e-10           # |M x - b| / |b| GMRES must reach (``lagged.LAG_RTOL``; the direct saddle solve: 2e-9, 19 wires)
MAX_ITERATIONS = 30    # GMRES iterations with a fresh factorisation of ``A`` before the direct fallback
POLISH = True          # after GMRES, one more step of the preconditioned iteration (the multipliers' last digits)
LAGGED = True          # ``A`` factorised through the solver's lagging (``linsolve.Solver.factorize``), else afresh
MIN_UNKNOWNS = 300     # smaller saddle systems are factorised directly (SuperLU); from 300 the augmented path is faster
                       # (the twisted pair at 32 / 64 el/wire: 8.8 -> 5.9 / 22.9 -> 10.6 ms an iteration, benchmarks/saddle_size.py)
ENABLED = True         # False: ``Newton.direction`` solves the saddle system directly (benchmarks: before)
STATS = ("saddle_augmented", "saddle_iterations", "saddle_fallbacks")


def weights(Kq, Kl, free, kdiag, d, idle):
    """``(E, p22)`` ``(u,)``: the augmentation of each kept row (0: none) and the preconditioner's diagonal
    entry there, from the rows' couplings ``Kq``, ``Kl`` ``(u, k6)`` (columns / rows of the group's slots), the
    slots' freedom ``free`` and the elements' diagonal stiffness ``kdiag`` ``(u, k6)``, ``D``'s entries ``d`` and
    the idle rows ``idle`` ``(u,)`` (module docstring).  Compiled (``_couplings``, ``_weights_of``) but for the rows'
    sums, numpy's (their sign: the same pairwise sums)."""
    u = len(d)
    p, scale = np.empty(np.shape(Kq)), np.empty(u)
    _couplings(np.ascontiguousarray(Kq, dtype=float), np.ascontiguousarray(Kl, dtype=float),
               np.ascontiguousarray(free), np.ascontiguousarray(kdiag, dtype=float), p, scale)
    E, p22 = np.empty(u), np.empty(u)
    _weights_of(scale, p.sum(axis=1), np.ascontiguousarray(idle), np.ascontiguousarray(d, dtype=float), RATIO, E, p22)
    return E, p22


@jit
def _couplings(Kq, Kl, free, kdiag, p, scale):
    """``p = Kq Kl / kdiag`` on the free slots with stiffness (else 0) and each row's largest ``|p|`` (``scale``,
    0 for none; NaN as ``np.max``)."""
    for i in range(Kq.shape[0]):
        m = 0.0
        for a in range(Kq.shape[1]):
            v = (Kq[i, a] * Kl[i, a]) / kdiag[i, a] if free[i, a] and kdiag[i, a] > 0.0 else 0.0
            p[i, a] = v
            if m == m and not (abs(v) <= m):
                m = abs(v)
        scale[i] = m


@jit
def _weights_of(scale, total, idle, d, ratio, E, p22):
    """``(E, p22)`` of ``weights`` from the rows' ``scale`` and coupling sums ``total`` (their sign, as ``np.sign``)."""
    for i in range(len(scale)):
        t = total[i]
        sign = 1.0 if t > 0.0 else (-1.0 if t < 0.0 else (0.0 if t == 0.0 else t))
        if not idle[i] and scale[i] > 0.0 and sign != 0.0:
            e = sign * ratio / scale[i]
            inv = 1.0 / e
            q = d[i] - inv if e * d[i] < 0.0 else -inv
            p22[i] = q
            E[i] = -1.0 / q
        else:
            p22[i] = 1.0 if idle[i] or d[i] == 0.0 else d[i]
            E[i] = 0.0


class Augmented:
    """One condensed Newton system ``M x = [f; g]`` with its augmented matrix ``A`` (CSC ``(n, n)``, the
    tangent's pattern); ``Kq``, ``Kl`` ``(u, k6)`` the kept rows' couplings on the free rows ``rows`` ``(u, k6)``
    (``-1``: held slot, ignored), ``D`` ``(u,)`` the multiplier rows' diagonal (idle rows: 1), ``E``, ``p22``
    from ``weights``, ``idle`` ``(u,)``; ``K`` ``(n, n)`` the tangent ``K'`` (products); ``direct()`` builds
    ``M`` (bordered, CSC) and its right-hand side for the fallback."""

    def __init__(self, K, A, f, g, Kq, Kl, rows, D, E, p22, idle, direct):
        self.K, self.A, self.f, self.g = K, A, f, g
        free = rows >= 0
        self.rows = np.where(free, rows, 0)
        self.Kq, self.Kl = np.where(free, Kq, 0.0), np.where(free, Kl, 0.0)
        self.Klp = np.where(idle[:, None], 0.0, self.Kl)      # the preconditioner's Kl: none on idle rows
        self.D, self.E, self.p22, self.idle = D, E, p22, idle
        self.plain = E == 0.0
        self.direct = direct           # () -> (M, rhs): the bordered system
        self.n = A.shape[0]
        self.iterations = 0
        self.fallback = False

    def drop_tangent(self):
        """Forget ``K'`` and the direct fallback's system once solved (``Evaluation.drop_tangent``, ``Newton.iterate``):
        ``solve`` is then an error; the factor of ``A`` (``factor``) stays."""
        self.K = self.direct = None

    def _Kl(self, x, K=None):
        """``Kl x`` ``(u,)`` for ``x`` ``(n,)``."""
        return np.einsum("ua,ua->u", self.Kl if K is None else K, x[self.rows])

    def matvec(self, x):
        """``M x`` for ``x`` ``(n + u,)``: ``[K' x_u + Kq x_b; Kl x_u + D x_b]`` (``_join``)."""
        xu, xb = x[:self.n], x[self.n:]
        out = np.empty(len(x))
        _join(self.K @ xu, self.rows, self.Kq, np.ascontiguousarray(xb), self._Kl(xu), self.D, out)
        return out

    def precondition(self, v, apply):
        """``P^-1 v`` with ``apply`` the solve with (a factorisation of) ``A`` (``_precondition_rhs``,
        ``_precondition_out``: the module's formulas)."""
        vf, vg = np.ascontiguousarray(v[:self.n]), np.ascontiguousarray(v[self.n:])
        db0, r = np.empty(len(vg)), np.empty(self.n)
        _precondition_rhs(vf, vg, self.plain, self.p22, self.E, self.rows, self.Kq, db0, r)
        du = apply(r)
        out = np.empty(len(v))
        du = np.ascontiguousarray(du)
        _precondition_out(du, self._Kl(du, self.Klp), vg, self.plain, db0, self.E, out)
        return out

    def solve(self, solver):
        """The solution ``x`` ``(n + u,)`` of ``M x = [f; g]`` (``Problem.split_solution`` reads it): GMRES
        preconditioned by ``solver``'s factor of ``A`` (lagged while it allows, then fresh), else the direct
        saddle solve (module docstring).  ``solver.stats`` counts."""
        if self.K is None:
            raise ValueError("Augmented.solve: its tangent K' was dropped (drop_tangent)")
        for k in STATS:
            solver.stats.setdefault(k, 0)
        solver.stats["saddle_augmented"] += 1
        b = np.concatenate([self.f, self.g])
        try:
            lu = factorize_tangent(self.A, solver, kind="augmented", fresh=not LAGGED)
            for attempt in range(2):
                lagged = getattr(lu, "lagged", False)
                budget = lu.budget if lagged else MAX_ITERATIONS
                x, its, ok = gmres(self.matvec, lambda v: self.precondition(v, lu.apply), b, RTOL, budget)
                self.iterations += its
                solver.stats["saddle_iterations"] += its
                if lagged:
                    lu.done(its, ok)
                if ok and np.all(np.isfinite(x)):
                    if POLISH:                 # one step of the preconditioned (augmented Lagrangian) iteration
                        x = x + self.precondition(b - self.matvec(x), lu.apply)
                    self.factor = lu
                    return x
                if not lagged:
                    break
                lu = factorize_tangent(self.A, solver, fresh=True)
        except SingularTangent:
            pass
        self.fallback = True
        solver.stats["saddle_fallbacks"] += 1
        M, rhs = self.direct()
        lu = factorize_tangent(M, solver, saddle=True)
        self.factor = lu
        return lu.solve(rhs)


@jit
def _scatter_rows(rows, Kq, y, out):
    """``out[rows[u, a]] += Kq[u, a] y[u]`` row after row, slot after slot (``rows``, ``Kq`` ``(u, k6)``, ``y``
    ``(u,)``, ``out`` ``(n,)`` zeros in): ``np.bincount(rows.ravel(), weights=(Kq * y[:, None]).ravel())``, the same
    products summed in the same order, without the ``(u, k6)`` temporaries."""
    for u in range(rows.shape[0]):
        for a in range(rows.shape[1]):
            out[rows[u, a]] += Kq[u, a] * y[u]


@jit
def _join(top, rows, Kq, xb, kl, D, out):
    """``out = [top + Kq xb; kl + D xb]`` (``Augmented.matvec``; ``Kq xb`` by ``_scatter_rows``, then added)."""
    n = len(top)
    s = np.zeros(n)
    _scatter_rows(rows, Kq, xb, s)
    for i in range(n):
        out[i] = top[i] + s[i]
    for u in range(len(xb)):
        out[n + u] = kl[u] + D[u] * xb[u]


@jit
def _precondition_rhs(vf, vg, plain, p22, E, rows, Kq, db0, r):
    """``P^-1``'s first half (``Augmented.precondition``): ``db0 = vg / p22`` on the plain rows (else 0) and the
    right-hand side of ``A``, ``r = vf + Kq y`` with ``y = -db0`` on the plain rows, ``E vg`` on the others."""
    y = np.empty(len(vg))
    for u in range(len(vg)):
        db0[u] = vg[u] / p22[u] if plain[u] else 0.0
        y[u] = -db0[u] if plain[u] else E[u] * vg[u]
    s = np.zeros(len(vf))
    _scatter_rows(rows, Kq, y, s)
    for i in range(len(vf)):
        r[i] = vf[i] + s[i]


@jit
def _precondition_out(du, kl, vg, plain, db0, E, out):
    """``P^-1 v = [du; db]`` (``Augmented.precondition``), ``db = db0`` on the plain rows, ``E (kl - vg)`` on the
    others (``kl = Kl du`` without the idle rows)."""
    n = len(du)
    for i in range(n):
        out[i] = du[i]
    for u in range(len(vg)):
        out[n + u] = db0[u] if plain[u] else E[u] * (kl[u] - vg[u])
