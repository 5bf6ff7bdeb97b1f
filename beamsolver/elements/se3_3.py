"""The three-node SE(3) element, ``"se3-3"``: quadratic interpolation of relative twists (numpy, batched).

Nodes 0, 1, 2 sit at ``s = 0, 1/2, 1`` along the element.  With the relative
twists ``h_i = log(H_0^-1 H_i)`` (``i = 1, 2``) and the quadratic Lagrange
functions ``N_1 = 4 s (1 - s)``, ``N_2 = s (2 s - 1)`` (docs/theory.md eqs. 14.3-14.7):

- poses ``H(s) = H_0 exp(hat(phi(s)))``, ``phi = N_1 h_1 + N_2 h_2``; a beam at
  constant strain ``e`` has ``h_i = s_i L e``, so ``phi = s L e`` is linear and
  the interpolation is exact;
- strain per unit ``s``: ``k(s) = (H^-1 dH/ds)^vee = T(phi) phi'`` with the right
  tangent ``T(phi) = sum_m (-1)^m ad(phi)^m / (m + 1)!`` (summed to round-off);
  per unit reference length ``eps = k / J`` with ``J = |k_0^u|`` of the reference;
- energy ``V = sum_g w_g J_g / 2 (eps_g - eps0_g)^T C (eps_g - eps0_g)`` over two
  Gauss points (reduced integration, no shear locking; 12 strains for the 12
  deformation modes), ``sigma_g = C (eps_g - eps0_g)``;
- ``dV/dx = sum_g w_g (dk_g/dx)^T sigma_g``,
  ``d2V/dx2 = sum_g w_g [(dk_g/dx)^T (C / J_g) (dk_g/dx) + sigma_g . d2k_g/dx2]`` for
  ``x = (h_1, h_2)``: ``k`` and its first and second derivatives are carried
  through the series exactly (forward-mode jets: ``ad`` is bilinear);
- nodal forces and tangent for body increments ``H_i <- H_i exp(hat(q_i))``:
  ``dh_i = -T(-h_i)^-1 q_0 + T(h_i)^-1 q_i`` (``B``), ``f = B^T dV/dx``,
  ``K = B^T (d2V/dx2) B + sum_i [G(-h_i, g_i); G(h_i, g_i)] [-T(-h_i)^-1, T(h_i)^-1]``
  with ``g_i = dV/dh_i`` and ``G`` the pair stiffness of the two-node element
  (``geometric.geometric``).

The reported state is the Gauss-point mean of strain and section forces; ``h``
is the pair twist of largest rotation (what the solver's rotation check reads).
"""
import numpy as np

from ..lie import se3
from .element import ElementState
from .geometric import geometric
from .base import ElementType, Reference, is_diagonal

__all__ = ["SE3Three", "GAUSS"]

# two-point Gauss rule on [0, 1]: points and weights
GAUSS = (np.array([0.5 - 0.5 / np.sqrt(3.0), 0.5 + 0.5 / np.sqrt(3.0)]), np.array([0.5, 0.5]))
SERIES_TOL = 2.0 ** -60      # a series term below this times the sum so far ends the series
SERIES_MAX = 80              # terms at most (|phi| ~ pi needs ~30)


def shape(s):
    """``N_1, N_2`` and their derivatives in ``s`` at ``s`` (the coefficients of ``h_1``, ``h_2``)."""
    return 4.0 * s * (1.0 - s), s * (2.0 * s - 1.0), 4.0 - 8.0 * s, 4.0 * s - 1.0


def _ad(a, b):
    """``ad(a) b = (w_a x u_b + u_a x w_b, w_a x w_b)``, last axis 6, broadcast."""
    return np.concatenate([se3.cross(a[..., 3:], b[..., :3]) + se3.cross(a[..., :3], b[..., 3:]),
                           se3.cross(a[..., 3:], b[..., 3:])], axis=-1)


def _small(term, total):
    return np.abs(term).max(initial=0.0) <= SERIES_TOL * np.abs(total).max(initial=0.0)


def strain_jets(h1, h2, s, order=2):
    """``k = T(phi) phi'`` at ``s`` and its derivatives in ``x = (h_1, h_2)``.

    Returns ``k`` ``(n, 6)``, ``dk/dx`` ``(n, 12, 6)`` (``order >= 1``) and ``d2k/dx2``
    ``(n, 12, 12, 6)`` (``order == 2``); derivative indices first, components last.
    """
    n1, n2, d1, d2 = shape(s)
    phi, v = n1 * h1 + n2 * h2, d1 * h1 + d2 * h2
    P = np.concatenate([n1 * np.eye(6), n2 * np.eye(6)])              # d phi / dx (12, 6)
    x = [v, np.broadcast_to(np.concatenate([d1 * np.eye(6), d2 * np.eye(6)]), (len(v), 12, 6)),
         np.zeros((len(v), 12, 12, 6))][:order + 1]
    k = [a.copy() for a in x]
    c = 1.0
    for m in range(1, SERIES_MAX):
        new = [_ad(phi, x[0])]
        if order >= 1:
            new.append(_ad(P, x[0][:, None, :]) + _ad(phi[:, None, :], x[1]))
        if order == 2:
            dd = _ad(P[:, None, :], x[1][:, None, :, :])
            new.append(dd + np.swapaxes(dd, 1, 2) + _ad(phi[:, None, None, :], x[2]))
        c = -c / (m + 1)
        x = new
        for j in range(len(k)):
            k[j] += c * x[j]
        if all(_small(c * a, b) for a, b in zip(x, k)):
            break
    return k


def _relative(H, nodes):
    """Pair twists ``h_i`` ``(n, 6)`` and ``T(h_i)^-1``, ``T(-h_i)^-1`` ``(n, 6, 6)`` for ``i = 1, 2``."""
    H0 = H[nodes[:, 0]]
    return [se3.log_and_tangent_inv(se3.relative(H0, H[nodes[:, i]])) for i in (1, 2)]


class SE3Three(ElementType):
    """Three nodes, 18 unknowns, quadratic relative-twist interpolation, exact tangent (numpy)."""
    name = "se3-3"
    n_nodes = 3
    rotation_pairs = ((0, 1), (0, 2))

    def reference(self, P0, C):
        H, nodes = self.poses(P0, None)
        (h1, _, _), (h2, _, _) = _relative(H, nodes)
        J, eps0 = [], []
        for s in GAUSS[0]:
            k = strain_jets(h1, h2, s, order=0)[0]
            J.append(np.sqrt(np.einsum("ni,ni->n", k[:, :3], k[:, :3])))
            eps0.append(k / J[-1][:, None])
        J, eps0 = np.stack(J, axis=1), np.stack(eps0, axis=1)                # (n, 2), (n, 2, 6)
        C = np.ascontiguousarray(C, dtype=float)
        return Reference(J @ GAUSS[1], eps0.mean(axis=1), C, is_diagonal(C), dict(J=J, eps0=eps0))

    def _gauss(self, h1, h2, ref, order):
        """Strain and section forces per Gauss point, ``dV/dx`` ``(n, 12)`` and ``d2V/dx2`` ``(n, 12, 12)``."""
        n = len(h1)
        grad, hess = np.zeros((n, 12)), (np.zeros((n, 12, 12)) if order == 2 else None)
        strain, sigma = [], []
        for g, (s, w) in enumerate(zip(*GAUSS)):
            jets = strain_jets(h1, h2, s, order)
            J = ref.data["J"][:, g]
            eps = jets[0] / J[:, None]
            sg = np.einsum("nij,nj->ni", ref.C, eps - ref.data["eps0"][:, g])
            strain.append(eps)
            sigma.append(sg)
            grad += w * np.einsum("naj,nj->na", jets[1], sg)
            if order == 2:
                CJ = ref.C / J[:, None, None]
                hess += w * (np.einsum("naj,njl,nbl->nab", jets[1], CJ, jets[1], optimize=True)
                             + np.einsum("nabj,nj->nab", jets[2], sg))
        return np.mean(strain, axis=0), np.mean(sigma, axis=0), grad, hess

    def energy(self, H, nodes, ref):
        """Strain energy per element ``(n,)``."""
        H, nodes = self.poses(H, nodes)
        (h1, _, _), (h2, _, _) = _relative(H, nodes)
        V = 0.0
        for g, (s, w) in enumerate(zip(*GAUSS)):
            J = ref.data["J"][:, g]
            de = strain_jets(h1, h2, s, order=0)[0] / J[:, None] - ref.data["eps0"][:, g]
            V = V + w * J * 0.5 * np.einsum("ni,nij,nj->n", de, ref.C, de)
        return V

    def evaluate(self, H, nodes, ref, tangent, out=None):
        H, nodes = self.poses(H, nodes)
        pairs = _relative(H, nodes)
        h = [p[0] for p in pairs]
        strain, sigma, grad, hess = self._gauss(h[0], h[1], ref, 2 if tangent else 1)
        n = len(nodes)
        B = np.zeros((n, 12, 18))
        for i, (hi, Tp, Tm) in enumerate(pairs):
            B[:, 6 * i:6 * i + 6, :6] = -Tm
            B[:, 6 * i:6 * i + 6, 6 * i + 6:6 * i + 12] = Tp
        f = np.einsum("nai,na->ni", B, grad)
        ang = np.stack([se3.rotation_angle(x[:, 3:]) for x in h], axis=1)
        state = ElementState(np.where((ang[:, 1] >= ang[:, 0])[:, None], h[1], h[0]), strain, sigma)
        if not tangent:
            return f, None, state
        K = np.zeros((n, 18, 18)) if out is None else out
        if K.shape != (n, 18, 18):
            raise ValueError(f"out must have shape ({n}, 18, 18), got {K.shape}")
        K[:] = np.swapaxes(B, 1, 2) @ hess @ B
        for i, (hi, Tp, Tm) in enumerate(pairs):
            gi = grad[:, 6 * i:6 * i + 6]
            cols = [(slice(0, 6), -Tm), (slice(6 * i + 6, 6 * i + 12), Tp)]
            for rows, G in ((slice(0, 6), geometric(-hi, gi)), (slice(6 * i + 6, 6 * i + 12), geometric(hi, gi))):
                for c, T in cols:
                    K[:, rows, c] += G @ T
        return f, K, state

    def interpolate(self, H_el, e, xi):
        H, nodes = self.poses(H_el, None)
        (h1, _, _), (h2, _, _) = _relative(H, nodes)
        n1, n2, _, _ = shape(np.asarray(xi, dtype=float))
        return se3.compose(H_el[e, 0], se3.exp(n1[..., None] * h1[e] + n2[..., None] * h2[e]))
