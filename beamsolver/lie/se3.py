"""Lie-group kernels on SO(3) and SE(3), batched over leading axes.

Conventions (stated once, used everywhere in beamsolver):

- A pose is ``H = [[R, x], [0, 1]]``, shape ``(..., 4, 4)``.
- A twist / increment is ``h = (u, w)``, shape ``(..., 6)``: translation first,
  rotation second.
- Increments are body (right) increments: ``H <- H exp(hat(h))``.
- ``tangent(h)`` is the right tangent operator: ``exp(h + dh) = exp(h) exp(tangent(h) dh)``
  to first order (Sonneville, Cardona & Bruls 2014; docs/theory.md section 2).

Every coefficient that is 0/0 at zero angle has its own Taylor switch point,
chosen where the truncated series (nine terms in t^2) and the closed form
agree to round-off; ``tests/lie/test_se3_coefficients.py`` sweeps them against
200-digit arithmetic.
"""
import numpy as np

__all__ = [
    "SERIES", "SWITCH", "COEFFICIENT_NAMES", "coefficient", "coefficients", "cross", "dot",
    "skew", "unskew", "hat", "vee", "exp_so3", "log_so3", "tangent_so3",
    "tangent_inv_so3", "exp", "log", "tangent", "tangent_inv", "adjoint",
    "inverse", "compose", "relative", "interpolate", "rotation_angle", "log_relative",
    "log_and_tangent_inv", "quaternion",
]

# ---------------------------------------------------------------- coefficients
# Series coefficients in powers of t^2 (exact rationals, computed with sympy).
SERIES = {
    "a": [1, -1 / 6, 1 / 120, -1 / 5040, 1 / 362880, -1 / 39916800,
          1 / 6227020800, -1 / 1307674368000, 1 / 355687428096000],
    "b": [1 / 2, -1 / 24, 1 / 720, -1 / 40320, 1 / 3628800, -1 / 479001600,
          1 / 87178291200, -1 / 20922789888000, 1 / 6402373705728000],
    "c": [1 / 6, -1 / 120, 1 / 5040, -1 / 362880, 1 / 39916800, -1 / 6227020800,
          1 / 1307674368000, -1 / 355687428096000, 1 / 121645100408832000],
    "d": [1 / 12, 1 / 720, 1 / 30240, 1 / 1209600, 1 / 47900160,
          691 / 1307674368000, 1 / 74724249600, 3617 / 10670622842880000,
          43867 / 5109094217170944000],
    "q2": [1 / 24, -1 / 720, 1 / 40320, -1 / 3628800, 1 / 479001600,
           -1 / 87178291200, 1 / 20922789888000, -1 / 6402373705728000,
           1 / 2432902008176640000],
    "q3": [1 / 120, -1 / 2520, 1 / 120960, -1 / 9979200, 1 / 1245404160,
           -1 / 217945728000, 1 / 50812489728000, -1 / 15205637551104000,
           1 / 5676771352412160000],
    # derivatives divided by t: f'(t)/t
    "cp": [-1 / 60, 1 / 1260, -1 / 60480, 1 / 4989600, -1 / 622702080,
           1 / 108972864000, -1 / 25406244864000, 1 / 7602818775552000,
           -1 / 2838385676206080000],
    "dp": [1 / 360, 1 / 7560, 1 / 201600, 1 / 5987520, 691 / 130767436800,
           1 / 6227020800, 3617 / 762187345920000, 43867 / 319318388573184000,
           174611 / 44603203483238400000],
    "q2p": [-1 / 360, 1 / 10080, -1 / 604800, 1 / 59875200, -1 / 8717829120,
            1 / 1743565824000, -1 / 457312407552000, 1 / 152056375511040000,
            -1 / 62444484876533760000],
    "q3p": [-1 / 1260, 1 / 30240, -1 / 1663200, 1 / 155675520, -1 / 21794572800,
            1 / 4234374144000, -1 / 1086116967936000, 1 / 354798209525760000,
            -1 / 143622315216027648000],
}


def _closed_a(t):
    return np.sin(t) / t


def _closed_b(t):
    s = np.sin(0.5 * t) / (0.5 * t)  # 1 - cos t = 2 sin^2(t/2): no cancellation
    return 0.5 * s * s


def _closed_c(t):
    return (t - np.sin(t)) / t**3


def _closed_d(t):
    return (1.0 - 0.5 * t / np.tan(0.5 * t)) / t**2


def _closed_q2(t):
    return (t * t + 2.0 * np.cos(t) - 2.0) / (2.0 * t**4)


def _closed_q3(t):
    return (2.0 * t - 3.0 * np.sin(t) + t * np.cos(t)) / (2.0 * t**5)


def _closed_cp(t):
    return (3.0 * np.sin(t) - t * np.cos(t) - 2.0 * t) / t**5


def _closed_dp(t):
    s = np.sin(0.5 * t)
    return (t * t / (s * s) + 2.0 * t / np.tan(0.5 * t) - 8.0) / (4.0 * t**4)


def _closed_q2p(t):
    return (-t * t - t * np.sin(t) - 4.0 * np.cos(t) + 4.0) / t**6


def _closed_q3p(t):
    return (-8.0 * t + 15.0 * np.sin(t) - 7.0 * t * np.cos(t) - t * t * np.sin(t)) / (2.0 * t**7)


_CLOSED = {"a": _closed_a, "b": _closed_b, "c": _closed_c, "d": _closed_d,
           "q2": _closed_q2, "q3": _closed_q3, "cp": _closed_cp, "dp": _closed_dp,
           "q2p": _closed_q2p, "q3p": _closed_q3p}

# Switch points, one per coefficient, from a sweep against 200-digit
# arithmetic (tests/lie/test_se3_coefficients.py): below them the nine-term
# series is exact to round-off, above them the closed form has lost little to
# cancellation.  `d` and `dp` have poles at 2 pi, so their series converge
# more slowly and switch earlier.  Worst relative errors over t in
# [1e-12, 5]: a, b, c, q2 < 2e-15; d 3e-15; q3, cp 5e-15; q2p 8e-15;
# q3p 1.5e-14; dp 2.5e-13 (with nine terms the series and closed-form errors
# of dp cross near 1e-13 around t = 1, so no switch point does better).
# log_so3: below this ratio |q_v| / q_w (rotation angle < 2 atan(0.1) = 0.2 rad) the factor
# 2 atan(x) / x is summed as its series (nine terms: error < x^18 / 19 ~ 1e-19); above it, atan2 has
# no cancellation
ATAN_SERIES_RATIO = 0.1

SWITCH = {"a": 0.75, "b": 1.0, "c": 1.5, "d": 0.75, "q2": 1.5, "q3": 1.5,
          "cp": 1.5, "dp": 1.0, "q2p": 2.0, "q3p": 2.0}


def coefficient(name, t):
    """Evaluate the named singular coefficient at angles ``t >= 0`` (any shape; docs/theory.md eq. 2.9)."""
    t = _arr(t)
    t2 = t * t
    coeffs = SERIES[name]
    series = np.full_like(t2, coeffs[-1])
    for c in coeffs[-2::-1]:
        series = series * t2 + c
    small = t.real < SWITCH[name]
    safe = np.where(small, 1.0, t)
    with np.errstate(invalid="ignore", divide="ignore"):
        closed = _CLOSED[name](safe)
    return np.where(small, series, closed)


COEFFICIENT_NAMES = tuple(SERIES)


def coefficients(names, t):
    """``{name: coefficient(name, t)}`` for several names at once, ``t`` of shape ``(m,)``.

    The series run as one stacked Horner scheme (the same values as
    ``coefficient``); only angles at or above a coefficient's switch point call
    ``coefficient`` for the closed form.
    """
    t = _arr(t)
    table = np.array([SERIES[k] for k in names]).T[:, :, None]
    t2 = t * t
    series = np.repeat(table[-1], len(t), axis=-1)
    for row in table[-2::-1]:
        series = series * t2 + row
    out = dict(zip(names, series))
    for name in names:
        big = np.flatnonzero(t.real >= SWITCH[name])
        if len(big):
            out[name] = out[name].copy()
            out[name][big] = coefficient(name, t[big])
    return out


# ---------------------------------------------------------------- small algebra
def _arr(x):
    """Float array, or complex if the input is complex (complex-step differentiation)."""
    x = np.asarray(x)
    return x if np.iscomplexobj(x) else x.astype(float, copy=False)


def _zeros(shape, *like):
    dt = complex if any(np.iscomplexobj(a) for a in like) else float
    return np.zeros(shape, dtype=dt)


def cross(a, b, axis=-1):
    """Cross product of 3-vectors along ``axis`` (-1 or 0; other axes broadcast; faster than np.cross)."""
    if axis == 0:
        return np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def dot(a, b, axis=-1):
    """Dot product along ``axis`` (-1 or 0), other axes broadcast; unrolled for 3-vectors."""
    if np.shape(a)[axis] != 3:
        return np.sum(a * b, axis=axis)
    if axis == 0:
        return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def _mv(A, v):
    return np.einsum("...ij,...j->...i", A, v)


def skew(w):
    """so(3) hat: ``(..., 3) -> (..., 3, 3)`` with ``skew(w) @ v = w x v``."""
    w = _arr(w)
    W = _zeros(w.shape[:-1] + (3, 3), w)
    W[..., 0, 1] = -w[..., 2]
    W[..., 0, 2] = w[..., 1]
    W[..., 1, 0] = w[..., 2]
    W[..., 1, 2] = -w[..., 0]
    W[..., 2, 0] = -w[..., 1]
    W[..., 2, 1] = w[..., 0]
    return W


def unskew(W):
    """so(3) vee of the skew part: ``(..., 3, 3) -> (..., 3)``."""
    W = np.asarray(W)
    return 0.5 * np.stack([W[..., 2, 1] - W[..., 1, 2],
                           W[..., 0, 2] - W[..., 2, 0],
                           W[..., 1, 0] - W[..., 0, 1]], axis=-1)


def hat(h):
    """se(3) hat: ``(..., 6) -> (..., 4, 4)``, ``[[skew(w), u], [0, 0]]``."""
    h = _arr(h)
    X = _zeros(h.shape[:-1] + (4, 4), h)
    X[..., :3, :3] = skew(h[..., 3:])
    X[..., :3, 3] = h[..., :3]
    return X


def vee(X):
    """se(3) vee: ``(..., 4, 4) -> (..., 6)``."""
    X = np.asarray(X)
    return np.concatenate([X[..., :3, 3], unskew(X[..., :3, :3])], axis=-1)


def rotation_angle(w):
    """``|w|``, shape ``(...,)``."""
    return np.sqrt(dot(w, w))


# ---------------------------------------------------------------- SO(3)
def exp_so3(w):
    """``exp(skew(w)) = I + a W + b W^2`` (docs/theory.md eq. 2.1); ``(..., 3) -> (..., 3, 3)``."""
    w = _arr(w)
    t = rotation_angle(w)
    a, b = coefficient("a", t), coefficient("b", t)
    W = skew(w)
    return np.eye(3) + a[..., None, None] * W + b[..., None, None] * (W @ W)


def quaternion(R):
    """Unit quaternion ``(qw, qx, qy, qz)``, ``qw >= 0``, of ``R`` (Shepperd's method)."""
    R = _arr(R)
    r00, r11, r22 = R[..., 0, 0], R[..., 1, 1], R[..., 2, 2]
    tr = r00 + r11 + r22
    d21, d02, d10 = R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]
    s01, s02, s12 = R[..., 0, 1] + R[..., 1, 0], R[..., 0, 2] + R[..., 2, 0], R[..., 1, 2] + R[..., 2, 1]
    choice = np.argmax(np.stack([tr, r00, r11, r22], axis=-1), axis=-1)
    # each candidate: 4 * q_k * q with q_k the largest component (never small)
    cand = np.stack([
        np.stack([1.0 + tr, d21, d02, d10], axis=-1),
        np.stack([d21, 1.0 + r00 - r11 - r22, s01, s02], axis=-1),
        np.stack([d02, s01, 1.0 - r00 + r11 - r22, s12], axis=-1),
        np.stack([d10, s02, s12, 1.0 - r00 - r11 + r22], axis=-1),
    ], axis=-2)
    q = np.take_along_axis(cand, choice[..., None, None], axis=-2)[..., 0, :]
    q = q / np.sqrt(np.sum(q * q, axis=-1))[..., None]
    return np.where(q[..., :1] < 0.0, -q, q)


def log_so3(R):
    """Rotation vector of ``R``: ``(..., 3, 3) -> (..., 3)``, angle in ``[0, pi]``.

    Goes through the quaternion, so nothing divides by ``sin t`` near ``pi``.
    """
    q = quaternion(R)
    qw, qv = q[..., 0], q[..., 1:]
    s = np.sqrt(dot(qv, qv))
    # 2 atan2(s, qw) / s; for small x = s/qw use the series of atan(x)/x.
    small = s < ATAN_SERIES_RATIO * qw
    x2 = np.where(small, (s / np.where(small, qw, 1.0)) ** 2, 0.0)
    series = np.zeros_like(x2)
    for k in range(8, -1, -1):
        series = series * x2 + (-1) ** k / (2 * k + 1)
    series = 2.0 * series / np.where(small, qw, 1.0)
    closed = 2.0 * np.arctan2(s, qw) / np.where(small, 1.0, s)
    return np.where(small, series, closed)[..., None] * qv


def tangent_so3(w):
    """Right tangent ``T(w) = I - b W + c W^2``: ``exp(w + dw) = exp(w) exp(T dw)`` (eq. 2.2)."""
    w = _arr(w)
    t = rotation_angle(w)
    W = skew(w)
    return np.eye(3) - coefficient("b", t)[..., None, None] * W + coefficient("c", t)[..., None, None] * (W @ W)


def tangent_inv_so3(w):
    """``T(w)^-1 = I + W/2 + d W^2`` (eq. 2.3; singular at ``|w| = 2 pi``)."""
    w = _arr(w)
    t = rotation_angle(w)
    W = skew(w)
    return np.eye(3) + 0.5 * W + coefficient("d", t)[..., None, None] * (W @ W)


# ---------------------------------------------------------------- SE(3)
def exp(h):
    """``exp(hat(h))`` (docs/theory.md eq. 2.4): ``(..., 6) -> (..., 4, 4)``, translation ``T_SO3(w)^T u``."""
    h = _arr(h)
    u, w = h[..., :3], h[..., 3:]
    t = rotation_angle(w)
    a, b, c = coefficient("a", t), coefficient("b", t), coefficient("c", t)
    W = skew(w)
    WW = W @ W
    H = _zeros(h.shape[:-1] + (4, 4), h)
    H[..., :3, :3] = np.eye(3) + a[..., None, None] * W + b[..., None, None] * WW
    wxu = cross(w, u)
    H[..., :3, 3] = u + b[..., None] * wxu + c[..., None] * cross(w, wxu)
    H[..., 3, 3] = 1.0
    return H


def log(H):
    """``vee(log(H))`` (docs/theory.md eqs. 2.5, 2.10): ``(..., 4, 4) -> (..., 6)``; rotation angle in ``[0, pi]``."""
    H = _arr(H)
    w = log_so3(H[..., :3, :3])
    x = H[..., :3, 3]
    d = coefficient("d", rotation_angle(w))
    wxx = cross(w, x)
    u = x - 0.5 * wxx + d[..., None] * cross(w, wxx)  # T_SO3(w)^-T x
    return np.concatenate([u, w], axis=-1)


def _q_matrix(u, w, t=None):
    """``Q(u, w)`` of docs/theory.md eq. (2.6) (the coupling block), ``(..., 3, 3)``."""
    if t is None:
        t = rotation_angle(w)
    c1, c2, c3 = coefficient("c", t), coefficient("q2", t), coefficient("q3", t)
    P, U = skew(w), skew(u)
    PU, UP = P @ U, U @ P
    PUP = PU @ P
    return (0.5 * U + c1[..., None, None] * (PU + UP + PUP)
            + c2[..., None, None] * (P @ PU + UP @ P - 3.0 * PUP)
            + c3[..., None, None] * (PUP @ P + P @ PUP))


def tangent(h):
    """Right tangent of SE(3) (docs/theory.md eq. 2.7): ``[[T(w), Q(-u,-w)], [0, T(w)]]``, ``(..., 6, 6)``."""
    h = _arr(h)
    u, w = h[..., :3], h[..., 3:]
    Tw = tangent_so3(w)
    out = _zeros(h.shape[:-1] + (6, 6), h)
    out[..., :3, :3] = Tw
    out[..., 3:, 3:] = Tw
    out[..., :3, 3:] = _q_matrix(-u, -w)
    return out


def tangent_inv(h):
    """Inverse right tangent (eq. 2.7): ``[[Ti, -Ti Q(-u,-w) Ti], [0, Ti]]``, ``(..., 6, 6)``."""
    h = _arr(h)
    u, w = h[..., :3], h[..., 3:]
    Ti = tangent_inv_so3(w)
    out = _zeros(h.shape[:-1] + (6, 6), h)
    out[..., :3, :3] = Ti
    out[..., 3:, 3:] = Ti
    out[..., :3, 3:] = -Ti @ _q_matrix(-u, -w) @ Ti
    return out


def adjoint(H):
    """``Ad(H) = [[R, skew(x) R], [0, R]]`` in the (u, w) ordering, ``(..., 6, 6)``."""
    H = _arr(H)
    R, x = H[..., :3, :3], H[..., :3, 3]
    out = _zeros(H.shape[:-2] + (6, 6), H)
    out[..., :3, :3] = R
    out[..., 3:, 3:] = R
    out[..., :3, 3:] = skew(x) @ R
    return out


def inverse(H):
    """``H^-1 = [[R^T, -R^T x], [0, 1]]``."""
    H = _arr(H)
    R, x = H[..., :3, :3], H[..., :3, 3]
    out = _zeros(H.shape, H)
    Rt = np.swapaxes(R, -1, -2)
    out[..., :3, :3] = Rt
    out[..., :3, 3] = -_mv(Rt, x)
    out[..., 3, 3] = 1.0
    return out


def compose(A, B):
    """``A @ B`` for poses, batched (exploits the last row)."""
    A, B = _arr(A), _arr(B)
    shape = np.broadcast_shapes(A.shape, B.shape)
    out = _zeros(shape, A, B)
    out[..., :3, :3] = A[..., :3, :3] @ B[..., :3, :3]
    out[..., :3, 3] = _mv(A[..., :3, :3], B[..., :3, 3]) + A[..., :3, 3]
    out[..., 3, 3] = 1.0
    return out


def relative(A, B):
    """``A^-1 B`` for poses, batched."""
    A, B = _arr(A), _arr(B)
    Rt = np.swapaxes(A[..., :3, :3], -1, -2)
    shape = np.broadcast_shapes(A.shape, B.shape)
    out = _zeros(shape, A, B)
    out[..., :3, :3] = Rt @ B[..., :3, :3]
    out[..., :3, 3] = _mv(Rt, B[..., :3, 3] - A[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def interpolate(H_A, h, xi):
    """Constant-strain interpolation ``H_A exp(xi h)`` (Sonneville 2014).

    ``H_A``: ``(..., 4, 4)``, ``h``: ``(..., 6)``, ``xi``: broadcastable to the batch.
    """
    xi = _arr(xi)
    return compose(H_A, exp(xi[..., None] * _arr(h)))


def log_relative(A, B):
    """``log(A^-1 B)``: relative twist of poses ``(..., 4, 4) -> (..., 6)``."""
    return log(relative(A, B))


def log_and_tangent_inv(H):
    """``h = log(H)`` and ``T(h)^-1``, ``T(-h)^-1`` (``(..., 6)``, ``(..., 6, 6)`` twice), trig shared.

    ``T(-h)^-1`` is ``T(h)^-1`` with the signs of its skew-odd parts flipped:
    ``Ti(-w) = Ti(w)^T`` and ``X(-h) = -Ti(w)^T Q(u, w) Ti(w)^T``.
    """
    h = log(H)
    u, w = h[..., :3], h[..., 3:]
    Ti = tangent_inv_so3(w)
    TiT = np.swapaxes(Ti, -1, -2)
    plus = _zeros(h.shape[:-1] + (6, 6), h)
    minus = _zeros(h.shape[:-1] + (6, 6), h)
    plus[..., :3, :3] = plus[..., 3:, 3:] = Ti
    minus[..., :3, :3] = minus[..., 3:, 3:] = TiT
    plus[..., :3, 3:] = -Ti @ _q_matrix(-u, -w) @ Ti
    minus[..., :3, 3:] = -TiT @ _q_matrix(u, w) @ TiT
    return h, plus, minus
