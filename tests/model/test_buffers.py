"""``buffers.BufferPool``: a kept buffer is handed out again only when no array still uses it."""
import numpy as np
import pytest

from beamsolver.model.buffers import REUSE_BUFFERS, BufferPool


def _base(a):
    return a if a.base is None else a.base


@pytest.mark.skipif(not REUSE_BUFFERS, reason="buffers are not reused on this Python")
def test_a_free_buffer_is_reused_a_held_one_never():
    pool = BufferPool()
    a = pool.take((8, 24, 24))
    assert a.shape == (8, 24, 24) and _base(a).shape == (9, 24, 24)     # room for an eighth more
    a[...] = 1.0
    b = pool.take((9, 24, 24))                 # ``a`` held: a new buffer
    assert not np.shares_memory(a, b)
    np.testing.assert_array_equal(a, 1.0)
    first = id(_base(a))                       # (an id: a reference would hold the buffer)
    del a
    c = pool.take((7, 24, 24))                 # the first buffer is free again (and long enough)
    assert id(_base(c)) == first and c.shape == (7, 24, 24)
    del b, c
    d = pool.take((40, 24, 24))                # none long enough: a new one, the oldest dropped
    assert len(pool.buffers) == 2 and _base(d) is pool.buffers[0] and first not in map(id, pool.buffers)


@pytest.mark.skipif(not REUSE_BUFFERS, reason="buffers are not reused on this Python")
def test_growing_along_another_axis_and_dtype():
    pool = BufferPool(np.int32, axis=1)
    a = pool.take((2, 100))
    assert a.dtype == np.int32 and a.shape == (2, 100) and _base(a).shape == (2, 112)
    rows = a[0, :50]                           # a view of the view still holds the buffer
    del a
    b = pool.take((2, 60))
    assert not np.shares_memory(rows, b)
    del rows, b
    c = pool.take((2, 112))
    assert _base(c).shape == (2, 112) and c.shape == (2, 112)


def test_without_reuse_every_take_is_new(monkeypatch):
    from beamsolver.model import buffers
    monkeypatch.setattr(buffers, "REUSE_BUFFERS", False)
    pool = BufferPool()
    a = pool.take((5, 3))
    address = a.__array_interface__["data"][0]
    del a
    b = pool.take((5, 3))
    assert _base(b).shape == (5, 3)
    assert len(pool.buffers) == 2 and pool.buffers[1].__array_interface__["data"][0] == address


@pytest.mark.skipif(not REUSE_BUFFERS, reason="buffers are not reused on this Python")
def test_release_drops_only_the_buffers_nothing_uses():
    """``BufferPool.release`` (``buffers.release_idle``, issue 30: the 0.6 m rope's idle tangent blocks during a
    line search's trial) drops the kept buffers without a live view and keeps the others, with their values."""
    from beamsolver.model import buffers
    pool = BufferPool()
    a = pool.take((8, 24, 24))
    a[...] = 2.0
    b = pool.take((4, 24, 24))
    del b
    assert len(pool.buffers) == 2
    assert pool.release() == 4 * 24 * 24 * 8 and len(pool.buffers) == 1 and _base(a) is pool.buffers[0]
    np.testing.assert_array_equal(a, 2.0)
    assert pool.release() == 0
    del a
    assert buffers.release_idle() >= 9 * 24 * 24 * 8 and pool.buffers == []      # (a: 8 + an eighth)


def test_released_buffers_give_the_same_bits(monkeypatch):
    """The shear lag with exact stick (31 Newton systems) with the pools' idle buffers released at every
    ``Evaluation.drop_tangent`` (``RELEASE_MIN_VALUES`` 0; the default releases from 4e6 tangent values only) and
    the mmap threshold fixed: the same iterations and the same poses, bit for bit, as with the buffers kept."""
    import shear_lag
    from beamsolver.model import buffers
    calls = []
    release = buffers.release_idle

    def counted(**kw):
        calls.append(release(**kw))
        return calls[-1]
    kept = shear_lag.main(n_wire=20)[0]
    assert not calls
    monkeypatch.setattr(buffers, "RELEASE_MIN_VALUES", 0)
    monkeypatch.setattr(buffers, "release_idle", counted)
    released = shear_lag.main(n_wire=20)[0]
    assert len(calls) >= 30 and sum(calls) > 0
    assert [s["iterations"] for s in released.stats] == [s["iterations"] for s in kept.stats]
    assert np.array_equal(released.poses, kept.poses)


def _bits(sol):
    """Poses, iterations, contact tables and exact stick's nodal multipliers (``extra``) of every step, as bytes."""
    out = [np.asarray(sol.poses).tobytes(), repr([s["iterations"] for s in sol.stats])]
    for c in sol.contacts:
        out += [k + np.asarray(v).tobytes().hex() for k, v in sorted(c.items())]
    for k, steps in sorted(sol.extra.items()):
        out += [k + ("-" if v is None else np.asarray(v).tobytes().hex()) for v in steps]
    return out


@pytest.mark.slow
@pytest.mark.parametrize("scene", ["twisted_pair", "shear_lag"])
def test_release_at_commit_gives_the_same_bits(monkeypatch, scene):
    """``buffers.RELEASE_AT_COMMIT`` (issue 30: the pools' idle buffers let go at every accepted step, before the
    contributions' commit pass): the twisted pair (exact stick, the augmented path, 4 steps) and the shear lag
    (exact stick, 4 steps) give the same iterations, poses, contact tables and nodal multipliers, bit for bit, as
    with the buffers kept; and the release ran with buffers to drop."""
    from beamsolver.model import buffers
    if scene == "twisted_pair":
        import twisted_pair as ex
        run = lambda: ex.main(steps=4, turns=1.0, n_elements=32, check_stability=False)[0]   # noqa: E731
    else:
        import shear_lag as ex
        run = lambda: ex.main(n_wire=20)[0]      # noqa: E731
    monkeypatch.setattr(buffers, "RELEASE_AT_COMMIT", False)
    kept = _bits(run())
    calls = []
    release = buffers.release_idle

    def counted(**kw):
        calls.append(release(**kw))
        return calls[-1]
    monkeypatch.setattr(buffers, "RELEASE_AT_COMMIT", True)
    monkeypatch.setattr(buffers, "release_idle", counted)
    released = _bits(run())
    assert len(calls) >= 4 and (sum(calls) > 0 or not REUSE_BUFFERS)
    assert released == kept


@pytest.mark.slow
@pytest.mark.parametrize("scene", ["twisted_pair", "shear_lag"])
def test_lean_commit_gives_the_same_bits_and_holds_no_point_data_past_it(monkeypatch, scene):
    """Issue 30, the 61-wire strand in two steps: ``system.LEAN_COMMIT`` (the last step's point data let go before the
    commit's pass, its frames, ``_cache``, section poses and the kernel parameters ``results`` does not read after
    it), ``history.SHARED_STATE`` (``Solution.contact_state``: the history's own arrays, read-only, not copies) and
    ``linsolve.DROP_BASE_AT_COMMIT`` (the lagged solves' base let go at every accepted step): the twisted pair
    (exact stick, the augmented path, 4 steps) and the shear lag (exact stick, 4 steps) give the same iterations,
    poses, contact tables, nodal multipliers and contact state, bit for bit, as with all three off; and with them on,
    after every step the contact system holds no frames nor ``_cache``, five kernel parameters, no section poses
    once the table is read, and the state's history is the history's, read-only."""
    from beamsolver.contact import history, system
    from beamsolver.nonlinear import linsolve
    if scene == "twisted_pair":
        import twisted_pair as ex
        run = lambda: ex.main(steps=4, turns=1.0, n_elements=32, check_stability=False)[0]   # noqa: E731
    else:
        import shear_lag as ex
        run = lambda: ex.main(n_wire=20)[0]      # noqa: E731

    def state_bits(sol):
        return [k + np.asarray(v).tobytes().hex() for k, v in sorted(sol.contact_state.items())]
    knobs = ((system, "LEAN_COMMIT"), (history, "SHARED_STATE"), (linsolve, "DROP_BASE_AT_COMMIT"))
    for mod, name in knobs:
        monkeypatch.setattr(mod, name, False)
    sol = run()
    kept = _bits(sol) + state_bits(sol)
    for mod, name in knobs:
        monkeypatch.setattr(mod, name, True)
    seen, drops = [], []
    commit, results, drop = system.ContactSystem.commit, system.ContactSystem.results, linsolve.Solver.drop_base

    def commit_(self, H):
        commit(self, H)
        P, sel, p, out, _ = self._last
        seen.append((self, "HL" not in out and "HK" not in out and self._cache is None and sorted(p) ==
                     sorted(system._RESULTS_PARAMS)))

    def results_(self, H):
        table = results(self, H)
        seen.append((self, self._last is None or self._last[4][1] is None))
        return table
    monkeypatch.setattr(system.ContactSystem, "commit", commit_)
    monkeypatch.setattr(system.ContactSystem, "results", results_)
    monkeypatch.setattr(linsolve.Solver, "drop_base", lambda self: (drops.append(1), drop(self))[1])
    sol = run()
    assert _bits(sol) + state_bits(sol) == kept
    assert len(seen) >= 8 and all(ok for _, ok in seen) and len(drops) >= 4
    cs = seen[-1][0]
    state = cs.get_state()
    for k, v in cs.history.friction.items():
        assert state[f"history.{k}"] is v and not v.flags.writeable
    assert len(cs.history.friction["key"]) > 0
