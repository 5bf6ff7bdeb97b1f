"""A stabilised run is not a converged equilibrium unless its final state balances without the
damping (issue 28 item 1): per step the undamped residual and whether the state is an equilibrium
of the model, and the final verdict in the Solution, the saved file, ``beamsolver info`` and a
sweep row."""
import pickle
import subprocess
import sys
import warnings

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.app import study
from beamsolver.app.sweep_engine import run_point

P = 10.0      # N


def loaded(hold=False, n=6):
    """Cantilever (1 m, r = 1 cm steel) with a tip load ``P`` ramped to ``t = 1`` (held after with ``hold``)."""
    sec = bs.Section.circular(radius=1e-2, E=200e9, nu=0.3)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(0, P, 0), scale=(lambda t: min(t, 1.0)) if hold else (lambda t: t))
    return m, b


def _solve(m, **kw):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = bs.solve(m, verbose=False, **kw)
    return sol, [w for w in caught if issubclass(w.category, bs.StabilizationWarning)]


@pytest.mark.slow
def test_damping_carrying_the_load_is_not_a_converged_equilibrium(tmp_path):
    m, b = loaded()
    sol, warned = _solve(m, steps=4, stabilize=dict(factor=1e3), output=tmp_path / "out")
    lin = bs.linearize(m, sol)                   # the model's own residual at the final state
    carried = np.abs(lin.r[lin.dofs.component < 3]).max() / P
    assert carried > 0.9                         # the damping holds nearly all of the load
    rec = sol.stats[-1]["stabilization"]
    assert rec["equilibrium"] is False and rec["undamped_residual"] == pytest.approx(carried, rel=1e-6)
    assert not sol.converged and sol.off_equilibrium and sol.status == "off-equilibrium"
    assert "not an equilibrium" in sol.message
    assert any("not an equilibrium" in str(w.message) for w in warned)
    saved = bs.load(tmp_path / "out")
    assert saved.status == "off-equilibrium" and saved.message == sol.message
    assert saved.stats[-1]["stabilization"]["equilibrium"] is False
    out = subprocess.run([sys.executable, "-m", "beamsolver.app.cli", "info", str(tmp_path / "out")],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and "OFF-EQUILIBRIUM" in out.stdout and "; converged" not in out.stdout
    lines = out.stdout.splitlines()
    at = next(i for i, line in enumerate(lines) if line.split()[:1] == ["step"])
    assert lines[at].split()[-2:] == ["undamped", "equilibrium"]
    row = lines[at + 5]                                    # step 4, the last
    assert row.split()[-2:] == [f"{rec['undamped_residual']:.1e}", "NO"]


def test_stabilised_run_at_rest_is_a_converged_equilibrium():
    m, b = loaded(hold=True)
    ref = bs.solve(m, steps=4, verbose=False)
    sol, warned = _solve(m, steps=8, t_end=2.0, stabilize=True)
    rec = [s["stabilization"] for s in sol.stats[1:]]
    assert not rec[3]["equilibrium"]              # loading at t = 1: the damping carries a little
    assert rec[-1]["equilibrium"] and rec[-1]["undamped_residual"] <= 1e-8
    assert sol.converged and sol.status == "converged" and not warned
    assert np.abs(sol.position(b.last) - ref.position(b.last)).max() < 1e-9


def test_plain_run_and_restart_are_converged_and_the_status_round_trips(tmp_path):
    m, b = loaded()
    sol = bs.solve(m, steps=2, verbose=False)
    assert sol.status == "converged" and not sol.off_equilibrium
    sol.save(tmp_path / "s.npz")
    assert bs.load(tmp_path / "s.npz").status == "converged"
    off, _ = _solve(m, steps=2, stabilize=dict(factor=1e3))
    again, _ = _solve(m, steps=2, stabilize=dict(factor=1e3), restart=off)   # nothing left to solve
    assert again.status == "off-equilibrium"


def scene(factor=None):
    return loaded()


def tip(sol, model, beam):
    return {"tip": float(sol.position(beam.last)[1])}


def test_sweep_row_says_off_equilibrium(tmp_path):
    code = pickle.dumps((scene, tip))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bs.StabilizationWarning)
        row = run_point(code, {"factor": 1.0}, "p", str(tmp_path), {"steps": 2, "stabilize": {"factor": 1e3}})
        plain = run_point(code, {"factor": 0.0}, "q", str(tmp_path), {"steps": 2})
    assert row["status"] == "off-equilibrium" and "not an equilibrium" in row["message"] and "tip" in row
    assert plain["status"] == "converged"
    assert study.is_complete(study.read_point(tmp_path, "p"), {"factor": 1.0}, {"steps": 2,
                                                                                "stabilize": {"factor": 1e3}})


@pytest.mark.parametrize("stabilize", [dict(fraction=1e-2, settle=True), dict(factor=1e3, settle=True)])
def test_settle_ends_on_the_equilibrium_of_the_model(stabilize):
    m, b = loaded()
    ref = bs.solve(m, steps=4, verbose=False)
    sol, warned = _solve(m, steps=4, stabilize=stabilize)
    assert sol.status == "converged" and not any("not an equilibrium" in str(w.message) for w in warned)
    assert not sol.stats[2]["stabilization"]["equilibrium"]          # the steps before stay damped
    last = sol.stats[-1]
    assert last["stabilization"]["equilibrium"] and last["stabilization"]["undamped_residual"] <= 1e-8
    assert last["settle"]["iterations"] >= 1 and last["settle"]["from_residual"] > 1e-8
    assert np.abs(sol.position(b.last) - ref.position(b.last)).max() < 1e-9
    assert np.abs(bs.linearize(m, sol).r[:3]).max() < 1e-7 * P


def test_settle_option_is_checked():
    m, _ = loaded()
    with pytest.raises(bs.InputError, match="settle must be True or False"):
        bs.solve(m, steps=1, stabilize=dict(settle="yes"), verbose=False)
