"""The twisted-pair example (frictionless) at a reduced size."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import twisted_pair  # noqa: E402


@pytest.fixture(scope="module")
def runs():
    kw = dict(turns=0.5, steps=4, n_elements=8, mu=0.0)
    base = twisted_pair.main(**kw)
    swapped = twisted_pair.main(swap=True, **kw)
    return base, swapped


def test_wires_touch_and_torque_grows(runs):
    (sol, rows, _), _ = runs
    assert sol.times[-1] == pytest.approx(1.0)
    twist = np.array([r[0] for r in rows])
    torque = np.array([r[1] for r in rows])
    assert np.all(np.diff(torque) > 0) and torque[-1] > 0
    # torsion of both wires dominates: 2 G J phi / L within 10 %
    G, J = 200e9 / 2.6, np.pi * 0.5e-3**4 / 2
    assert torque[-1] == pytest.approx(2 * G * J * 2 * np.pi * twist[-1] / 0.02, rel=0.1)
    c = sol.contact(-1)
    active = c["normal_force"] > 0
    assert active.sum() >= 10
    # touching along the twisted part: gaps within the smoothing gap, no deep penetration
    assert np.all(np.abs(c["gap"][active]) < 2e-3 * 0.5e-3 * 2)


def test_slave_master_symmetry(runs):
    (_, rows, _), (_, rows_s, _) = runs
    assert rows_s[-1][1] == pytest.approx(rows[-1][1], rel=0.02)
    assert rows_s[-1][2] == pytest.approx(rows[-1][2], rel=1e-6)


def test_halved_steps_agree(runs):
    (_, rows, _), _ = runs
    _, rows_h, _ = twisted_pair.main(turns=0.5, steps=8, n_elements=8, mu=0.0)
    assert rows_h[-1][1] == pytest.approx(rows[-1][1], rel=1e-3)
    assert rows_h[-1][2] == pytest.approx(rows[-1][2], rel=1e-6)
