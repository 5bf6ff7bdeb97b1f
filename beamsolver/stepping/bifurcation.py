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

Branch switching (``descend``): from the state ``H`` on the unstable branch
the amplitude ``a`` along the normalised critical mode ``phi`` is raised,
starting at ``AMPLITUDE`` (the largest translation ``AMPLITUDE`` times the
model size, or the largest rotation ``AMPLITUDE`` rad), at the same load; at
each amplitude the other unknowns are relaxed, and the energy along the way,
``Pi(a)``, is minimised: its slope and curvature come from the relaxed state's
residual and the tangent bordered with the amplitude constraint.  Plain Newton
from ``H exp(AMPLITUDE phi)`` would be attracted back to the saddle, in
particular for a beam held at both ends, whose perturbation stretches it.
"""
import numpy as np
import scipy.sparse as sp

from ..failures import StepFailed

__all__ = ["crossing", "full_increments", "size", "normalise", "node_twists", "descend", "AMPLITUDE", "TRUST",
           "HANDOVER", "DESCENT_MAX"]

AMPLITUDE = 0.01     # first perturbation along the normalised critical mode (unit-free size)
TRUST = 0.1          # largest change of the amplitude per descent step
HANDOVER = 1e-3      # a Newton step in the amplitude below this: the solver's Newton takes over
DESCENT_MAX = 100    # most amplitudes tried
RELAX_TOL = 1e-8     # size of the last relaxation step at a fixed amplitude
RELAX_MAX = 30       # most relaxation iterations per amplitude
CUTS = 8             # a failed relaxation halves the amplitude step, down to AMPLITUDE 2^-CUTS


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


def _bordered(K, w):
    """``[[K, w], [w^T, 0]]``: the tangent with the amplitude constraint ``w . dz = 0`` (CSC)."""
    w = sp.csc_matrix(np.asarray(w, dtype=float)[:, None])
    return sp.bmat([[sp.csc_matrix(K), w], [w.T, None]], format="csc")


def _relax(evaluate, factorize, update, scaled_size, H, w):
    """Newton iterations at a fixed amplitude (``w . dz = 0``), each at most ``TRUST`` long, to
    ``RELAX_TOL``; ``(H, r, K)``."""
    for _ in range(RELAX_MAX):
        r, K = evaluate(H)
        lu = factorize(_bordered(K, w))
        dz = lu.solve(np.append(-r, 0.0))[:-1]
        if not np.all(np.isfinite(dz)):
            raise StepFailed("branch switching: non-finite step at a fixed amplitude")
        s = scaled_size(dz)
        if s > TRUST:
            dz = dz * (TRUST / s)
        H = update(H, dz)
        if s <= RELAX_TOL:
            r, K = evaluate(H)
            return H, r, K
    raise StepFailed(f"branch switching: no equilibrium at a fixed amplitude within {RELAX_MAX} iterations")


def descend(evaluate, factorize, update, scaled_size, H, direction, weights):
    """Leave an unstable equilibrium ``H`` along ``direction`` ``phi`` (free unknowns, size 1).

    The amplitude ``a`` along ``phi`` is the control: each step moves by ``da phi`` and relaxes
    the other unknowns with ``w . dz = 0``, ``w = weights * phi`` (``_relax``: Newton with the
    constraint bordered to the tangent; a perturbation alone would stretch a beam held at both
    ends, and its tension would pull Newton back to the saddle).  At the relaxed state
    ``r = -mu w``: the energy's slope is ``dPi/da = phi . r`` and its curvature
    ``c^2 / (w . K^-1 w)``, ``c = w . phi`` (the bordered solve of ``(0, c)``), which give a
    Newton step in ``a``; where the curvature is not positive the amplitude doubles instead
    (downhill, away from the saddle).  Steps are capped at ``TRUST`` and at twice the last
    step; a relaxation that fails halves the step (down to ``AMPLITUDE 2^-CUTS``).  Returns ``(H, steps)``
    once a Newton step in ``a`` is below ``HANDOVER`` (the state then is the equilibrium
    within Newton's reach); raises ``StepFailed`` after ``DESCENT_MAX`` steps.
    ``evaluate(H) -> (r, K)`` free residual and tangent; ``factorize(A)`` an object with
    ``solve(rhs)``; ``update(H, dz_free) -> H``; ``scaled_size(dz_free)`` the unit-free size.
    """
    phi = np.asarray(direction, dtype=float)
    w = np.asarray(weights, dtype=float) * phi
    c = float(w @ phi)
    a, da, last = 0.0, AMPLITUDE, AMPLITUDE
    for step in range(1, DESCENT_MAX + 1):
        try:
            H1, r, K = _relax(evaluate, factorize, update, scaled_size, update(H, da * phi), w)
        except StepFailed as e:
            da *= 0.5                                 # the relaxation failed: a shorter step from H
            if abs(da) < AMPLITUDE * 2.0**-CUTS:
                raise StepFailed(f"branch switching: {e} (amplitude steps cut down to {abs(da):.2g})") from None
            continue
        H, a, last = H1, a + abs(da), abs(da)
        slope = float(phi @ r)
        curvature = -c * float(factorize(_bordered(K, w)).solve(np.append(np.zeros(len(phi)), c))[-1])
        if curvature > 0.0:
            da = -slope / curvature
            if abs(da) <= HANDOVER:
                return H, step
        else:
            da = -np.sign(slope) * max(a, AMPLITUDE)
        da = float(np.clip(da, -min(TRUST, 2.0 * last), min(TRUST, 2.0 * last)))
    raise StepFailed(f"branch switching: no stable state within {DESCENT_MAX} amplitudes")
