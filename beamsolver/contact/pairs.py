"""Local contact kernel: one slave section against one master element, batched over pairs.

For each pair the kernel takes the poses of the four nodes (slave element
A1, B1; master element A2, B2) and returns the body-frame nodal wrenches of
the contact forces (seed paper; docs/theory.md sections 6-7):

- slave section ``{C}`` at ``xi1`` from the constant-strain interpolation
  ``H_A1 exp(xi1 h1)``; master section ``{F}`` at ``xi2`` from the projection
  (kind ``LINE``: ``(x_F - x_C) . e_C1 = 0``; ``ORTHOGONAL``: ``(x_C - x_F) . e_F1 = 0``;
  ``POINT``: closest points of both centre lines, ``xi1`` solved too);
- ``n = (x_F - x_C)/|x_F - x_C|``, ``t1 = e_C1`` (made orthogonal to ``n``),
  ``t2 = n x t1``; ``{L}`` at ``x_C + R1 n``, ``{K}`` at ``x_F - R2 n``, gap
  ``g = |x_F - x_C| - R1 - R2``;
- slip ``dg_T = (dy[1], dy[2])``, ``dy = log(H_LK_prev^-1 H_LK)`` with ``{L}``,
  ``{K}`` carried as material frames from the last converged step;
- traction on the slave at ``L``: ``-lam_N n + lam_T1 t1 + lam_T2 t2`` (times
  the integration weight); the opposite on the master at ``K``; lever arms
  give the moments ``R1 n x F`` and ``-R2 n x F``.

The kernel is written so that complex inputs give complex-step derivatives:
branches are fixed on the real part, and the non-analytic SE(3) logarithm is
linearised exactly around its real part (``_log_c``).
"""
import numpy as np

from ..lie import se3
from ..lie.se3 import cross as _cross, dot as _dot
from .law import coulomb_return_mapping, normal_force

LINE, ORTHOGONAL, POINT = 0, 1, 2
NORMAL_TOL = 1e-9        # centre distance / (R1 + R2) below which a pair has no contact normal
PENALTY_T_MIN = 1e-3     # floor of lam_N in the slip-tolerance stick stiffness, / (normal penalty x elastic slip)
TOUCH_ROUNDOFF = 32.0    # touching tolerance / (eps (scene extent + R1 + R2)): the gap's round-off is ~1 such unit


def touch_tolerance(extent, R1, R2):
    """Gap below which a pair touches (``touching_gap``): ``TOUCH_ROUNDOFF eps (extent + R1 + R2)``,
    ``extent`` the largest node coordinate of the scene (its round-off in the centre-line distance),
    ``R1 + R2`` that of the distance itself (docs/theory_contact_tolerances.md)."""
    return TOUCH_ROUNDOFF * np.finfo(float).eps * (extent + R1 + R2)


def touching_gap(gap, touch):
    """The gap the normal law sees: a gap in ``(0, touch]`` is round-off of an exactly touching pair,
    taken as 0 (the law then counts the pair touching, with stiffness and without force); its
    variation is kept (complex step: the real part is shifted).  The kernel's rule, elementwise."""
    r = np.real(gap)
    return gap - np.where((r > 0.0) & (r <= touch), r, 0.0)


def stick_penalty(lam_n, mu, penalty, elastic_slip):
    """Tangential penalty ``mu max(lam_N, lam_min) / s_e`` of the slip-tolerance friction law.

    Sliding starts at the elastic slip ``s_e`` exactly (``|lam_T| = mu lam_N`` at
    ``|slip| = s_e``) wherever ``lam_N >= lam_min = PENALTY_T_MIN penalty s_e``, the
    normal traction of a penetration of ``PENALTY_T_MIN s_e``.  Below it (a just-touching
    point) the stiffness stays at ``mu lam_min / s_e``, so a point with ``lam_N = 0`` does not
    leave a rigid mode that only friction holds unconstrained; sliding starts there at the
    smaller slip ``s_e lam_N / lam_min``.  The derivative with respect to ``lam_N`` is
    carried (complex step: the branch is taken on the real part).
    """
    lam_min = PENALTY_T_MIN * penalty * elastic_slip
    return mu * np.where(np.real(lam_n) >= np.real(lam_min), lam_n, lam_min + 0 * lam_n) / elastic_slip


def _log_c(H):
    """SE(3) log that is exact under complex-step: ``log(H_r) + i T^-1 vee(Im(H_r^-1 H))``."""
    if not np.iscomplexobj(H):
        return se3.log(H)
    Hr = H.real
    h = se3.log(Hr)
    d = se3.vee(se3.relative(Hr, H).imag)
    return h + 1j * np.einsum("...ij,...j->...i", se3.tangent_inv(h), d)


def _section(HA, h, xi):
    """Pose, position derivative ``dx/dxi`` and second derivative at ``xi``."""
    H = se3.compose(HA, se3.exp(xi[..., None] * h))
    R = H[..., :3, :3]
    u, w = h[..., :3], h[..., 3:]
    xp = np.einsum("...ij,...j->...i", R, u)
    xpp = np.einsum("...ij,...j->...i", R, _cross(w, u))
    return H, xp, xpp


def _project(kind, HA1, h1, xi1, HA2, h2, xi2, iterations=3):
    """Newton on the projection conditions, starting from the search's real solution.

    Each kind's step is computed for every pair and selected with ``where``; a denominator is
    replaced by 1 where its kind is not the pair's (or where it is 0), so the branches a pair
    does not take never divide by a tiny number (an overflow warning for a value thrown away).
    """
    line, point = np.asarray(kind) == LINE, np.asarray(kind) == POINT
    for _ in range(iterations):
        H1, x1p, x1pp = _section(HA1, h1, xi1)
        H2, x2p, x2pp = _section(HA2, h2, xi2)
        d = H2[..., :3, 3] - H1[..., :3, 3]
        e1 = H1[..., :3, 0]
        # LINE: f = d . e_C1, df/dxi2 = x2' . e_C1
        f_line = _dot(d, e1)
        j_line = _dot(x2p, e1)
        # ORTHOGONAL: f = d . x2', df/dxi2 = x2'.x2' + d . x2''
        f_orth = _dot(d, x2p)
        j_orth = _dot(x2p, x2p) + _dot(d, x2pp)
        step2 = np.where(line, -f_line / np.where(line & (j_line != 0), j_line, 1.0),
                         -f_orth / np.where(np.logical_not(line) & (j_orth != 0), j_orth, 1.0))
        # POINT: F = (d . x1', d . x2') = 0, 2x2 Newton
        a11 = -_dot(x1p, x1p) + _dot(d, x1pp)
        a12 = _dot(x2p, x1p)
        a21 = -_dot(x1p, x2p)
        a22 = _dot(x2p, x2p) + _dot(d, x2pp)
        det = a11 * a22 - a12 * a21
        det = np.where(point & (det != 0), det, 1.0)
        g1, g2 = _dot(d, x1p), f_orth
        p1 = -(a22 * g1 - a12 * g2) / det
        p2 = -(-a21 * g1 + a11 * g2) / det
        xi1 = xi1 + np.where(point, p1, 0.0)
        xi2 = xi2 + np.where(point, p2, step2)
    return xi1, xi2


def _node_jacobians(h, xi, E_h, E_xi):
    """``J_A, J_B`` with ``dq_C = J_A dq_A + J_B dq_B`` for ``H_C = H_A exp(xi h)``.

    ``J_B = xi T(xi h) T(h)^-1`` and ``J_A = Ad(exp(-xi h)) - xi T(xi h) T(-h)^-1``,
    with ``T(-h)^-1 = T(h)^-1 Ad(exp(-h))`` (from ``T(-h) = Ad(exp(h)) T(h)``), so one
    inverse tangent serves both.  ``E_h = exp(h) = H_A^-1 H_B``, ``E_xi = exp(xi h) = H_A^-1 H_C``.
    """
    JB = (se3.tangent(xi[..., None] * h) * xi[..., None, None]) @ se3.tangent_inv(h)
    JA = se3.adjoint(se3.inverse(E_xi)) - JB @ se3.adjoint(se3.inverse(E_h))
    return JA, JB


def _body_wrench(H, F, m):
    R = H[..., :3, :3]
    return np.concatenate([np.einsum("...ji,...j->...i", R, F), np.einsum("...ji,...j->...i", R, m)], axis=-1)


def contact_kernel(X, p, friction=True):
    """Nodal wrenches ``(..., 4, 6)`` (body frames of A1, B1, A2, B2) and point data.

    ``X``: ``(..., 4, 4, 4)`` node poses.  ``p``: dict of per-pair arrays
    (``kind``, ``xi1``, ``xi2``, ``R1``, ``R2``, ``weight``, ``penalty``,
    ``multiplier``, ``mu``, ``penalty_t`` (nan: ``mu lam_N / elastic_slip``), optional ``smoothing``
    (gap), ``touch`` (``touching_gap``) and ``elastic_slip``, and for friction ``has_history``,
    ``H_CL``, ``H_FK``, ``H_LK_prev``, ``xi1_prev``, ``xi2_prev``, ``lam_t_prev``
    (global 3-vector per unit weight)).
    """
    HA1, HB1, HA2, HB2 = X[..., 0, :, :], X[..., 1, :, :], X[..., 2, :, :], X[..., 3, :, :]
    E1, E2 = se3.relative(HA1, HB1), se3.relative(HA2, HB2)
    h1, h2 = _log_c(E1), _log_c(E2)
    kind = p["kind"]
    # the search converged the projection at these poses: two Newton iterations polish it
    # and carry its exact derivative (one would, from an exact start)
    xi1, xi2 = _project(kind, HA1, h1, p["xi1"] + 0 * h1[..., 0], HA2, h2, p["xi2"] + 0 * h2[..., 0],
                        iterations=2)
    HC, _, _ = _section(HA1, h1, xi1)
    HF, _, _ = _section(HA2, h2, xi2)
    R1, R2 = p["R1"], p["R2"]
    xC, xF, n, t1, t2, dist = _axes(HC, HF, R1, R2)
    gap = dist - R1 - R2
    lam_n, active = normal_force(touching_gap(gap, p.get("touch", 0.0)), p["penalty"], p["multiplier"],
                                 p.get("smoothing", 0.0))
    w = p["weight"]
    F_slave = -(w * lam_n)[..., None] * n
    out = dict(gap=gap, lam_n=lam_n, active=active, n=n, t1=t1, t2=t2, xC=xC, xF=xF,
               xi1=xi1, xi2=xi2)
    lam_t = np.zeros(gap.shape + (2,), dtype=gap.dtype)
    stick = np.ones(gap.shape, dtype=bool)
    slip = np.zeros(gap.shape + (2,), dtype=gap.dtype)
    if friction:
        HL, HK = _contact_frames(n, t1, t2, xC, xF, R1, R2)
        # material frames carried from the last converged step
        HCm, _, _ = _section(HA1, h1, p["xi1_prev"] + 0 * xi1)
        HFm, _, _ = _section(HA2, h2, p["xi2_prev"] + 0 * xi2)
        HLm = se3.compose(HCm, p["H_CL"])
        HKm = se3.compose(HFm, p["H_FK"])
        dy = _log_c(se3.relative(p["H_LK_prev"], se3.relative(HLm, HKm)))
        has = p["has_history"]
        slip = np.where(has[..., None], dy[..., 1:3], 0.0)
        prev = p["lam_t_prev"]
        lam_prev = np.stack([_dot(prev, t1), _dot(prev, t2)], axis=-1)
        # transport: keep the magnitude of the stored traction in the new basis
        np_ = np.sqrt(np.real(_dot(prev, prev)))
        nl = np.sqrt(_dot(lam_prev, lam_prev))
        scale = np.where(np.real(nl) > 1e-300 * (1 + np_), np_ / np.where(np.real(nl) > 0, nl, 1.0), 0.0)
        lam_prev = lam_prev * scale[..., None]
        pen_t = p["penalty_t"]
        if "elastic_slip" in p:
            pen_t = np.where(np.isnan(np.real(pen_t)), stick_penalty(lam_n, p["mu"], p["penalty"], p["elastic_slip"]),
                             pen_t)
        trial = lam_prev + pen_t[..., None] * slip
        lam_t, stick = coulomb_return_mapping(trial, p["mu"], lam_n)
        lam_t = np.where(active[..., None], lam_t, 0.0)
        F_slave = F_slave + (w * lam_t[..., 0])[..., None] * t1 + (w * lam_t[..., 1])[..., None] * t2
        out.update(HL=HL, HK=HK, HC=HC, HF=HF)
    out.update(lam_t=lam_t, stick=stick, slip=slip)
    m_slave = _cross(R1[..., None] * n, F_slave)
    F_master = -F_slave
    m_master = _cross(-R2[..., None] * n, F_master)
    wC = _body_wrench(HC, F_slave, m_slave)
    wF = _body_wrench(HF, F_master, m_master)
    JA1, JB1 = _node_jacobians(h1, xi1, E1, se3.relative(HA1, HC))
    JA2, JB2 = _node_jacobians(h2, xi2, E2, se3.relative(HA2, HF))
    f = np.stack([np.einsum("...ji,...j->...i", JA1, wC), np.einsum("...ji,...j->...i", JB1, wC),
                  np.einsum("...ji,...j->...i", JA2, wF), np.einsum("...ji,...j->...i", JB2, wF)], axis=-2)
    out["F_slave"] = F_slave
    return f, out


def no_normal(dist, R1, R2):
    """Pairs whose centre lines (nearly) intersect: ``dist < NORMAL_TOL (R1 + R2)``, no normal."""
    return np.real(dist) < NORMAL_TOL * np.real(R1 + R2)


def _axes(HC, HF, R1, R2):
    """Centre points, contact axes ``n, t1, t2`` and centre distance (docs/theory.md eqs. 6.2-6.3).

    Where the centre lines intersect (``no_normal``) there is no normal: ``n`` is then
    ``(nan, nan, nan)`` without a division by zero, and the caller must refuse the pair.
    """
    xC, xF = HC[..., :3, 3], HF[..., :3, 3]
    d = xF - xC
    dist = np.sqrt(_dot(d, d))
    bad = no_normal(dist, R1, R2) | (np.real(dist) == 0.0)
    n = np.where(bad[..., None], np.nan, d) / np.where(bad, 1.0, dist)[..., None]
    e1 = HC[..., :3, 0]
    t1 = e1 - _dot(e1, n)[..., None] * n
    t1 = t1 / np.sqrt(_dot(t1, t1))[..., None]
    return xC, xF, n, t1, _cross(n, t1), dist


def _contact_frames(n, t1, t2, xC, xF, R1, R2):
    """``{L}`` at ``x_C + R1 n`` and ``{K}`` at ``x_F - R2 n``, axes ``(n, t1, t2)``."""
    frame = np.stack([n, t1, t2], axis=-1)
    return _pose(frame, xC + R1[..., None] * n), _pose(frame, xF - R2[..., None] * n)


def material_frames(X, kind, xi1, xi2, R1, R2, h1=None, h2=None):
    """Frames of a pair at fixed ``xi1, xi2`` (no projection): ``H_CL``, ``H_FK``, ``H_LK``.

    Used to start the friction history of a pair that has none: its material
    frames are those of the pair at the last converged poses ``X``.  ``h1``, ``h2``: the
    elements' twists ``log(H_A^-1 H_B)`` there if known (else computed).
    """
    HA1, HB1, HA2, HB2 = X[..., 0, :, :], X[..., 1, :, :], X[..., 2, :, :], X[..., 3, :, :]
    h1 = se3.log(se3.relative(HA1, HB1)) if h1 is None else h1
    h2 = se3.log(se3.relative(HA2, HB2)) if h2 is None else h2
    HC, _, _ = _section(HA1, h1, xi1)
    HF, _, _ = _section(HA2, h2, xi2)
    xC, xF, n, t1, t2, _ = _axes(HC, HF, R1, R2)
    HL, HK = _contact_frames(n, t1, t2, xC, xF, R1, R2)
    return se3.relative(HC, HL), se3.relative(HF, HK), se3.relative(HL, HK)


def _pose(R, x):
    H = np.zeros(R.shape[:-2] + (4, 4), dtype=R.dtype)
    H[..., :3, :3] = R
    H[..., :3, 3] = x
    H[..., 3, 3] = 1.0
    return H


CHUNK = 256   # pairs per complex-step block: (24, CHUNK) arrays stay in cache


def kernel_and_tangent(X, p, friction=True, h=1e-30):
    """Wrenches ``(P, 4, 6)`` and their exact derivative ``(P, 24, 24)`` by complex step.

    Column ``6 j + k`` perturbs node ``j`` by the body increment ``exp(i h e_k)``.
    The 24 perturbed kernels run in blocks of ``CHUNK`` pairs (same results,
    bounded memory).  The values are the real parts of the first perturbed
    kernel: with ``h = 1e-30`` the perturbation changes them by ``O(h^2) = 0``.
    """
    P = X.shape[0]
    K = np.empty((P, 24, 24))
    f = np.empty((P, 4, 6))
    E = se3.exp(1j * h * np.eye(6))                     # (6, 4, 4)
    outs = []
    for a in range(0, P, CHUNK):
        b = min(a + CHUNK, P)
        Xb = X[a:b]
        Xc = np.broadcast_to(Xb.astype(complex), (24,) + Xb.shape).copy()
        for j in range(4):
            Xc[6 * j:6 * j + 6, :, j] = se3.compose(Xb[None, :, j], E[:, None])
        pc = {k: (np.broadcast_to(v[a:b], (24,) + np.shape(v[a:b])) if np.ndim(v) else v)
              for k, v in p.items()}
        fc, oc = contact_kernel(Xc, pc, friction)
        f[a:b] = fc[0].real
        dF = fc.imag.reshape(24, b - a, 24) / h         # (col, pair, row)
        K[a:b] = np.transpose(dF, (1, 2, 0))
        outs.append({k: np.real(v[0]) for k, v in oc.items()})
    out = {k: np.concatenate([o[k] for o in outs]) for k in outs[0]} if outs else contact_kernel(X, p, friction)[1]
    return f, K, out
