"""The plectoneme example (``examples/plectoneme.py``) at a reduced size: the stabilised twisted pair
with self-contact, before the onset of writhing (the snap itself takes minutes: run the script)."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))

import plectoneme  # noqa: E402


@pytest.fixture(scope="module")
def run():
    return plectoneme.main(turns=0.5, steps=3, n_elements=8, stabilize=2e-3)


def test_reduced_run_reaches_its_turns_with_lk_equal_tw_plus_wr(run):
    sol, rows, _, checks = run
    assert checks["reached"] == pytest.approx(0.5)
    lk, tw, wr = (np.array([r[i] for r in rows]) for i in (0, 3, 4))
    assert np.allclose(tw + wr, lk, atol=1e-6)           # straight two-ply: all twist, no writhe
    assert np.abs(wr).max() < 1e-4 and checks["lk_error"] < 0.02


def test_torque_and_stabilisation_are_reported(run):
    sol, rows, _, _ = run
    G, J = 200e9 / 2.6, np.pi * plectoneme.R**4 / 2
    assert rows[-1][1] == pytest.approx(2 * G * J * np.pi / plectoneme.LENGTH, rel=0.1)
    st = [s["stabilization"] for s in sol.stats[1:]]
    assert st[0]["factor"] > 0 and all(s["fraction"] < 0.05 for s in st)
    assert all(s["dissipated"] > 0 for s in st[1:])


def test_self_contact_is_declared_between_the_wire_halves():
    model, plate, wires = plectoneme.build(n_elements=8)
    pairs = {(d.slave[0].id, d.master[0].id) for d in model.contacts if len(d.slave) == 1}
    (a_lo, a_up), (b_lo, b_up) = wires
    assert (a_lo.id, a_up.id) in pairs and (b_lo.id, b_up.id) in pairs
    assert len(plectoneme.wire_nodes(wires[0])) == 9
