"""Exact stick's mortar kernel in passes (``contact.system.CHUNKED``, ``kernel_jit.mortar_terms(sink=)``,
``mortar.block_sink``): the points' tangents go to their groups' blocks ``kernel_jit.MORTAR_CHUNK`` points at a
time instead of through one ``(P, 24, 24)`` array (issue 30: 0.3 GB on the 37-wire bundle).  The same operations
per point and the same order of the sums: the evaluation is the same bits."""
import numpy as np
import pytest

from beamsolver import se3
from beamsolver.contact import kernel_jit, system as csys
from beamsolver.nonlinear.problem import Problem
from test_contact_exact_stick import R, _move, _parallel, _pressed, _updates_committed

TERMS = kernel_jit.mortar_terms


def _spied(monkeypatch, chunked, chunk, shapes=False):
    """``CHUNKED`` and ``MORTAR_CHUNK`` set, ``kernel_jit.mortar_terms`` spied on: the list the passes its sink gets
    are appended to, ``(a, b, len)`` (and the values' shape with ``shapes``)."""
    monkeypatch.setattr(csys, "CHUNKED", chunked)
    monkeypatch.setattr(kernel_jit, "MORTAR_CHUNK", chunk)
    passes = []
    terms = TERMS

    def spy(*a, sink=None, **k):
        if sink is not None:
            def counted(a0, b0, vals, _sink=sink):
                passes.append((a0, b0, len(vals)) + ((vals.shape,) if shapes else ()))
                _sink(a0, b0, vals)
            return terms(*a, sink=counted, **k)
        return terms(*a, **k)
    monkeypatch.setattr(kernel_jit, "mortar_terms", spy)
    return passes


def _evaluated(monkeypatch, chunked, chunk):
    """The pressed, slid slave of ``_parallel`` evaluated with the tangent and its augmented Newton matrix:
    ``(residual, tangent values, A's values, multiplier blocks, passes)``, ``passes`` the ``(a, b)`` the sink got."""
    passes = _spied(monkeypatch, chunked, chunk)
    model, slave, _ = _parallel(0.5, n_slave=8)
    problem = Problem.from_model(model, check_rigid_modes=False)
    H = _pressed(problem, slave, 2e-3 * R)
    problem.begin_step(H, 0.0)
    problem.commit(H)
    problem.begin_step(H, 0.1)
    H = _move(H, slave.nodes, se3.exp(np.array([1e-6 * R, 2e-7 * R, 0.0, 1e-6 * R, 0.0, 0.0])))
    ev = problem.evaluate(H, 0.1, tangent=True)
    assert ev.mult is not None
    blocks = {k: np.array(ev.mult[k]) for k in ("Kql", "Klq", "Kll", "C")}
    A = problem.augmented_system(ev).A if problem.augments(ev) else problem.linear_system(ev)[0]
    return ev.r.copy(), np.array(ev.extra[2]), A.data.copy(), blocks, passes


@pytest.mark.parametrize("chunk", [1, 7, 1 << 20])
def test_passes_give_the_bits_of_one_array(monkeypatch, chunk):
    ref = _evaluated(monkeypatch, False, chunk)
    out = _evaluated(monkeypatch, True, chunk)
    assert not ref[4]
    P = out[4][-1][1]
    assert P > 7                                      # (several passes at the small chunk sizes)
    assert [(a, b) for a, b, _ in out[4]] == [(a, min(a + chunk, P)) for a in range(0, P, chunk)]
    assert all(n == b - a for a, b, n in out[4])
    for x, y in zip(ref[:3], out[:3]):
        assert np.array_equal(x, y)
    for k in ref[3]:
        assert np.array_equal(ref[3][k], out[3][k]), k


def _updates(monkeypatch, chunked, chunk):
    """The slid slave of ``_parallel`` (sliding and sticking groups) evaluated with the tangent by the multiplier
    updates (``newton_multipliers`` off: step 0's first attempt, the four tractions' tangents): ``(residual,
    tangent values, passes)``, ``passes`` the ``(a, b, len)`` the sink got."""
    passes = _spied(monkeypatch, chunked, chunk, shapes=True)
    problem, slave, H = _updates_committed(n_slave=8, penalty_t=1e7)
    c = problem.contact
    slide = 8e-5 * R                       # (the groups of the deeper end stick, the others slide)
    H = _move(H, slave.nodes, se3.exp(np.array([slide, slide, 0.0, slide, 0.0, 0.5 * slide])))
    ev = problem.evaluate(H, 0.0, tangent=True)
    blocks = c._local_blocks(H, True)[5]["mortar"]
    assert ev.mult is None and not blocks["stick"].all() and blocks["stick"].any()   # both branches
    return ev.r.copy(), np.array(ev.extra[2]), np.array(blocks["K"]), passes


@pytest.mark.parametrize("chunk", [1, 7, 1 << 20])
def test_the_updates_passes_give_the_bits_of_the_four_tractions_array(monkeypatch, chunk):
    """With the multiplier updates the four tractions' tangents ``(4, P, 24, 24)`` are not held at once either
    (``ContactSystem._mortar_passes``: the point data first, the tangent's passes at the points' tractions then;
    0.4 GB at the 61-wire strand's step 0): the same residual, tangent and groups' blocks bit for bit."""
    ref = _updates(monkeypatch, False, chunk)
    out = _updates(monkeypatch, True, chunk)
    assert not ref[3]
    P = out[3][-1][1]
    assert P > 7
    assert [(a, b) for a, b, *_ in out[3]] == [(a, min(a + chunk, P)) for a in range(0, P, chunk)]
    assert all(shape == (b - a, 3, 24, 24) for a, b, _, shape in out[3])
    for x, y in zip(ref[:3], out[:3]):
        assert np.array_equal(x, y)
