"""Nothing lost (issue 12 item 9): whatever ends a run with ``output=``, the converged steps are saved.

In-process: an exception from a callback, from a prescribed motion, a Ctrl-C
(``KeyboardInterrupt``); ``checkpoint=None``.  Fault injection: a subprocess
running ``beamsolver run`` is sent SIGINT (exit 130, one line, folder
restartable) and, separately, SIGKILL (with ``checkpoint=0``); the folder then
loads, lists converged steps only, and ``--restart`` reaches the same final
state as an uninterrupted run.
"""
import os
import signal
import subprocess
import sys
import textwrap
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

import beamsolver as bs

ROOT = Path(__file__).resolve().parents[2]

SCENE = """
import time
import numpy as np
import beamsolver as bs


def build():
    m = bs.Model()
    sec = bs.Section.circular(radius=0.01, E=200e9, nu=0.3)
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 8), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(0.0, 0.0, 5e3), moment=(0.0, 2e3, 0.0))
    return m, b


def _slow(info):
    time.sleep({sleep})


solve_options = dict(steps={steps}, checkpoint={checkpoint}, callback=_slow)
"""
STEPS = 30


def _scene(steps=STEPS):
    ns = {}
    exec(SCENE.format(sleep=0.0, steps=steps, checkpoint=60.0), ns)
    return ns["build"]()


def _pvd_steps(folder):
    path = Path(folder) / "beams.pvd"
    if not path.exists():
        return 0
    try:
        return len(ET.parse(path).getroot()[0])
    except ET.ParseError:
        return 0


class _Boom(Exception):
    pass


def _raise_at(t_stop, exc=_Boom):
    def callback(info):
        if info["t"] > t_stop:
            raise exc("stop here")
    return callback


@pytest.mark.parametrize("exc", [_Boom, KeyboardInterrupt])
def test_an_exception_in_a_callback_keeps_the_converged_steps(tmp_path, exc):
    m, b = _scene(6)
    with pytest.raises(exc) as err:
        bs.solve(m, steps=6, output=tmp_path, callback=_raise_at(0.55, exc), verbose=False)
    sol = err.value.solution
    assert sol.n_steps == 3 and sol.times[-1] == 0.5 and exc.__name__ in sol.message
    saved = bs.load(tmp_path)
    np.testing.assert_array_equal(saved.times, sol.times)
    assert _pvd_steps(tmp_path) == 4
    m, b = _scene(6)
    rest = bs.solve(m, steps=6, restart=tmp_path, verbose=False)
    full = bs.solve(_scene(6)[0], steps=6, verbose=False)
    np.testing.assert_array_equal(rest.poses[-1], full.poses[-1])


def test_a_motion_that_raises_keeps_the_converged_steps(tmp_path):
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 4), bs.Section.circular(radius=0.01, E=2e11, nu=0.3))
    m.clamp(b.first)
    turn = bs.motion.rotation((1, 0, 0), 1.0)

    def motion(t):
        if t > 0.6:
            raise _Boom("motion failed")
        return turn(t)
    m.prescribe(b.last, motion)
    with pytest.raises(_Boom) as err:
        bs.solve(m, steps=4, output=tmp_path, verbose=False)
    assert err.value.solution.n_steps == 2
    assert bs.load(tmp_path).n_steps == 2


def test_checkpoint_none_still_saves_at_the_end(tmp_path):
    m, b = _scene(2)
    bs.solve(m, steps=2, output=tmp_path, checkpoint=None, verbose=False)
    assert bs.load(tmp_path).n_steps == 2


def _start(folder, checkpoint, steps=STEPS, restart=False):
    script = folder.parent / f"scene_{folder.name}.py"
    script.write_text(textwrap.dedent(SCENE.format(sleep=0.03, steps=steps, checkpoint=checkpoint)))
    cmd = [sys.executable, "-m", "beamsolver.app.cli", "run", str(script), "--output", str(folder), "--quiet"]
    if restart:
        cmd += ["--restart", str(folder)]
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=_interruptible)


def _interruptible():
    """In the child before ``exec``: SIGINT back to its default, so that Python raises ``KeyboardInterrupt`` on it as
    at a terminal.  A test run started in the background of a non-interactive shell (``pytest &``) ignores SIGINT, its
    children inherit that, and the run went on after the test's SIGINT (returncode 0, or a timeout)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _wait_for_steps(proc, folder, n, timeout=120.0):
    end = time.monotonic() + timeout
    while _pvd_steps(folder) < n:
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < end, "the run did not get going"
        time.sleep(0.02)


def _reference():
    m, b = _scene()
    return bs.solve(m, steps=STEPS, verbose=False)


@pytest.mark.slow
@pytest.mark.parametrize("sig, checkpoint", [(signal.SIGINT, 60.0), (signal.SIGKILL, 0)])
def test_fault_injection_signal_mid_run_then_restart(tmp_path, sig, checkpoint):
    folder = tmp_path / ("int" if sig == signal.SIGINT else "kill")
    proc = _start(folder, checkpoint)
    _wait_for_steps(proc, folder, 6)
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=60)
    ref = _reference()
    if sig == signal.SIGINT:
        assert proc.returncode == 130
        lines = err.strip().splitlines()
        assert len(lines) == 1 and "interrupted" in lines[0] and "--restart" in lines[0], err
    else:
        assert proc.returncode == -signal.SIGKILL
    part = bs.load(folder)
    k = part.n_steps
    assert 5 <= k < STEPS and abs(_pvd_steps(folder) - (k + 1)) <= 1
    np.testing.assert_array_equal(part.times, ref.times[:k + 1])
    np.testing.assert_array_equal(part.poses, ref.poses[:k + 1])
    rest = _start(folder, checkpoint, restart=True)
    out, err = rest.communicate(timeout=300)
    assert rest.returncode == 0, err
    final = bs.load(folder)
    np.testing.assert_array_equal(final.times, ref.times)
    np.testing.assert_array_equal(final.poses[-1], ref.poses[-1])
    assert _pvd_steps(folder) == STEPS + 1
