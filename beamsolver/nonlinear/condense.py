"""Exact block elimination of multiplier components from the bordered Newton system (issue 26, speed).

The bordered system of ``Problem.bordered`` has per group ``g`` (``k6`` rows of its nodes) the blocks ``K_ql``
``(k6, 3)``, ``K_lq`` ``(3, k6)`` and ``K_ll`` ``(3, 3)``.  Its owner gives an orthonormal basis ``B`` ``(3, 3)``
(columns, global) in which ``D = B^T K_ll R^T B`` is diagonal (``R`` the group's rotation: ``dLam = R^T B db``):
exact stick's ``K_ll = (I - M_P Pi) R`` has ``D = diag(1, 0, 0)`` in ``[nu, t1, t2]`` when sticking,
``diag(1, 1, 1 - mu lamN / |tau|)`` in ``[nu, t, nu x t]`` when sliding and ``I`` for a group without pressure.
A component with ``D_jj >= ELIMINATE`` is eliminated: ``db_j = -(C'_j + K'_lq,j dz) / D_jj`` (``C' = B^T C``,
``K'_lq = B^T K_lq``), which adds ``-K'_ql,j K'_lq,j / D_jj`` to the group's block of the tangent and
``K'_ql,j C'_j / D_jj`` to the right-hand side; the others (a sticking group's two tangential components, a
sliding one's at the cone's edge) stay unknowns, one row and column each with the diagonal entry ``D_jj``.
In exact arithmetic the Newton step is that of the full bordered system (``test_condensed_step_is_the_bordered_one``);
on the 19-wire bundle the system loses the 3 unknowns of every sliding or unloaded group and 1 of every sticking one.
"""
import numpy as np

from .._jit import jit

__all__ = ["ELIMINATE", "Split", "split", "add_schur", "add_products", "remove_schur", "scatter_free"]

ELIMINATE = 0.1      # smallest diagonal entry of D eliminated (a sliding group at the cone's edge stays an unknown)
ENABLED = True       # False: ``Problem.linear_system`` solves the full bordered system (benchmarks: before)


class Split:
    """The kept and eliminated components of the groups of one evaluation (``split``)."""

    def __init__(self, Q, Kql, Klq, d, Cp, elim, kept, b):
        self.Q, self.Kql, self.Klq, self.d, self.C, self.elim = Q, Kql, Klq, d, Cp, elim
        self.kept = kept            # (u, 2): group and component of each kept unknown
        self.b = b                  # (g, 3): the traction's components B^T R Lam (idle rows)


def split(Kql, Klq, Kll, R, Lam, C, B):
    """Transform the blocks (``Kql`` ``(g, k6, 3)``, ``Klq`` ``(g, 3, k6)``, ``Kll``, ``R``, ``B`` ``(g, 3, 3)``,
    ``Lam``, ``C`` ``(g, 3)``) to the owner's basis ``B`` and decide which components are eliminated: ``Split``."""
    Q = np.einsum("gji,gjk->gik", R, B)                       # dLam = Q db
    Kq = Kql @ Q
    Kl = np.swapaxes(B, 1, 2) @ Klq
    D = np.swapaxes(B, 1, 2) @ Kll @ Q
    d = np.diagonal(D, axis1=1, axis2=2).copy()
    Cp = np.einsum("gji,gj->gi", B, C)
    elim = d >= ELIMINATE
    kept = np.argwhere(~elim)
    b = np.einsum("gji,gj->gi", B, np.einsum("gij,gj->gi", R, Lam))
    return Split(Q, Kq, Kl, d, Cp, elim, kept, b)


@jit
def _schur(vals, off, Kql, Klq, w):
    """``vals[off:]`` as ``(g, k6, k6)`` blocks ``-= Kql diag(w) Klq`` per group, in place: each entry's terms
    subtracted component after component (those with ``w`` or the product ``w Kql`` zero skipped), in one pass
    over the block."""
    g, k6 = Kql.shape[0], Kql.shape[1]
    js = np.empty(3, dtype=np.int64)
    cs = np.empty(3)
    for i in range(g):
        base = off + i * k6 * k6
        for a in range(k6):
            n = 0
            for j in range(3):
                c = w[i, j] * Kql[i, a, j]
                if w[i, j] != 0.0 and c != 0.0:
                    js[n], cs[n] = j, c
                    n += 1
            row = base + a * k6
            if n == 1:
                j0, c0 = js[0], cs[0]
                for b in range(k6):
                    vals[row + b] -= c0 * Klq[i, j0, b]
            elif n == 2:
                j0, c0, j1, c1 = js[0], cs[0], js[1], cs[1]
                for b in range(k6):
                    vals[row + b] = (vals[row + b] - c0 * Klq[i, j0, b]) - c1 * Klq[i, j1, b]
            elif n == 3:
                c0, c1, c2 = cs[0], cs[1], cs[2]
                for b in range(k6):
                    vals[row + b] = ((vals[row + b] - c0 * Klq[i, 0, b]) - c1 * Klq[i, 1, b]) - c2 * Klq[i, 2, b]


def add_schur(vals, off, sp):
    """Add the eliminated components' Schur terms to the groups' tangent blocks, the ``(g, k6, k6)`` values
    starting at ``off`` of the COO values ``vals`` (z numbering, in place)."""
    add_products(vals, off, sp, np.where(sp.elim, 1.0 / np.where(sp.elim, sp.d, 1.0), 0.0))


def add_products(vals, off, sp, w):
    """``vals[off:]`` as ``(g, k6, k6)`` blocks ``-= K'_ql diag(w) K'_lq`` per group (``w`` ``(g, 3)``, in place):
    the Schur terms (``add_schur``) and the augmentation of the kept components (``augmented``)."""
    _schur(vals, off, np.ascontiguousarray(sp.Kql), np.ascontiguousarray(sp.Klq), np.ascontiguousarray(w))


def remove_schur(vals, off, sp):
    """Take ``add_schur``'s terms out of the values again (to round-off): the tangent of the evaluation, for a
    bordered system with other multiplier rows (``Problem.uncondense``)."""
    add_products(vals, off, sp, -np.where(sp.elim, 1.0 / np.where(sp.elim, sp.d, 1.0), 0.0))


def rhs_terms(sp):
    """``(g, k6)``: the eliminated components' ``K'_ql C' / D`` on the groups' rows."""
    w = np.where(sp.elim, sp.C / np.where(sp.elim, sp.d, 1.0), 0.0)
    return np.einsum("gaj,gj->ga", sp.Kql, w)


@jit
def scatter_free(rows, vals, out):
    """``out[rows[i, a]] += vals[i, a]`` over the free slots (``rows >= 0``) in order (``rows``, ``vals`` ``(g, k6)``,
    ``out`` zeros in): ``np.bincount(rows[free], weights=vals[free])``, the same sums."""
    for i in range(rows.shape[0]):
        for a in range(rows.shape[1]):
            if rows[i, a] >= 0:
                out[rows[i, a]] += vals[i, a]


def recover(sp, x_kept, dz_slots):
    """``dLam`` ``(g, 3)`` from the kept unknowns' solution ``x_kept`` ``(u,)`` and the increments of the groups'
    slots ``dz_slots`` ``(g, k6)`` (free and prescribed)."""
    db = np.where(sp.elim, -(sp.C + np.einsum("gja,ga->gj", sp.Klq, dz_slots)) / np.where(sp.elim, sp.d, 1.0), 0.0)
    db[sp.kept[:, 0], sp.kept[:, 1]] = x_kept
    return np.einsum("gij,gj->gi", sp.Q, db)
