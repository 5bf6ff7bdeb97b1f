"""Exact stick's saddle-point Newton system solved through the augmented matrix ``A = K' + Kq E Kl`` (GMRES
preconditioned by one factorisation of ``A``, ``nonlinear/augmented.py``): the step is the direct solve's of the
condensed system to round-off, on sticking groups, turned multipliers, sticking and sliding groups together (a
sliding one kept at the cone's edge) and with prescribed increments; the same over four decades of the augmentation;
a preconditioner that does not get there falls back to the direct saddle solve and says so in a counter.
"""
import numpy as np
import pytest
import scipy.sparse.linalg as spla

from beamsolver import se3
from beamsolver.nonlinear import augmented, linsolve
from test_contact_exact_stick import R, SEC, _committed, _move, _parallel


def _scene(regime):
    """``(problem, ev)``: an evaluation of ``_parallel`` with multiplier unknowns of the given regime."""
    # mixed: c pinned to 24 EI / L_e^4 (1.18e5 N/m^2, the default before session 7; now 8 times that at 8 elements),
    # with which the turn below leaves one group sliding at the cone's edge
    options = dict(penalty_t=24.0 * SEC.C[4, 4] / 0.1 ** 4) if regime == "mixed" else {}
    model, slave, master = _parallel(0.5, n_slave=8 if regime == "mixed" else 4, **options)
    problem, H = _committed(model, slave, turned=regime == "turned")
    if regime == "mixed":        # turned about the vertical through the clamped end: its far group slides
        x0 = np.eye(4)
        x0[:3, 3] = H[slave.first, :3, 3]
        G = x0 @ se3.exp(np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1e-4])) @ np.linalg.inv(x0)
    else:
        slide = 1e-7 * R
        G = se3.exp(np.array([slide, slide, 0.0, slide, 0.0, 0.5 * slide]))
    H = _move(H, slave.nodes, G)
    return problem, H, slave


def _prescribed(problem, slave):
    dz_c = np.zeros((problem.system.n_nodes, 6))
    dz_c[slave.first] = [1e-6 * R, -2e-6 * R, 1e-6 * R, 1e-6, 0.0, -1e-6]
    return dz_c


def _direct(problem, H, dz_c):
    """The condensed system's step solved directly (SuperLU), ``(dq, dlam)``."""
    ev = problem.evaluate(H, 0.0, tangent=True)
    A, b = problem.linear_system(ev, dz_c)
    return problem.split_solution(ev, spla.spsolve(A.tocsc(), b), dz_c)


def _augmented(problem, H, dz_c, solver=None):
    ev = problem.evaluate(H, 0.0, tangent=True)
    aug = problem.augmented_system(ev, dz_c)
    x = aug.solve(solver if solver is not None else linsolve.Solver())
    return problem.split_solution(ev, x, dz_c), ev, aug


def _close(a, b, rtol=1e-10):
    return np.abs(a - b).max() <= rtol * np.abs(b).max()


@pytest.mark.parametrize("regime", ["stick", "turned", "mixed"])
def test_augmented_step_is_the_direct_one(regime):
    """Poses' and multipliers' steps equal the direct solve's to 1e-10 relative, with and without prescribed
    increments; ``mixed``: sticking groups and a sliding one kept at the cone's edge (``D_jj`` 0.02)."""
    problem, H, slave = _scene(regime)
    for dz_c in (None, _prescribed(problem, slave)):
        dq0, dl0 = _direct(problem, H, dz_c)
        solver = linsolve.Solver()
        (dq, dl), ev, aug = _augmented(problem, H, dz_c, solver)
        sp = ev.mult["split"]
        d = sp.d[sp.kept[:, 0], sp.kept[:, 1]]
        if regime == "mixed":
            assert (~ev.mult["stick"]).sum() == 1 and ev.mult["stick"].sum() > 1 and (np.abs(d) > 1e-3).sum() == 1
        else:
            assert ev.mult["stick"].all() and len(d) == 2 * len(ev.mult["C"])
        assert _close(dq, dq0) and _close(dl, dl0), (np.abs(dq - dq0).max() / np.abs(dq0).max(),
                                                     np.abs(dl - dl0).max() / np.abs(dl0).max())
        assert solver.stats["saddle_fallbacks"] == 0 and solver.stats["saddle_augmented"] == 1
        assert solver.stats["saddle_iterations"] <= 3


@pytest.mark.parametrize("regime", ["stick", "mixed"])
def test_augmented_step_does_not_depend_on_the_augmentation(monkeypatch, regime):
    """The same step (1e-10 relative) for ``RATIO`` (E times the constraint's stiffness over the structure's) over
    four decades around the default 1e6 (measured: 2e-14 .. 1e-12 from 1e4 to 1e9), 2-3 iterations each."""
    problem, H, slave = _scene(regime)
    dz_c = _prescribed(problem, slave)
    dq0, dl0 = _direct(problem, H, dz_c)
    for ratio in (1e4, 1e5, 1e6, 1e7, 1e8):
        monkeypatch.setattr(augmented, "RATIO", ratio)
        solver = linsolve.Solver()
        (dq, dl), _, _ = _augmented(problem, H, dz_c, solver)
        assert _close(dq, dq0) and _close(dl, dl0), ratio
        assert solver.stats["saddle_fallbacks"] == 0 and solver.stats["saddle_iterations"] <= 3


def test_a_preconditioner_that_stagnates_falls_back_to_the_direct_solve(monkeypatch):
    """An augmentation far too soft (``RATIO`` 1e-8: ``A`` is nearly ``K'``, no preconditioner of the saddle) does
    not converge within the iterations allowed: the direct saddle solve gives the step, counted in the solver's
    ``saddle_fallbacks``."""
    problem, H, slave = _scene("stick")
    dq0, dl0 = _direct(problem, H, None)
    monkeypatch.setattr(augmented, "RATIO", 1e-8)
    solver = linsolve.Solver()
    (dq, dl), _, _ = _augmented(problem, H, None, solver)
    assert solver.stats["saddle_fallbacks"] == 1
    assert _close(dq, dq0) and _close(dl, dl0)


def test_the_augmented_matrix_has_the_tangents_pattern():
    """``A`` has the pattern of the tangent ``Problem.tangent`` where the pattern is held (``System.hold_pattern``,
    large scenes: no bordering, the penalty path's pattern, factorised and lagged as it is), and ``linear_system``
    called after the augmentation (in ``ev``'s values) still gives the direct step (from the tangent kept)."""
    problem, H, slave = _scene("turned")
    dq0, dl0 = _direct(problem, H, None)
    problem.system.hold_pattern = True
    first = problem.augmented_system(problem.evaluate(H, 0.0, tangent=True)).A    # (the reserve grows to the groups)
    ev = problem.evaluate(H, 0.0, tangent=True)
    K = problem.tangent(ev)
    aug = problem.augmented_system(ev)
    for A in (first, aug.A, aug.K):
        assert A.shape == K.shape and np.array_equal(A.indptr, K.indptr) and np.array_equal(A.indices, K.indices)
    # the products added on the held pattern (``System.add_products``) are Kq E Kl
    dense = np.zeros(K.shape)
    for u in range(len(aug.E)):
        np.add.at(dense, np.ix_(aug.rows[u], aug.rows[u]), aug.E[u] * np.outer(aug.Kq[u], aug.Kl[u]))
    assert np.abs((aug.A - aug.K).toarray() - dense).max() <= 1e-12 * np.abs(dense).max()
    M, b = problem.linear_system(ev)
    dq, dl = problem.split_solution(ev, spla.spsolve(M.tocsc(), b))
    assert _close(dq, dq0) and _close(dl, dl0)


@pytest.mark.parametrize("scene", ["contact_patch", "shear_lag"])
def test_newton_through_the_augmented_solve_takes_the_direct_path(monkeypatch, scene):
    """The Newton loop with the augmented solve at any size (``MIN_UNKNOWNS`` 0) takes the direct solve's
    iterations to the same states (the contact patch with friction; the shear lag's slip front).  The shear lag's
    first system falls back to the direct solve: no pressure yet, every kept row idle (``A = K'``), the wire held
    along its axis by the unloaded groups' stiffness floor alone; GMRES stalls at 3e-6 of the right-hand side."""
    import contact_patch
    import shear_lag
    import beamsolver as bs

    def run():
        if scene == "contact_patch":
            return bs.solve(contact_patch.build(stick="exact")[0], **contact_patch.solve_options)
        return shear_lag.main(n_wire=10, stick="exact")[0]

    direct = run()
    monkeypatch.setattr(augmented, "MIN_UNKNOWNS", 0)
    counts = dict(n=0, fallbacks=0)
    solve = augmented.Augmented.solve

    def counted(self, solver):
        x = solve(self, solver)
        counts["n"] += 1
        counts["fallbacks"] += self.fallback
        return x
    monkeypatch.setattr(augmented.Augmented, "solve", counted)
    aug = run()
    assert counts["n"] >= 8 and counts["fallbacks"] == (1 if scene == "shear_lag" else 0)
    assert [s["iterations"] for s in aug.stats] == [s["iterations"] for s in direct.stats]
    x0, x1 = direct.poses[-1][:, :3, 3], aug.poses[-1][:, :3, 3]
    assert np.abs(x1 - x0).max() <= 1e-9 * np.abs(x0).max()


def test_dropping_the_tangent_frees_k_prime(monkeypatch):
    """The evaluation's tangent values are dropped once ``K'`` and ``A`` are built, before the factorisation
    (``newton.DROP_BEFORE_SOLVE``), and once the Newton system is solved (``Newton.iterate``: ``Augmented.
    drop_tangent``) nothing holds exact stick's tangent ``K'`` any more, before the line search's trial (issue 30:
    the 0.6 m rope's peak; ``A`` lives on in its factor): the shear lag's iterations and poses bit for bit as with
    the tangent kept to the end; the evaluation's Newton system and the solve are then errors that say so."""
    import weakref
    import shear_lag
    from beamsolver.nonlinear import newton
    from beamsolver.nonlinear.problem import Problem
    monkeypatch.setattr(augmented, "MIN_UNKNOWNS", 0)
    monkeypatch.setattr(newton, "DROP_BEFORE_SOLVE", False)
    kept = shear_lag.main(n_wire=20)[0]
    monkeypatch.setattr(newton, "DROP_BEFORE_SOLVE", True)
    seen = dict(solved=0, freed=0, dropped=0)
    refs, evs = [], []
    solve = augmented.Augmented.solve
    system = Problem.augmented_system

    def built(self, ev, dz_c=None):
        evs.append(ev)
        return system(self, ev, dz_c)

    def tracked(self, solver):
        seen["dropped"] += evs.pop().kvals is None        # (``DROP_BEFORE_SOLVE``: before the factorisation)
        x = solve(self, solver)
        refs.append(weakref.ref(self.K))
        seen["solved"] += 1
        return x
    drop = newton.Newton.release

    def check(ev, lu):
        # the iteration's Newton system solved (``Newton._normal_branches``' directions too), before the line search
        drop(ev, lu)
        seen["freed"] += sum(r() is None for r in refs)
        refs.clear()
    monkeypatch.setattr(augmented.Augmented, "solve", tracked)
    monkeypatch.setattr(newton.Newton, "release", staticmethod(check))
    monkeypatch.setattr(Problem, "augmented_system", built)
    dropped = shear_lag.main(n_wire=20)[0]
    assert seen["solved"] >= 8 and seen["freed"] == seen["solved"] == seen["dropped"], seen
    assert [s["iterations"] for s in dropped.stats] == [s["iterations"] for s in kept.stats]
    assert np.array_equal(dropped.poses, kept.poses)            # the same bits
    monkeypatch.undo()

    problem, H, slave = _scene("stick")
    (dq, dl), ev, aug = _augmented(problem, H, None)
    ev.drop_tangent()
    assert "Kp" not in ev.mult and "A" not in ev.mult
    with pytest.raises(ValueError, match="dropped"):
        problem.augmented_system(ev)
    aug.drop_tangent()
    assert aug.K is None and aug.factor is not None
    with pytest.raises(ValueError, match="dropped"):
        aug.solve(linsolve.Solver())
