"""Critical modes as node fields, bifurcation detection and the move onto a stable branch.

Conventions.  A mode ``phi`` is a direction of the solver's unknowns (free
DOFs; ``modes.lowest_modes``).  ``full_increments`` spreads it to ``(n, 6)``
increments of the representative nodes (zero on constrained ones), the
variables of ``System.update`` (body increments ``H exp(dz)``, global ones
for partially fixed nodes).  Its *size* is unit-free,
``|dz| = max_i max(|dz_u,i| / L_ref, |dz_w,i|)`` over the nodes ``i``
(Euclidean norms: translations in units of the model size ``L_ref``,
rotations in radians; unchanged by a rotation of the axes); ``normalise`` scales a mode
to size 1 with its largest scaled component positive.  ``node_twists``
gives the first-order motion of *every* node (joined and constrained ones
included) along ``dz`` in global axes: displacement ``(3)`` and rotation
vector ``(3)`` per node, ``(n, 6)``.

Branch switching (``descend``): the state ``H`` on the unstable branch is
perturbed to ``H exp(AMPLITUDE phi)`` (``phi`` normalised: the largest
translation is ``AMPLITUDE`` times the model size, or the largest rotation
``AMPLITUDE`` rad) and iterated at the same load with a shifted tangent,
``(K + sigma diag|K|) dz = -r`` with ``sigma = SHIFT_FACTOR max(-lam_min, 0)``
(``lam_min`` the lowest eigenvalue of the scaled pencil).  With a
conservative problem ``r`` is the gradient of the potential energy and the
shifted matrix is positive definite, so ``dz`` descends the energy: along the
unstable mode the perturbation doubles per iteration instead of being
undone, as plain Newton does (it is attracted back to the saddle).  Steps are
capped at size ``TRUST``; once the tangent is positive definite and a full
step is below ``HANDOVER``, the state is handed back to the solver's Newton.
"""
import numpy as np
import scipy.sparse as sp

from .definiteness import ZERO
from .failures import StepFailed
from .modes import lowest_modes

__all__ = ["crossing", "full_increments", "size", "normalise", "node_twists", "descend",
           "AMPLITUDE", "TRUST", "SHIFT_FACTOR", "HANDOVER", "DESCENT_MAX"]

AMPLITUDE = 0.01     # first perturbation along the normalised critical mode (unit-free size)
TRUST = 0.1          # largest size of one descent step
SHIFT_FACTOR = 2.0   # sigma = SHIFT_FACTOR |lam_min|: the unstable component doubles per step
HANDOVER = 0.01      # positive definite and a full step below this size: the solver's Newton takes over
DESCENT_MAX = 200    # most descent steps


def crossing(previous, current):
    """Whether the count of negative eigenvalues went up from ``previous`` (``None``: unknown,
    taken as 0) to ``current``."""
    return current is not None and current > (previous or 0)


def full_increments(system, phi):
    """Increments ``(n, 6)`` of all nodes from a direction ``phi`` ``(n_free,)`` of the free unknowns."""
    dz = np.zeros(6 * system.n_nodes)
    dz[system.free_dofs] = phi
    return dz.reshape(-1, 6)


def size(system, dz):
    """Unit-free size ``max_i max(|dz_u,i| / L_ref, |dz_w,i|)`` of increments ``(n, 6)``."""
    dz = np.asarray(dz).reshape(-1, 6)
    return max(np.linalg.norm(dz[:, :3], axis=1).max(initial=0.0) / system.length_scale,
               np.linalg.norm(dz[:, 3:], axis=1).max(initial=0.0))


def normalise(system, dz):
    """``dz`` scaled to ``size`` 1, its largest scaled component positive (a reproducible sign)."""
    dz = np.array(dz, dtype=float).reshape(-1, 6)
    scaled = dz.copy()
    scaled[:, :3] /= system.length_scale
    big = np.flatnonzero(np.abs(scaled.ravel()) >= (1.0 - 1e-9) * np.abs(scaled).max(initial=0.0))
    s = size(system, dz)
    if s == 0.0:
        return dz
    return dz * (np.sign(scaled.ravel()[big[0]]) / s)


def node_twists(system, H, dz):
    """Global displacement and rotation vector ``(n, 6)`` of every node along increments ``dz``
    ``(n, 6)`` of the representatives at poses ``H`` (first order)."""
    xi = np.asarray(dz, dtype=float).reshape(-1, 6)[system.rep]
    M = system.node_transforms(H)
    if M is not None:
        xi = np.einsum("nij,nj->ni", M, xi)
    R = H[:, :3, :3]
    return np.concatenate([np.einsum("nij,nj->ni", R, xi[:, :3]), np.einsum("nij,nj->ni", R, xi[:, 3:])], axis=1)


def _shifted(K, sigma):
    """``K + sigma |diag K_s|`` (``K_s`` the symmetric part; zero diagonal entries count as 1)."""
    K = sp.csc_matrix(K)
    d = np.abs(K.diagonal())
    d[d == 0.0] = 1.0
    return K + sigma * sp.diags(d, format="csc")


def descend(evaluate, factorize, update, scaled_size, H, direction):
    """Leave an unstable equilibrium ``H`` along ``direction`` (free unknowns, normalised).

    ``evaluate(H) -> (r, K)``: free residual and tangent; ``factorize(K)`` an object with
    ``solve(rhs)``; ``update(H, dz_free) -> H``; ``scaled_size(dz_free)`` the unit-free size.
    Returns ``(H, steps)`` once the tangent is positive definite and a full step is below
    ``HANDOVER``; raises ``StepFailed`` after ``DESCENT_MAX`` steps or on a non-finite state.
    """
    H = update(H, AMPLITUDE * direction)
    for step in range(1, DESCENT_MAX + 1):
        r, K = evaluate(H)
        lam = lowest_modes(K, 1)[0]
        lam = float(lam[0]) if len(lam) else 0.0
        sigma = SHIFT_FACTOR * -lam if lam < -ZERO else 0.0
        dz = factorize(_shifted(K, sigma) if sigma > 0 else K).solve(-r)
        if not np.all(np.isfinite(dz)):
            raise StepFailed("branch switching: the shifted tangent gave a non-finite step")
        s = scaled_size(dz)
        if sigma == 0.0 and s <= HANDOVER:
            return update(H, dz), step
        H = update(H, dz * min(1.0, TRUST / s) if s > 0 else dz)
    raise StepFailed(f"branch switching: no stable state within {DESCENT_MAX} descent steps")
