"""Exact stick's commit (``contact.system.LIGHT_COMMIT``): the end of a step stores the points' frames, slips and
tractions and the mortar groups' state of every active point, those Newton's evaluations left out
(``SKIP_OPEN``) included, from the mortar kernel's point data alone (``kernel_jit.mortar_data``), not from an
evaluation of the forces of every point: the committed history, the point and nodal tables the same bits as
before."""
import numpy as np
import pytest

import beamsolver as bs
from beamsolver import driver
from beamsolver.contact import kernel_jit
from beamsolver.contact import system as csys

R, LAY, STRAIN = 1e-3, 0.1, 1e-4
_COMMIT = csys.ContactSystem.commit
_WARM_UP = driver.warm_up


def _strand():
    """A short 19-wire strand stretched in two steps: most of its search's points lie beyond the normal law's band,
    in open groups Newton's evaluations leave out (1872 of 2352 at the commits)."""
    L = bs.cables.Layer
    layers = [L(R)] + [L(R, 6 * k, lay_length=LAY) for k in (1, 2)]
    st = bs.cables.build_strand(layers, 0.25 * LAY, E=2e11, elements_per_lay=12, mu=0.3,
                                contact_options=dict(gauss_points=5), fit_core=True, touch_tol=-0.5)
    st.clamp("bottom")
    for w in st.all_wires:
        st.model.prescribe(w.last, bs.motion.translation(lambda t: (0.0, 0.0, STRAIN * st.length * t)))
    return st.model


def _solve(monkeypatch, light, inside=None):
    """The strand solved with ``LIGHT_COMMIT = light`` (absent before it existed: the full pass), every commit's
    contact state, point table and nodal table recorded; ``inside``: a list holding the commit's number while one runs."""
    monkeypatch.setattr(csys, "LIGHT_COMMIT", light, raising=False)
    records, warming = [], []
    orig = _COMMIT

    def warm_up(model):             # a first run's warm-up commits a throwaway problem: not one of the solve's
        warming.append(True)
        try:
            _WARM_UP(model)
        finally:
            warming.pop()

    def commit(self, H):
        if warming:
            return orig(self, H)
        if inside is not None:
            inside.append(len(records))
        try:
            orig(self, H)
        finally:
            if inside is not None:
                inside.pop()
        records.append(({k: np.array(v) for k, v in self.get_state().items()},
                        {k: np.array(v) for k, v in self.results(H).items()},
                        {k: np.array(v) for k, v in (self.nodal_results() or {}).items()},
                        self.kernel_inputs(H)))
        return None

    monkeypatch.setattr(csys.ContactSystem, "commit", commit)
    monkeypatch.setattr(driver, "warm_up", warm_up)
    sol = bs.solve(_strand(), steps=2, min_step_ratio=2.0 ** -3)
    return [s["iterations"] for s in sol.stats], records


def _bits(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.mark.slow
def test_commit_stores_the_same_bits_as_the_full_pass(monkeypatch):
    """Every array of the committed contact state (friction history, multipliers, extrapolation and c data, the
    search's memory), of the point table and of the nodal table after each step: the same bits with the light
    commit as with the evaluation of every point's forces (before); the same Newton iterations."""
    its0, full = _solve(monkeypatch, False)
    its1, light = _solve(monkeypatch, True)
    assert its0 == its1
    assert len(full) == len(light) == 3
    for (s0, r0, n0, _), (s1, r1, n1, _) in zip(full, light):
        for x, y in ((s0, s1), (r0, r1), (n0, n1)):
            assert sorted(x) == sorted(y)
            for k in x:
                assert _bits(x[k], y[k]), k
    assert len(light[-1][0]["history.key"]) > 2000       # the left-out points' history too


def test_commit_runs_no_force_pass(monkeypatch):
    """The commits call the mortar kernel for point data only (``mortar_data``, or chunk by chunk ``mortar_data_of``
    with ``LEAN_COMMIT``: every active point once), no kernel that computes forces (``mortar_forces``,
    ``mortar_terms``, the pairs' kernels); Newton's evaluations took fewer points (the open groups' left out), the
    commit all of them."""
    inside, calls = [], []
    names = ("mortar_forces", "mortar_terms", "contact_kernel", "kernel_and_tangent", "mortar_data", "mortar_data_of")
    for name in names:
        f = getattr(kernel_jit, name, None)
        if f is None:
            continue

        def counted(X, *args, _f=f, _name=name, **kw):
            calls.append((_name, inside[-1] if inside else None, len(args[0] if _name == "mortar_data_of" else X)))
            return _f(X, *args, **kw)
        monkeypatch.setattr(kernel_jit, name, counted)
    _, records = _solve(monkeypatch, True, inside)
    # the loaded steps' commits (step 0's commits the state before friction acts: the pairs' kernel)
    at_commit = [c for c in calls if c[1] is not None and c[1] >= 1]
    assert [c for c in at_commit if c[0] != ("mortar_data_of" if csys.LEAN_COMMIT else "mortar_data")] == []
    sizes = [len(r[1]["gap"]) for r in records[1:]]
    assert [c[2] for c in at_commit] == sizes
    evaluated = max(c[2] for c in calls if c[1] is None and c[0] in ("mortar_forces", "mortar_terms"))
    assert evaluated < 0.5 * min(sizes)


def test_mortar_data_is_mortar_forces_point_data(monkeypatch):
    """``kernel_jit.mortar_data``: the point data of ``mortar_forces(pairs=True)``, the same bits (points with and
    without friction history, in and out of the normal law's band)."""
    _, records = _solve(monkeypatch, True)
    X, p = records[-1][3]
    p = dict(p, has_history=p["has_history"] & (np.arange(len(X)) % 3 > 0))
    d0, d1 = kernel_jit.mortar_forces(X, p, pairs=True), kernel_jit.mortar_data(X, p)
    (_, pair0), (f1, pair1) = d0.pop("pairs"), d1.pop("pairs")
    assert f1 is None
    for k in d1:
        assert _bits(d0[k], d1[k]), k
    assert sorted(pair0) == sorted(pair1)
    for k in pair1:
        assert _bits(pair0[k], pair1[k]), k
    active = d1["active"]
    assert active.any() and not active.all()


def test_groups_kept_without_members_build_them_when_asked():
    """``mortar.groups(full=False)``: the keys, nodes, point groups and shape functions of a full build, nothing
    else; ``Groups`` keeps such a build for the same points and builds the members and slots when a call asks."""
    from beamsolver.contact import mortar
    rng = np.random.default_rng(3)
    P, n_nodes = 40, 12
    slave = np.sort(rng.choice(n_nodes, (P, 2)), axis=1)
    nodes = np.concatenate([slave, rng.integers(0, n_nodes, (P, 2))], axis=1)
    beam, decl, held = rng.integers(0, 2, P), np.zeros(P, int), rng.random((P, 2)) < 0.2
    xi = rng.uniform(0.01, 0.99, P)
    args = (slave, xi, beam, decl, nodes, n_nodes, 2, held)
    ref, part = mortar.groups(*args), mortar.groups(*args, full=False)
    assert sorted(part) == ["g", "key", "node", "phi"]
    for k in part:
        assert _bits(ref[k], part[k]), k
    keep = mortar.Groups()
    assert sorted(keep(*args, full=False)) == sorted(part) and keep.builds == 1
    assert sorted(keep(*args, full=False)) == sorted(part) and keep.builds == 1      # kept
    out = keep(*args)
    assert keep.builds == 2 and sorted(out) == sorted(ref)
    for k in ref:
        assert _bits(ref[k], out[k]), k
    assert sorted(keep(*args, full=False)) == sorted(ref) and keep.builds == 2       # the full build serves both


@pytest.mark.parametrize("chunk", [1, 7, None, 1 << 20])
def test_mortar_data_of_chunks_is_mortar_data(monkeypatch, chunk):
    """``kernel_jit.mortar_data_of(H, nodes, p, chunk=)`` (the commit's pass, ``system.LEAN_COMMIT``: the points'
    poses gathered chunk by chunk, ``HL`` and ``HK`` kept of the kernel's four frames): ``mortar_data(H[nodes], p)``,
    the same bits, for chunks of 1, 7, ``COMMIT_CHUNK`` and more than every point."""
    _, records = _solve(monkeypatch, True)
    X, p = records[-1][3]
    p = dict(p, has_history=p["has_history"] & (np.arange(len(X)) % 3 > 0))
    rng = np.random.default_rng(5)
    order = rng.permutation(4 * len(X))                     # the poses of every node, shuffled
    H = np.empty((4 * len(X), 4, 4))
    H[order] = X.reshape(-1, 4, 4)
    nodes = order.reshape(-1, 4)
    d0, d1 = kernel_jit.mortar_data(X, p), kernel_jit.mortar_data_of(H, nodes, p, chunk=chunk)
    (_, pair0), (_, pair1) = d0.pop("pairs"), d1.pop("pairs")
    assert sorted(d0) == sorted(d1) and sorted(pair0) == sorted(pair1)
    for k in d1:
        assert _bits(d0[k], d1[k]), k
    for k in pair1:
        assert _bits(pair0[k], pair1[k]), k
    assert d1["HL"].base.shape == (len(X), 2, 4, 4)
