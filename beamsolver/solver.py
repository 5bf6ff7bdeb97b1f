"""Newton's method with pseudo-time stepping, line search and automatic cut-back.

Per step ``t -> t + dt``: loads are evaluated at ``t + dt``; the first
iteration carries the prescribed motions into the free unknowns through the
tangent (``K_ff dz_f = -r_f - K_fc dz_c``), later iterations are plain Newton
``K dz = -r`` with a backtracking line search on the scaled residual.
A failing step is halved; steps regrow after easy convergence, never past
the user's step size, and always land on the user's time grid.
"""
import logging
import time
from dataclasses import dataclass

import numpy as np

from . import linsolve, se3
from .assembly import System
from .errors import ConvergenceError, InputError
from .progress import Progress
from .restart import contact_snapshot, restart_from
from .results import Solution

__all__ = ["solve", "Convergence"]

log = logging.getLogger("beamsolver")

MAX_ELEMENT_ROTATION = 0.8 * np.pi   # an iterate turning an element further is rejected
LS_GROWTH = 10.0                     # full Newton steps are kept unless the merit grows this much


@dataclass
class Convergence:
    """Stopping rule of the Newton loop.

    Converged when the scaled residual is small,
    ``|r_u|_inf <= rtol F_ref`` and ``|r_w|_inf <= rtol M_ref``, or when the last
    full Newton increment is at round-off level,
    ``|dz_u|_inf <= dtol L_ref`` and ``|dz_w|_inf <= dtol``.  ``F_ref`` and
    ``M_ref`` are the largest element nodal force/moment or applied load of
    the iterate (``F_ref >= M_ref / L_ref`` and ``M_ref >= F_ref L_ref``), ``L_ref``
    the model size: the same scene in any unit system converges in the
    same iterations.
    """
    rtol: float = 1e-8
    dtol: float = 1e-11
    max_iter: int = 30
    divergence: float = 1e12

    def scales(self, info, L_ref):
        f, m = info["f_level"], info["m_level"]
        F = max(f, m / L_ref)
        M = max(m, f * L_ref)
        return F, M

    def residual_ratio(self, r_free_u, r_free_w, F, M):
        ru = np.abs(r_free_u).max(initial=0.0)
        rw = np.abs(r_free_w).max(initial=0.0)
        return max(ru / F if F > 0 else (0.0 if ru == 0 else np.inf),
                   rw / M if M > 0 else (0.0 if rw == 0 else np.inf))

    def increment_ratio(self, dz, L_ref):
        return max(np.abs(dz[:, :3]).max(initial=0.0) / L_ref, np.abs(dz[:, 3:]).max(initial=0.0))


class _StepFailed(Exception):
    pass


def _factorize(K, solver=None):
    """Factorise the tangent through ``linsolve`` (default back-end ``"auto"``)."""
    try:
        return (solver if solver is not None else linsolve.Solver()).factorize(K)
    except linsolve.SingularMatrixError as e:
        raise _StepFailed(f"singular tangent ({e}); is a rigid-body mode unconstrained?") from None


def _solve_linear(lu, rhs):
    try:
        return lu.solve(rhs)
    except linsolve.SingularMatrixError as e:   # pardiso reports singularity at the solve
        raise _StepFailed(f"singular tangent ({e}); is a rigid-body mode unconstrained?") from None


def _largest_element_rotation(system, H):
    """Largest rotation angle between the two nodes of an element at poses ``H``."""
    if system.n_elements == 0:
        return 0.0
    en = system.enodes
    R = np.swapaxes(H[en[:, 0], :3, :3], 1, 2) @ H[en[:, 1], :3, :3]
    c = np.clip(0.5 * (np.trace(R, axis1=1, axis2=2) - 1.0), -1.0, 1.0)
    return float(np.arccos(c).max())


class _Newton:
    def __init__(self, system, conv, line_search, callback):
        self.sys = system
        self.conv = conv
        self.line_search = line_search
        self.callback = callback
        n = system.n_nodes
        dof_u = np.zeros((n, 6), dtype=bool)
        dof_u[:, :3] = True
        fu = dof_u.ravel()[system.free_dofs]
        self.fu, self.fw = np.flatnonzero(fu), np.flatnonzero(~fu)
        self.L_ref = system.length_scale
        self.linsolver = linsolve.Solver()    # solve(linear_solver=...) replaces it

    def _ratio(self, r, scales):
        rf = r[self.sys.free_dofs]
        return self.conv.residual_ratio(rf[self.fu], rf[self.fw], *scales)

    def _merit(self, r, scales):
        rf = r[self.sys.free_dofs]
        F, M = scales
        return float(np.sum((rf[self.fu] / F) ** 2) + np.sum((rf[self.fw] / M) ** 2))

    def _check_rotation(self, state):
        ang = se3.rotation_angle(state.h[:, 3:])
        worst = int(np.argmax(ang)) if len(ang) else 0
        if len(ang) and ang[worst] > MAX_ELEMENT_ROTATION:
            raise _StepFailed(f"element {worst} turns by {ang[worst]:.3f} rad within one element "
                              f"(limit {MAX_ELEMENT_ROTATION:.3f}): refine the mesh")

    def step(self, H, t, H_target):
        """Solve for equilibrium at ``t``; returns ``(H, r, info, stats)`` or raises ``_StepFailed``."""
        sys, conv = self.sys, self.conv
        lf = sys.load_factors(t) if len(sys.load_scales) else np.zeros(0)
        n = sys.n_nodes
        residuals = []
        dz_c = None
        targets = sys.fixed_value_increments(H, t) if sys.fix_values else []
        if len(sys.prescribed_nodes) or targets:
            dz_c = np.zeros((n, 6))
            if len(sys.prescribed_nodes):
                p = sys.prescribed_nodes
                dz_c[p] = se3.log(se3.relative(H[p], H_target))
            for node, comp, dx in targets:
                dz_c[node, comp] = dx
            if not np.any(dz_c):
                dz_c = None
        last_inc = np.inf
        for it in range(conv.max_iter + 1):
            r, kvals, info = sys.evaluate(H, lf, tangent=True)
            if not np.all(np.isfinite(r)):
                raise _StepFailed("the residual is not finite")
            self._check_rotation(info["state"])
            scales = conv.scales(info, self.L_ref)
            ratio = self._ratio(r, scales)
            residuals.append(ratio)
            log.debug("t = %.6g  iteration %d  scaled residual %.3e", t, it, ratio)
            if self.callback is not None:
                self.callback(dict(t=t, iteration=it, residual=ratio, poses=H))
            if dz_c is None and (ratio <= conv.rtol or last_inc <= conv.dtol):
                return H, r, info, dict(iterations=it, residuals=residuals)
            if it == conv.max_iter:
                raise _StepFailed(f"no convergence in {conv.max_iter} iterations (scaled residual {ratio:.3g})")
            if ratio > conv.divergence:
                raise _StepFailed(f"diverging (scaled residual {ratio:.3g})")
            rhs = -r[sys.free_dofs]
            if dz_c is not None:
                rhs -= sys.prescribed_coupling(kvals, dz_c.ravel(), info["extra"])
            lu = _factorize(sys.matrix(kvals, info["extra"]), self.linsolver)
            dzf = _solve_linear(lu, rhs)
            if not np.all(np.isfinite(dzf)):
                raise _StepFailed("the linear solve returned non-finite values")
            dz = np.zeros(6 * n)
            dz[sys.free_dofs] = dzf
            dz = dz.reshape(n, 6)
            if dz_c is not None:
                H = sys.update(H, dz + dz_c)
                if len(sys.prescribed_nodes):
                    H[sys.prescribed_nodes] = H_target
                if targets:
                    sys.enforce_fixed_values(H, t)
                sys.sync_members(H)
                dz_c = None
                last_inc = np.inf
                continue
            last_inc = conv.increment_ratio(dz, self.L_ref)
            H = self._line_search(H, dz, r, scales, lf, lu, dzf) if self.line_search else sys.update(H, dz)
        raise AssertionError("unreachable")

    def _increment_norm(self, dzf):
        """Norm of free increments with translations measured in units of the model size."""
        return float(np.sqrt(np.sum((dzf[self.fu] / self.L_ref) ** 2) + np.sum(dzf[self.fw] ** 2)))

    def _line_search(self, H, dz, r0, scales, lf, lu=None, dzf=None):
        """Backtracking on the scaled residual, with Deuflhard's natural-monotonicity test: a
        trial ``alpha`` is also accepted when the simplified Newton correction at it (the old
        factorisation applied to the new residual) is smaller than the Newton increment,
        ``|dz_bar| < (1 - alpha / 4) |dz|``: near strong rotation nonlinearity the residual can
        grow along a good Newton step while the increments still contract.  Scenes without
        contact only: with contact (a piecewise smooth residual) the test accepted steps that
        later stalled (the twisted pair), so the residual merit decides alone."""
        sys = self.sys
        nrm = self._increment_norm(dzf) if dzf is not None else 0.0
        # contact makes the residual only piecewise smooth: there the residual merit decides alone
        smooth = sys.contact is None
        phi0 = self._merit(r0, scales)
        H1 = sys.update(H, dz)
        if phi0 <= (10.0 * self.conv.rtol) ** 2 * len(sys.free_dofs):
            return H1
        alpha = 1.0
        best = (np.inf, H1)
        for _ in range(8):
            try:
                r1, _, info = sys.evaluate(H1, lf, tangent=False)
                self._check_rotation(info["state"])
                phi = self._merit(r1, scales) if np.all(np.isfinite(r1)) else np.inf
            except _StepFailed:
                phi = np.inf
            if phi < best[0]:
                best = (phi, H1)
            # Newton may raise the residual for a while: only a blow-up (factor
            # LS_GROWTH) triggers backtracking, which then asks for a decrease
            if phi <= (LS_GROWTH * phi0 if alpha == 1.0 else (1.0 - 1e-4 * alpha) * phi0):
                return H1
            if smooth and np.isfinite(phi) and lu is not None and nrm > 0:
                try:
                    bar = _solve_linear(lu, -r1[sys.free_dofs])
                except _StepFailed:
                    bar = None
                if bar is not None and np.all(np.isfinite(bar)) and \
                        self._increment_norm(bar) < (1.0 - 0.25 * alpha) * nrm:
                    return H1
            # minimiser of the quadratic through phi(0), phi'(0) = -2 phi0, phi(alpha)
            if np.isfinite(phi):
                a_new = phi0 * alpha**2 / (phi - phi0 + 2.0 * alpha * phi0)
            else:
                a_new = 0.1 * alpha
            alpha = float(np.clip(a_new, 0.1 * alpha, 0.5 * alpha))
            H1 = sys.update(H, alpha * dz)
        if not np.isfinite(best[0]):
            raise _StepFailed("line search found no finite residual along the Newton direction")
        return best[1]


def solve(model, steps=20, t_end=1.0, output=None, *, t_start=0.0, rtol=1e-8, dtol=1e-11,
          max_iter=30, line_search=True, min_step_ratio=2.0**-12, callback=None,
          check_rigid_modes=True, verbose=None, initial_poses=None, restart=None, checkpoint=60.0,
          linear_solver=None):
    """Quasi-static solve of ``model`` from ``t_start`` to ``t_end`` in ``steps`` equal steps.

    Every converged (sub)step is recorded in the returned ``Solution``.  A step
    that fails is halved down to ``min_step_ratio`` times the user's step, then
    ``ConvergenceError`` is raised with the last converged ``Solution``.

    ``output``: folder for ParaView files and ``solution.npz`` (``None``: no
    output; see ``beamsolver.io.vtk``), the latter saved at the end and every
    ``checkpoint`` seconds (0: every step); or a writer object with
    ``write(solution, step)`` and ``close()`` such as ``io.vtk.StepWriter``.
    ``callback(info)`` is called at every Newton iteration with ``t``,
    ``iteration``, ``residual`` (scaled) and ``poses``.
    ``verbose``: progress bar / lines (see ``progress.Progress``); ``None`` shows a bar on a terminal.
    ``restart``: a ``Solution`` (or the path of a saved one) of this model; the
    run continues from its last step on the grid ``linspace(restart.times[0],
    t_end, steps + 1)`` with its stepping state and contact history, so the
    same arguments give the same final state as a run never interrupted.
    ``linear_solver``: sparse direct solver of the Newton systems, ``"auto"``
    (default: scipy ``"splu"`` for beams and small scenes; for large bundles
    of wires in contact ``"pardiso"`` if pypardiso is installed, ``pip install
    "beamsolver[fast]"``, else ``"splu-rcm"``, scipy after an RCM ordering),
    or one of those by name (see ``beamsolver.linsolve``).
    """
    if restart is not None and initial_poses is not None:
        raise InputError("solve: give either restart or initial_poses, not both")
    if int(steps) != steps or steps < 1:
        raise InputError(f"solve: steps must be a positive integer, got {steps!r}")
    system = System(model, check_rigid_modes=check_rigid_modes)
    if restart is not None:
        sol = restart_from(restart, model, system)
        t_start = sol._times[0]
    if not (np.isfinite(t_end) and np.isfinite(t_start) and t_end > t_start):
        raise InputError(f"solve: need t_end > t_start, got t_start={t_start!r}, t_end={t_end!r}")
    conv = Convergence(rtol=rtol, dtol=dtol, max_iter=max_iter)
    newton = _Newton(system, conv, line_search, callback)
    newton.linsolver = linsolve.Solver(linear_solver)
    writer = None
    if output is not None and hasattr(output, "write"):
        writer = output                   # e.g. io.vtk.StepWriter(folder, refine=4, compression=None)
    elif output is not None:
        from .io.vtk import StepWriter
        writer = StepWriter(output, system, checkpoint=checkpoint)

    grid = np.linspace(t_start, t_end, int(steps) + 1)
    dt_user = grid[1] - grid[0]
    dt_min = dt_user * min_step_ratio
    dt = dt_user
    t = t_start
    k = 1
    easy = 0
    if restart is None:
        H = system.poses0.copy() if initial_poses is None else np.array(initial_poses, dtype=float)
        if len(system.prescribed_nodes):
            H[system.prescribed_nodes] = system.prescribed_poses(t_start)
            system.sync_members(H)
        sol = Solution(model, system)
        lf0 = system.load_factors(t_start) if len(system.load_scales) else np.zeros(0)
        r0, _, info0 = system.evaluate(H, lf0, tangent=False)
        sol.append(t_start, H, system.reactions(H, r0), info0["state"].sigma, info0["state"].strain,
                   dict(iterations=0, residuals=[], wall_time=0.0, dt=0.0, cutbacks=0))
        if writer is not None:
            writer.write(sol, 0)
    else:
        H = sol._poses[-1].copy()
        t = sol._times[-1]
        k = int(np.searchsorted(grid, t + 1e-12 * dt_user, side="right"))
        rs = sol.resume
        if rs.get("t0") == t_start and rs.get("t_end") == t_end and rs.get("steps") == steps:
            dt, easy = min(rs["dt"], dt_user), rs["easy"]
        if writer is not None:
            for j in range(len(sol._times)):
                writer.write(sol, j)
    progress = Progress(verbose, t_start, t_end, t)
    while k <= steps:
        t_next = min(t + dt, grid[k])
        if grid[k] - t_next < 1e-9 * dt_user:
            t_next = grid[k]
        t0 = time.perf_counter()
        cutbacks = 0
        rotation_limit = None         # an attempt of this step turned an element too far
        while True:
            try:
                H_target = system.prescribed_poses(t_next) if len(system.prescribed_nodes) else None
                if system.contact is not None:
                    system.contact.begin_step(H, t_next)
                H_new, r, info, stats = newton.step(H, t_next, H_target)
                # augmented Lagrangian: update multipliers and re-solve until satisfied
                while system.contact is not None and system.contact.augment(H_new):
                    more = newton.step(H_new, t_next, H_target)
                    H_new, r, info = more[0], more[1], more[2]
                    stats["iterations"] += more[3]["iterations"]
                    stats["residuals"] += more[3]["residuals"]
                    stats["augmentations"] = stats.get("augmentations", 0) + 1
                break
            except _StepFailed as e:
                cutbacks += 1
                if "within one element" in str(e):
                    rotation_limit = str(e)
                dt_try = (t_next - t) / 2.0
                log.info("t = %.6g: step %.3g failed (%s); cutting back to %.3g", t_next, t_next - t, e, dt_try)
                if dt_try < dt_min:
                    sol.converged = False
                    sol.message = str(e)
                    progress.close()
                    if writer is not None:
                        writer.close()
                    hint = "" if rotation_limit is None or rotation_limit == str(e) else \
                        f"; a larger step had failed because {rotation_limit}"
                    turned = _largest_element_rotation(system, H)
                    if not hint and turned > 0.75 * MAX_ELEMENT_ROTATION:
                        hint = (f"; elements already turn by up to {turned:.2f} rad within one element "
                                f"(limit {MAX_ELEMENT_ROTATION:.2f}): refine the mesh")
                    if not hint and "no convergence" in str(e):
                        hint = ("; if the structure may have buckled (a limit point or bifurcation: "
                                "check the eigenvalues of bs.linearize(model, error.solution)) or "
                                "lost the support of a contact, a force-controlled quasi-static solve "
                                "cannot pass it: prescribe displacements, add supports, or refine")
                    raise ConvergenceError(
                        f"solve: could not advance from t = {t:.6g} (step fell below {dt_min:.3g}): {e}{hint}",
                        sol) from None
                t_next = t + dt_try
                easy = 0
        stats.update(wall_time=time.perf_counter() - t0, dt=t_next - t, cutbacks=cutbacks)
        H = H_new
        state = info["state"]
        contact_data = None
        if system.contact is not None:
            system.contact.commit(H)
            contact_data = system.contact.results(H)
            sol.contact_state = contact_snapshot(system.contact)
        sol.append(t_next, H, system.reactions(H, r), state.sigma, state.strain, stats, contact_data)
        if writer is not None:
            writer.write(sol, sol.n_steps)
        progress.step(sol.n_steps, t_next, t_next - t, stats)
        dt = t_next - t
        t = t_next
        if t >= grid[k] - 1e-12 * dt_user:
            t = grid[k]
            k += 1
        easy = easy + 1 if stats["iterations"] <= 6 and cutbacks == 0 else 0
        if easy >= 2:
            dt = min(2.0 * dt, dt_user)
        sol.resume = dict(t0=float(grid[0]), t_end=float(t_end), steps=int(steps), dt=float(dt), easy=int(easy))
    progress.close()
    if writer is not None:
        writer.close()
    return sol
