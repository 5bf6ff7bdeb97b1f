"""A run into a used output folder that fails before its first step: no other run's result is left
behind, the ``ConvergenceError`` is the run's own, and the writer's thread is closed."""
import logging
import threading

import pytest

import beamsolver as bs


def _scene(load, at_start):
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 2), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(0, load, 0), scale=(lambda t: 1.0) if at_start else (lambda t: t))
    return m


def test_failed_rerun_leaves_no_stale_solution_and_closes_the_writer(tmp_path, caplog):
    out = tmp_path / "out"
    bs.solve(_scene(1.0, False), steps=3, output=out, verbose=False)
    assert bs.load(out).n_steps == 3
    with caplog.at_level(logging.ERROR, logger="beamsolver"):
        with pytest.raises(bs.ConvergenceError, match="t_start") as e:
            bs.solve(_scene(1e6, True), steps=3, output=out, verbose=False, max_iter=1)
    assert len(e.value.solution) == 0
    assert not caplog.records, [r.getMessage() for r in caplog.records]     # was: "step -1 out of range"
    assert sorted(p.name for p in out.iterdir()) == []                         # the old run's files are gone
    with pytest.raises(bs.InputError, match="no solution.npz"):
        bs.load(out)                                                           # was: the old run's 3 steps
    assert not [t for t in threading.enumerate() if t.name.startswith("beamsolver-output")]


def test_rerun_that_converges_replaces_the_old_solution(tmp_path):
    out = tmp_path / "out"
    bs.solve(_scene(1.0, False), steps=3, output=out, verbose=False)
    bs.solve(_scene(2.0, False), steps=2, output=out, verbose=False)
    sol = bs.load(out)
    assert sol.n_steps == 2 and sorted(p.name for p in out.glob("beams_*.vtu")) == \
        ["beams_0000.vtu", "beams_0001.vtu", "beams_0002.vtu"]
