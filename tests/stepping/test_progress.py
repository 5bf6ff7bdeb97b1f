"""Progress bar (tqdm, terminals only), per-step lines and logging."""
import io
import logging

import numpy as np

import beamsolver as bs


def cantilever():
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (10, 0, 0), 4), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(0, 1.0, 0))
    return m


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def test_silent_off_a_terminal_unless_verbose(capsys):
    bs.solve(cantilever(), steps=2)
    assert capsys.readouterr().out == ""
    bs.solve(cantilever(), steps=2, verbose=True)
    out = capsys.readouterr().out
    assert out.count("iterations") == 2 and "t = 1" in out


def test_bar_on_a_terminal(monkeypatch):
    term = _Terminal()
    monkeypatch.setattr("sys.stderr", term)
    bs.solve(cantilever(), steps=3)
    text = term.getvalue()
    assert "beamsolver" in text and "100%" in text and "step 3" in text and "residual" in text
    term2 = _Terminal()
    monkeypatch.setattr("sys.stderr", term2)
    bs.solve(cantilever(), steps=3, verbose=False)
    assert term2.getvalue() == ""


def test_logging_reports_steps_and_iterations(caplog):
    with caplog.at_level(logging.DEBUG, logger="beamsolver"):
        sol = bs.solve(cantilever(), steps=2)
    steps = [r for r in caplog.records if r.levelno == logging.INFO and r.getMessage().startswith("step")]
    assert len(steps) == 2
    its = [r for r in caplog.records if r.levelno == logging.DEBUG and "iteration" in r.getMessage()]
    assert len(its) == int(np.sum(sol.iterations)) + 2
