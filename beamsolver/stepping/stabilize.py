"""Viscous stabilisation in pseudo-time, as Abaqus' ``*STATIC, STABILIZE`` (docs/theory.md, section
"Viscous stabilisation").

Every free node (a representative of kind ``FREE``: neither clamped, prescribed nor partly fixed)
carries an artificial viscous force, body frame, translation first:

- velocity ``v = h / dt`` with ``h = log(H_prev^-1 H)`` the SE(3) increment of the node since the
  last converged state and ``dt`` the pseudo-time step;
- force ``f_v = c M* v`` (added to the residual ``r = f_int - f_ext + f_v``);
- tangent ``df_v/dq = (c / dt) M* T(h)^-1`` (``H <- H exp(dq)``, ``T`` the right tangent of SE(3));
- ``M*`` a lumped, mass-like diagonal: ``m_u = sum_e EA_e L_e / (k l^2)`` on the three
  translations [N/m] and ``m_w = sum_e EI_e L_e / (k l^2)`` on the three rotations [N m]
  (``EI_e`` the mean of ``EI2, EI3``; sums over the elements at the node, each of an element's
  ``k`` nodes taking ``1/k``; ``l`` the model size): the beams' lumped mass matrix with the
  density replaced by ``E / l^2``, so ``c`` is unit-free;
- energy dissipated over a step: ``D = f_v . h = (c / dt) h^T M* h``.

The factor ``c`` follows from a dissipated-energy fraction ``fraction`` (Abaqus' default 2e-4):
the first step with a positive strain energy ``E_1`` and motion is solved without damping, then
``c = fraction E_1 dt_1 / (h_1^T M* h_1)``, so that the same step would have dissipated
``fraction E_1``; ``c`` is then kept for the whole solve (a restarted solve continues with the factor and the
dissipated total recorded in the solution it restarts from, ``Stabilization.resume``).  Each stabilised step is a step of
implicit Euler on the viscous flow ``c M* v = -r``, i.e. a minimiser of the potential plus
``(c / 2 dt) h^T M* h``: a converged step whose stabilised tangent ``K + (c / dt) M*`` is not
positive definite overshot an unstable mode (it lands on the far side of the unstable
equilibrium) and is refused (``StabilizedSaddle``, retried with a shorter step, which
raises ``c / dt``).  The check needs a symmetric tangent: ``solve`` makes it only for
conservative problems (no friction, no follower loads), where the symmetric part of a
frictional tangent may be indefinite at a stable state.  ``factor=`` sets ``c`` directly
(active from the first step).  ``settle=True``: the last step is solved once more without damping,
from its damped state, when that state is not an equilibrium of the model
(docs/theory_stabilized_equilibrium.md).  After every step the dissipated energy, its running total and its
ratio to the beams' strain energy are recorded; a ratio above ``warn`` (default 0.05) warns
(``StabilizationWarning``): the answer is then polluted by the damping.
"""
import logging
import warnings

import numpy as np

from ..lie import se3
from ..assembly.system import FREE
from ..model.blocks import Blocks, Contribution
from ..nonlinear.definiteness import negative_eigenvalues
from ..errors import InputError, StabilizationWarning
from ..failures import StepFailed

__all__ = ["StabilizedSaddle", "DEFAULT_FRACTION", "WARN_FRACTION", "mass_scales", "increments", "forces",
           "stabilized_tangent", "dissipated", "Stabilization", "from_option"]

log = logging.getLogger("beamsolver")

DEFAULT_FRACTION = 2e-4    # dissipated-energy fraction of ``stabilize=True`` (Abaqus' default)
WARN_FRACTION = 0.05       # dissipated / strain energy above which the answer is called polluted


class StabilizedSaddle(StepFailed):
    """A stabilised step converged to a point where ``K + (c / dt) M*`` is indefinite: an implicit
    Euler step of the viscous flow too long for its unstable mode (it lands on the far side of an
    unstable equilibrium, not on the flow); a shorter step raises ``c / dt``."""


def mass_scales(enodes, L, C, length, n_nodes, m=None):
    """Diagonal ``M*`` per node, ``(n_nodes, 2)``: ``(m_u, m_w)`` from element tables ``enodes``
    ``(n_el, k)`` (node numbers of ``k``-node elements), ``L`` ``(n_el,)``, ``C`` ``(n_el, 6, 6)``
    and the model size ``length``, each node taking ``1/k`` of an element; added to ``m`` if given."""
    k = enodes.shape[1]
    rho = np.stack([C[:, 0, 0], 0.5 * (C[:, 4, 4] + C[:, 5, 5])], axis=1) * (L / (k * length**2))[:, None]
    m = np.zeros((n_nodes, 2)) if m is None else m
    for j in range(k):
        np.add.at(m, enodes[:, j], rho)
    return m


def increments(H_prev, H):
    """``h = log(H_prev^-1 H)`` ``(n, 6)`` and ``T(h)^-1`` ``(n, 6, 6)`` of node poses ``(n, 4, 4)``."""
    h, Ti, _ = se3.log_and_tangent_inv(se3.relative(H_prev, H))
    return h, Ti


def _diagonal(m):
    """``(n, 2)`` scales -> ``(n, 6)`` diagonal of ``M*``."""
    return np.repeat(m, 3, axis=1)


def forces(h, m, c, dt):
    """Viscous forces ``c M* h / dt`` ``(n, 6)``."""
    return (c / dt) * _diagonal(m) * h


def stabilized_tangent(Ti, m, c, dt):
    """Their derivative ``(c / dt) M* T(h)^-1`` ``(n, 6, 6)`` with respect to body increments."""
    return (c / dt) * _diagonal(m)[:, :, None] * Ti


def dissipated(h, m, c, dt):
    """Energy ``(c / dt) h^T M* h`` dissipated by the viscous forces over the step."""
    return float((c / dt) * np.sum(_diagonal(m) * h * h))


class Stabilization(Contribution):
    """The damping of one solve as a ``blocks.Contribution`` (one 6x6 block per damped node):
    ``begin_step`` / ``evaluate`` / ``commit`` of the step life cycle, plus ``check`` (the saddle
    test of a converged step) and ``record`` (calibration, energies, warning) that ``solve``
    calls.  ``t_last``: the time of the last converged state (``None``: no step yet)."""
    name = "stabilization"
    smooth = True
    conservative = False          # viscous: no potential

    def __init__(self, system, fraction=DEFAULT_FRACTION, factor=None, warn=WARN_FRACTION, check=True, settle=False):
        self.sys = system
        self.check_saddle = check
        self.nodes = np.flatnonzero(system.is_rep & (system.kind == FREE))
        m = None          # M* over every element type: each element lumped at all its nodes
        for g in system.groups:
            m = mass_scales(system.rep[g.nodes], g.ref.L, g.ref.C, system.length_scale, system.n_nodes, m)
        self.m = (np.zeros((system.n_nodes, 2)) if m is None else m)[self.nodes]
        self.fraction, self.warn = fraction, warn
        self.c = 0.0 if factor is None else float(factor)
        self.H_prev, self.dt, self.t_last, self.t_next = None, None, None, None
        self.total = 0.0
        self.warned = False
        self.settle = bool(settle)    # solve the last step once more without damping (``stepping.Run``)
        self.suspended = False        # True while it does: no viscous forces

    @property
    def active(self):
        return self.c > 0.0 and self.H_prev is not None and len(self.nodes) > 0 and not self.suspended

    def begin_step(self, H, t):
        """Start the step to ``t`` from the converged poses ``H`` (at ``t_last``)."""
        self.t_next = t
        self.dt = None if self.t_last is None else t - self.t_last
        self.H_prev = None if self.dt is None or self.dt <= 0 else H[self.nodes].copy()

    def commit(self, H):
        self.t_last = self.t_next

    def evaluate(self, H, tangent=True):
        """``(Blocks, {})``: the viscous forces ``(m, 6)`` and their tangent ``(m, 6, 6)`` per node."""
        if not self.active:
            return Blocks.empty(1, tangent), {}
        h, Ti = increments(self.H_prev, H[self.nodes])
        K = stabilized_tangent(Ti, self.m, self.c, self.dt) if tangent else None
        return Blocks(self.nodes[:, None], forces(h, self.m, self.c, self.dt), K), {}

    def check(self, K, t):
        """Refuse (``StabilizedSaddle``) a converged step whose stabilised tangent ``K`` (free x free,
        its symmetric part) has a negative eigenvalue: the step then minimises nothing."""
        if not (self.active and self.check_saddle):
            return
        neg, _ = negative_eigenvalues(K)
        if neg:
            raise StabilizedSaddle(f"t = {t:.6g}: the stabilised tangent has {neg} negative eigenvalue(s): "
                                   f"the viscous damping (c / dt = {self.c / self.dt:.3g}) is too weak for this "
                                   "step")

    def resume(self, solution):
        """Continue the damping of the run ``solution`` (a restart): its last recorded factor ``c``
        (unless ``factor=`` was given) and dissipated total, so that the continued run damps as
        the uninterrupted one (a factor calibrated again would leave the first step undamped)."""
        rec = next((s["stabilization"] for s in reversed(solution.stats) if "stabilization" in s), None)
        if rec is None:
            return
        if self.c == 0.0:
            self.c = float(rec.get("factor", 0.0))
        self.total = float(rec.get("dissipated_total", 0.0))

    def strain_energy(self, H):
        """The beams' strain energy at ``H`` (``ElementType.energy`` of every element group)."""
        return float(sum(g.element_type.energy(H, g.nodes, g.ref).sum() for g in self.sys.groups))

    def record(self, H, t):
        """After a converged step: calibrate ``c`` if not yet set, account the dissipated energy;
        returns the step's record ``dict(factor, dissipated, dissipated_total, strain_energy,
        fraction)`` (energies in J)."""
        energy = self.strain_energy(H)
        if self.H_prev is None or not len(self.nodes):
            return dict(factor=self.c, dissipated=0.0, dissipated_total=self.total, strain_energy=energy,
                        fraction=0.0)
        h, _ = increments(self.H_prev, H[self.nodes])
        step = dissipated(h, self.m, self.c, self.dt)
        if self.c == 0.0:
            motion = dissipated(h, self.m, 1.0, self.dt)
            if energy > 0.0 and motion > 0.0:
                self.c = self.fraction * energy / motion
                log.info("stabilisation: damping factor c = %.4g from the step to t = %.6g", self.c, t)
        self.total += step
        frac = self.total / energy if energy > 0.0 else (0.0 if self.total == 0.0 else np.inf)
        if frac > self.warn and not self.warned:
            self.warned = True
            text = (f"t = {t:.6g}: the stabilisation has dissipated {frac:.3g} of the strain energy "
                    f"(more than {self.warn:g}): the answer is polluted by the artificial damping; "
                    "use a smaller stabilize fraction or finer steps")
            log.warning(text)
            warnings.warn(text, StabilizationWarning, stacklevel=6)
        return dict(factor=self.c, dissipated=step, dissipated_total=self.total, strain_energy=energy,
                    fraction=frac)


def from_option(system, stabilize, check=True):
    """The ``Stabilization`` of ``solve(stabilize=...)``: ``None``/``False`` (off), ``True`` (fraction
    ``DEFAULT_FRACTION``), a fraction ``> 0``, or ``dict(fraction=, factor=, warn=, settle=)``; ``check``:
    refuse saddle steps (``Stabilization.check``); ``settle``: a last step whose state is not an
    equilibrium of the model is solved once more without damping (docs/theory_stabilized_equilibrium.md)."""
    if stabilize is None or stabilize is False:
        return None
    if stabilize is True:
        return Stabilization(system, check=check)
    if isinstance(stabilize, dict):
        unknown = set(stabilize) - {"fraction", "factor", "warn", "settle"}
        if unknown:
            raise InputError(f"solve: stabilize has unknown keys {sorted(unknown)} (fraction, factor, warn, settle)")
        opts = dict(stabilize)
        if not isinstance(opts.get("settle", False), bool):
            raise InputError(f"solve: stabilize settle must be True or False, got {opts['settle']!r}")
    elif isinstance(stabilize, (int, float)) and not isinstance(stabilize, bool):
        opts = dict(fraction=stabilize)
    else:
        raise InputError(f"solve: stabilize must be None, True, a fraction or a dict, got {stabilize!r}")
    for key in ("fraction", "factor", "warn"):
        v = opts.get(key)
        if v is not None and not (isinstance(v, (int, float)) and np.isfinite(v) and v > 0):
            raise InputError(f"solve: stabilize {key} must be a positive number, got {v!r}")
    return Stabilization(system, fraction=opts.get("fraction") or DEFAULT_FRACTION, factor=opts.get("factor"),
                         warn=opts.get("warn") or WARN_FRACTION, check=check, settle=opts.get("settle", False))
