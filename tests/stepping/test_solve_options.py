"""``solve``'s options as types: ``convergence=Convergence(...)``, the run options (``RunOptions``),
steppers by name (``stepping.steppers``) and output formats by name (``io.writers``), whose
``solution.npz`` checkpoint is a writer of its own."""
import dataclasses

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.io import writers
from beamsolver.stepping import steppers
from beamsolver.stepping.options import RunOptions
from beamsolver.stepping.steps import Run


def _cantilever(n=4):
    m = bs.Model()
    sec = bs.Section.circular(radius=0.01, E=2e11)
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(0, 0, 3.0 * sec.C[4, 4]))     # a large deflection: several iterations a step
    return m


def _same(a, b):
    assert np.array_equal(a.poses, b.poses) and np.array_equal(a.times, b.times)
    assert [s["iterations"] for s in a.stats] == [s["iterations"] for s in b.stats]
    assert [s["residuals"] for s in a.stats] == [s["residuals"] for s in b.stats]


def test_convergence_object_is_the_same_rule_as_the_keywords():
    m = _cantilever()
    conv = bs.Convergence(rtol=1e-6, dtol=1e-9, max_iter=12)
    a = bs.solve(m, steps=2, verbose=False, convergence=conv)
    b = bs.solve(m, steps=2, verbose=False, rtol=1e-6, dtol=1e-9, max_iter=12)
    _same(a, b)
    assert max(s["iterations"] for s in a.stats) > 2
    assert conv == bs.Convergence(rtol=1e-6, dtol=1e-9, max_iter=12)       # the caller's object is not changed
    # a tighter rule takes more iterations: the object is what decides
    c = bs.solve(m, steps=2, verbose=False, convergence=bs.Convergence(rtol=1e-12, dtol=0.0, max_iter=40))
    assert sum(s["iterations"] for s in c.stats) > sum(s["iterations"] for s in a.stats)


@pytest.mark.parametrize("kwargs, match", [
    (dict(convergence=bs.Convergence(), rtol=1e-6), r"either convergence= or rtol=1e-06"),
    (dict(convergence=bs.Convergence(), max_iter=5), r"either convergence= or max_iter=5"),
    (dict(convergence=dict(rtol=1e-6)), r"convergence must be a beamsolver.Convergence"),
    (dict(convergence=bs.Convergence(max_iter=0)), r"convergence.max_iter must be a positive integer"),
    (dict(convergence=bs.Convergence(rtol=-1.0)), r"convergence.rtol must be positive"),
    (dict(convergence=bs.Convergence(divergence=float("nan"))), r"convergence.divergence"),
])
def test_bad_convergence_is_refused_naming_it(kwargs, match):
    with pytest.raises(bs.InputError, match=match):
        bs.solve(_cantilever(), steps=1, verbose=False, **kwargs)


def test_run_options_are_typed():
    fields = {f.name for f in dataclasses.fields(RunOptions)}
    assert {"advice", "allow_unmet_tolerance", "check_stability", "modes", "branch_switching", "stabilizer",
            "path"} <= fields
    assert RunOptions.of(None) == RunOptions() and RunOptions.of(dict(modes=2)).modes == 2
    with pytest.raises(bs.InputError, match="unknown option.*'colour'"):
        RunOptions.of(dict(colour="red"))
    assert RunOptions().advice(RuntimeError("x"), None, None, 0.0) == ""


def test_a_registered_stepper_is_used_by_name():
    """A new stepping strategy is a registered class, not an edit of ``solve``: here the load stepper
    under another name, counting its steps (the same answer, bit for bit)."""
    calls = []

    class Counting(Run):
        name = "counting"

        def loop(self):
            calls.append(self.t)
            return super().loop()
    steppers.register(Counting)
    try:
        m = _cantilever()
        _same(bs.solve(m, steps=2, verbose=False, path="counting"), bs.solve(m, steps=2, verbose=False))
        assert calls == [0.0]
        with pytest.raises(bs.InputError, match="arc_length options need path='arc-length'"):
            bs.solve(m, steps=2, verbose=False, path="counting", arc_length=dict(max_steps=3))
    finally:
        del steppers.STEPPERS["counting"]
    with pytest.raises(bs.InputError, match="path must be 'load' or 'arc-length', got 'counting'"):
        bs.solve(_cantilever(), steps=1, verbose=False, path="counting")
    with pytest.raises(bs.InputError, match="lacks"):
        steppers.register(type("Half", (), {"name": "half", "loop": lambda self: None}))


class _Recorder:
    """A writer of a new format: records the steps it was given."""

    def __init__(self, folder, system):
        self.folder, self.steps, self.closed = folder, [], False

    def write(self, solution, step):
        self.steps.append(step)

    def close(self):
        self.closed = True


def test_a_new_format_cannot_lose_the_checkpoint(tmp_path):
    made = []
    writers.register("recorder", lambda folder, system: made.append(_Recorder(folder, system)) or made[-1])
    try:
        # the new format alone: solution.npz is still written (its own writer, in front of every format)
        out = writers.open_output(tmp_path / "alone", None, checkpoint=None, formats=["recorder"])
        assert isinstance(out.writers[0], writers.ArchiveWriter)
        sol = bs.solve(_cantilever(), steps=2, verbose=False)
        for k in range(len(sol)):
            out.write(sol, k)
        out.close()
        assert made[-1].steps == [0, 1, 2] and made[-1].closed and out.entries == {0: 0.0, 1: 0.5, 2: 1.0}
        np.testing.assert_array_equal(bs.load(tmp_path / "alone").poses, sol.poses)
        # registered as a default format: solve(output=folder) writes VTK, the new format and the archive
        writers.DEFAULT_FORMATS.append("recorder")
        sol = bs.solve(_cantilever(), steps=2, verbose=False, output=tmp_path / "run")
        assert made[-1].steps == [0, 1, 2] and (tmp_path / "run" / "beams.pvd").exists()
        np.testing.assert_array_equal(bs.load(tmp_path / "run").poses, sol.poses)
    finally:
        writers.FORMATS.pop("recorder", None)
        if "recorder" in writers.DEFAULT_FORMATS:
            writers.DEFAULT_FORMATS.remove("recorder")
    with pytest.raises(bs.InputError, match="unknown format.*'nope'"):
        writers.open_output(tmp_path / "x", None, formats=["nope"])


def test_the_archive_writer_keeps_its_checkpoint_rule(tmp_path):
    """``checkpoint=0``: saved at every step; ``inf``: only at ``close``; the folder's previous archive
    is removed at once."""
    sol = bs.solve(_cantilever(), steps=2, verbose=False)
    (tmp_path / "solution.npz").write_bytes(b"an old run")
    w = writers.ArchiveWriter(tmp_path, checkpoint=float("inf"))
    assert not (tmp_path / "solution.npz").exists()
    w.write(sol, 0)
    assert not (tmp_path / "solution.npz").exists()
    w.close()
    assert (tmp_path / "solution.npz").exists()
    every = writers.ArchiveWriter(tmp_path / "every", checkpoint=0)
    every.write(sol, 0)
    assert (tmp_path / "every" / "solution.npz").exists()
