"""The complex-step oracle of the contact kernel: imported by tests and benchmarks only.

For each pair the kernel takes the poses of the four nodes (slave element
A1, B1; master element A2, B2) and returns the body-frame nodal wrenches of
the contact forces (seed paper; docs/theory.md sections 6-7), on the pair
geometry of ``frames``:

- slave section ``{C}`` at ``xi1``, master section ``{F}`` at ``xi2`` from the projection;
- gap ``g = |x_F - x_C| - R1 - R2``, normal law (``law.normal_force``);
- slip ``dg_T = (dy[1], dy[2])``, ``dy = log(H_LK_prev^-1 H_LK)`` with ``{L}``,
  ``{K}`` carried as material frames from the last converged step;
- traction on the slave at ``L``: ``-lam_N n + lam_T1 t1 + lam_T2 t2`` (times
  the integration weight); the opposite on the master at ``K``; lever arms
  give the moments ``R1 n x F`` and ``-R2 n x F``.

Complex inputs give complex-step derivatives (``kernel_and_tangent``).  Production runs the
compiled kernel (``kernel_jit``, the same maths and results to round-off); a contact system given
this module (``system.ContactSystem(..., kernel=reference)``, or made after
``system.use_numpy_kernel(True)``) evaluates with it.
"""
import numpy as np

from ..lie import se3
from ..lie.se3 import cross as _cross, dot as _dot
from .frames import axes, body_wrench, contact_frames, log_c, node_jacobians, project, section
from .law import PENALTY_T_MIN, coulomb_return_mapping, normal_force

__all__ = ["contact_kernel", "kernel_and_tangent", "touching_gap", "stick_penalty", "CHUNK", "mortar_point_friction",
           "mortar_point_derivatives"]


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
    h1, h2 = log_c(E1), log_c(E2)
    kind = p["kind"]
    # the search converged the projection at these poses: two Newton iterations polish it
    # and carry its exact derivative (one would, from an exact start)
    xi1, xi2 = project(kind, HA1, h1, p["xi1"] + 0 * h1[..., 0], HA2, h2, p["xi2"] + 0 * h2[..., 0],
                        iterations=2)
    HC, _, _ = section(HA1, h1, xi1)
    HF, _, _ = section(HA2, h2, xi2)
    R1, R2 = p["R1"], p["R2"]
    xC, xF, n, t1, t2, dist = axes(HC, HF, R1, R2)
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
        HL, HK = contact_frames(n, t1, t2, xC, xF, R1, R2)
        # material frames carried from the last converged step
        HCm, _, _ = section(HA1, h1, p["xi1_prev"] + 0 * xi1)
        HFm, _, _ = section(HA2, h2, p["xi2_prev"] + 0 * xi2)
        HLm = se3.compose(HCm, p["H_CL"])
        HKm = se3.compose(HFm, p["H_FK"])
        dy = log_c(se3.relative(p["H_LK_prev"], se3.relative(HLm, HKm)))
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
    wC = body_wrench(HC, F_slave, m_slave)
    wF = body_wrench(HF, F_master, m_master)
    JA1, JB1 = node_jacobians(h1, xi1, E1, se3.relative(HA1, HC))
    JA2, JB2 = node_jacobians(h2, xi2, E2, se3.relative(HA2, HF))
    f = np.stack([np.einsum("...ji,...j->...i", JA1, wC), np.einsum("...ji,...j->...i", JB1, wC),
                  np.einsum("...ji,...j->...i", JA2, wF), np.einsum("...ji,...j->...i", JB2, wF)], axis=-2)
    out["F_slave"] = F_slave
    return f, out


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


# ---------------------------------------------------------------- the mortar friction's point terms


def mortar_point_friction(X, p, T):
    """Friction wrenches ``(..., 4, 6)`` of the global traction ``T`` ``(..., 3)`` (force per length,
    its tangential part applied), the slip ``S`` ``(..., 3)`` (global), the normal traction and frames.

    ``X`` ``(..., 4, 4, 4)``: node poses A1, B1, A2, B2; ``p``: the kernel parameters of
    ``pairs.contact_kernel`` (friction history included).  Complex inputs give complex-step
    derivatives (branches on the real part).
    """
    HA1, HB1, HA2, HB2 = X[..., 0, :, :], X[..., 1, :, :], X[..., 2, :, :], X[..., 3, :, :]
    E1, E2 = se3.relative(HA1, HB1), se3.relative(HA2, HB2)
    h1, h2 = log_c(E1), log_c(E2)
    xi1, xi2 = project(p["kind"], HA1, h1, p["xi1"] + 0 * h1[..., 0], HA2, h2, p["xi2"] + 0 * h2[..., 0],
                        iterations=2)
    HC, _, _ = section(HA1, h1, xi1)
    HF, _, _ = section(HA2, h2, xi2)
    R1, R2 = p["R1"], p["R2"]
    xC, xF, n, t1, t2, dist = axes(HC, HF, R1, R2)
    lam_n, active = normal_force(dist - R1 - R2, p["penalty"], p["multiplier"], p.get("smoothing", 0.0))
    HL, HK = contact_frames(n, t1, t2, xC, xF, R1, R2)
    HCm, _, _ = section(HA1, h1, p["xi1_prev"] + 0 * xi1)
    HFm, _, _ = section(HA2, h2, p["xi2_prev"] + 0 * xi2)
    dy = log_c(se3.relative(p["H_LK_prev"], se3.relative(se3.compose(HCm, p["H_CL"]), se3.compose(HFm, p["H_FK"]))))
    s = np.where(p["has_history"][..., None], dy[..., 1:3], 0.0)
    S = s[..., :1] * t1 + s[..., 1:] * t2
    Tt = T - _dot(T, n)[..., None] * n
    F_slave = p["weight"][..., None] * Tt
    m_slave = _cross(R1[..., None] * n, F_slave)
    m_master = _cross(R2[..., None] * n, F_slave)
    wC = body_wrench(HC, F_slave, m_slave)
    wF = body_wrench(HF, -F_slave, m_master)
    JA1, JB1 = node_jacobians(h1, xi1, E1, se3.relative(HA1, HC))
    JA2, JB2 = node_jacobians(h2, xi2, E2, se3.relative(HA2, HF))
    f = np.stack([np.einsum("...ji,...j->...i", JA1, wC), np.einsum("...ji,...j->...i", JB1, wC),
                  np.einsum("...ji,...j->...i", JA2, wF), np.einsum("...ji,...j->...i", JB2, wF)], axis=-2)
    out = dict(lam_n=lam_n, S=S, slip=s, n=n, t1=t1, t2=t2, HL=HL, HK=HK, HC=HC, HF=HF, xi1=xi1, xi2=xi2)
    return f, out


def mortar_point_derivatives(X, p, T, h=1e-30):
    """Complex-step derivatives of ``mortar_point_friction`` on the group, batched over ``P`` pairs.

    Returns a dict: ``f`` ``(P, 24)``, ``dfdq`` ``(P, 24, 24)`` at fixed ``T``, ``G = df/dT``
    ``(P, 24, 3)``, ``S`` ``(P, 3)``, ``dS`` ``(P, 3, 24)``, ``lam_n`` ``(P,)``, ``dlam_n`` ``(P, 24)``, ``dn``
    ``(P, 3, 24)`` (of the normal) and
    the real point data of ``mortar_point_friction`` (``slip``, ``n``, ``t1``, ``t2``, ``HL``, ``HK``, ...).
    Column ``6 j + k`` perturbs node ``j`` by the body increment ``exp(i h e_k)``; columns 24-26
    perturb ``T``.
    """
    P = X.shape[0]
    res = dict(f=np.empty((P, 24)), dfdq=np.empty((P, 24, 24)), G=np.empty((P, 24, 3)), S=np.empty((P, 3)),
               dS=np.empty((P, 3, 24)), lam_n=np.empty(P), dlam_n=np.empty((P, 24)), dn=np.empty((P, 3, 24)))
    E = se3.exp(1j * h * np.eye(6))
    outs = []
    for a in range(0, P, CHUNK):
        b = min(a + CHUNK, P)
        Xc = np.broadcast_to(X[a:b].astype(complex), (27,) + X[a:b].shape).copy()
        for j in range(4):
            Xc[6 * j:6 * j + 6, :, j] = se3.compose(X[None, a:b, j], E[:, None])
        Tc = np.broadcast_to(T[a:b].astype(complex), (27, b - a, 3)).copy()
        Tc[24:] += 1j * h * np.eye(3)[:, None, :]
        pc = {k: (np.broadcast_to(v[a:b], (27,) + np.shape(v[a:b])) if np.ndim(v) else v) for k, v in p.items()}
        fc, oc = mortar_point_friction(Xc, pc, Tc)
        fc = fc.reshape(27, b - a, 24)
        res["f"][a:b] = fc[0].real
        res["dfdq"][a:b] = np.transpose(fc[:24].imag, (1, 2, 0)) / h
        res["G"][a:b] = np.transpose(fc[24:].imag, (1, 2, 0)) / h
        res["S"][a:b] = oc["S"][0].real
        res["dS"][a:b] = np.transpose(oc["S"][:24].imag, (1, 2, 0)) / h
        res["lam_n"][a:b] = oc["lam_n"][0].real
        res["dlam_n"][a:b] = oc["lam_n"][:24].imag.T / h
        res["dn"][a:b] = np.transpose(oc["n"][:24].imag, (1, 2, 0)) / h
        outs.append({k: np.real(v[0]) for k, v in oc.items() if k not in ("S", "lam_n")})
    res.update({k: np.concatenate([o[k] for o in outs]) for k in outs[0]} if outs else {})
    return res
