"""The plectoneme example (``examples/plectoneme.py``) at a reduced size: the stabilised twisted pair
with self-contact, before the onset of writhing (the snap itself takes minutes: run the script)."""

import numpy as np
import pytest


import plectoneme


@pytest.fixture(scope="module")
def run():
    return plectoneme.main(turns=0.5, steps=3, n_elements=8, stabilize=2e-3)


def test_reduced_run_reaches_its_turns_with_lk_equal_tw_plus_wr(run):
    sol, rows, _, checks = run
    assert checks["reached"] == pytest.approx(0.5)
    lk, tw, wr = (np.array([getattr(r, f) for r in rows]) for f in ("lk", "tw", "wr"))
    assert np.allclose(tw + wr, lk, atol=1e-6)           # straight two-ply: all twist, no writhe
    assert np.abs(wr).max() < 1e-4 and checks["lk_error"] < 0.02


def test_torque_and_stabilisation_are_reported(run):
    sol, rows, _, _ = run
    G, J = 200e9 / 2.6, np.pi * plectoneme.R**4 / 2
    assert rows[-1].torque == pytest.approx(2 * G * J * np.pi / plectoneme.LENGTH, rel=0.1)
    st = [s["stabilization"] for s in sol.stats[1:]]
    assert st[0]["factor"] > 0 and all(s["fraction"] < 0.05 for s in st)
    assert all(s["dissipated"] > 0 for s in st[1:])


def test_self_contact_is_declared_between_the_wire_halves():
    model, plate, wires = plectoneme.build(n_elements=8)
    pairs = {(d.slave[0].id, d.master[0].id) for d in model.contacts if len(d.slave) == 1}
    (a_lo, a_up), (b_lo, b_up) = wires
    assert (a_lo.id, a_up.id) in pairs and (b_lo.id, b_up.id) in pairs
    assert len(plectoneme.wire_nodes(wires[0])) == 9


def test_length_and_pull_are_build_arguments():
    model, plate, wires = plectoneme.build(n_elements=8, length=0.06, pull=50.0)
    z = model.poses0[plectoneme.wire_nodes(wires[0]), 2, 3]
    assert z[-1] == pytest.approx(0.06) and z[4] == pytest.approx(0.03)
    pulls = [ld.force[2] for ld in model.loads if ld.node == plate]
    assert pulls == [pytest.approx(50.0)]


def test_extension_control_prescribes_the_plate_height_with_its_turns():
    model, plate, wires = plectoneme.build(n_elements=8, length=0.06, approach=0.25, turns=2.0)
    kind, motion = model.constraints[plate]
    assert kind == "prescribe" and not [ld for ld in model.loads if ld.node == plate]
    G, angle = motion(0.3), 2 * np.pi * 2.0 * 0.3
    assert np.allclose(G[:3, :3] @ [1.0, 0.0, 0.0], [np.cos(angle), np.sin(angle), 0.0], atol=1e-12)
    assert np.allclose((G @ model.poses0[plate])[:3, 3], [0.0, 0.0, 0.06 * (1 - 0.25 * 0.3)])


def test_wires_in_pieces_have_self_contact_between_every_two_pieces():
    model, plate, wires = plectoneme.build(n_elements=12, pieces=3)
    pairs = {(d.slave[0].id, d.master[0].id) for d in model.contacts if len(d.slave) == 1}
    for wire in wires:
        ids = [b.id for b in wire]
        assert len(ids) == 3 and {(ids[0], ids[1]), (ids[0], ids[2]), (ids[1], ids[2])} <= pairs
    nodes = plectoneme.wire_nodes(wires[0])
    assert len(nodes) == 13 and np.allclose(np.diff(model.poses0[nodes, 2, 3]), 0.02 / 12)
    mid = [ld.node for ld in model.loads if ld.force[1] != 0.0]
    assert np.allclose(model.poses0[mid, 2, 3], 0.01)
    with pytest.raises(plectoneme.bs.InputError, match="pieces"):
        plectoneme.build(n_elements=8, pieces=3)


@pytest.mark.slow
def test_extension_control_buckles_the_pair_at_its_euler_load():
    """Shortened by 1.2 mm of 60 mm with a tenth of a turn, the clamped-clamped pair buckles: the
    axial force (the support's reaction, tension positive) sits on the Euler load
    ``4 pi^2 B / L^2`` of the pair (``B = 2 E I``; 8 coarse elements per wire: a few % stiff)."""
    sol, rows, _, checks = plectoneme.main(turns=0.1, steps=4, n_elements=8, stabilize=None, length=0.06,
                                           approach=0.02, pull=50.0)
    assert checks["reached"] == pytest.approx(0.1) and checks["lk_error"] < 0.02
    B = 2 * 200e9 * np.pi * plectoneme.R**4 / 4
    euler = 4 * np.pi**2 * B / 0.06**2
    assert rows[-1].axial == pytest.approx(-euler, rel=0.06)
    assert rows[-1].z == pytest.approx(60.0 * (1 - 0.02))


@pytest.mark.slow
def test_frictionless_pair_writhes_at_greenhills_torque():
    """Frictionless, with a small imperfection, the pair leaves the straight two-ply at the torque
    where its tangent turns indefinite (``M L / B = 8.36``, ``B = 2 E I``; Greenhill's single
    clamped rod 8.99) and converts a large part of the twist to writhe, Lk = Tw + Wr holding."""
    sol, rows, _, checks = plectoneme.main(turns=2.0, steps=20, n_elements=8, mu=0.0, stabilize=2e-3,
                                           imperfection=1e-3)
    assert checks["onset_ratio"] == pytest.approx(8.36, rel=0.03)
    assert checks["onset_ratio"] == pytest.approx(plectoneme.GREENHILL, rel=0.1)
    assert checks["writhe"] > 0.3 and checks["lk_error"] < 0.02


def test_two_stage_path_holds_the_turns_while_the_pull_relaxes():
    """``twist_until``: the turns reached at ``t1`` and held; the dead pull then goes linearly to
    ``relax`` (which also scales the imperfection)."""
    model, plate, wires = plectoneme.build(n_elements=8, turns=5.5, pull=2000.0, relax=300.0, twist_until=0.5)
    angle = model.fix_values[plate][5]
    assert angle(0.25) == pytest.approx(2 * np.pi * 2.75) and angle(0.5) == angle(0.8) == pytest.approx(11 * np.pi)
    pull, = [ld for ld in model.loads if ld.node == plate]
    assert [pull.force[2] * pull.scale(t) for t in (0.0, 0.5, 0.75, 1.0)] == pytest.approx([2000, 2000, 1150, 300])
    lateral = [ld.force[1] for ld in model.loads if ld.force[1] != 0.0]
    assert lateral == pytest.approx([3.0, 3.0])
    with pytest.raises(plectoneme.bs.InputError, match="relax"):
        plectoneme.build(n_elements=8, relax=300.0)
    with pytest.raises(plectoneme.bs.InputError, match="twist_until"):
        plectoneme.build(n_elements=8, twist_until=0.0)


@pytest.mark.slow
def test_two_stage_run_holds_lk_while_the_pull_relaxes():
    """A reduced two-stage run: the straight two-ply twisted 1 turn under 2000 N, the pull then
    lowered to 300 N (still far above the critical pull of 1 turn): ``Lk`` stays 1, all twist."""
    sol, rows, _, checks = plectoneme.main(turns=1.0, steps=4, n_elements=8, mu=0.0, stabilize=None, length=0.06,
                                           pull=2000.0, relax=300.0, twist_until=0.5)
    t = np.array([r.t for r in rows])
    assert t[-1] == pytest.approx(1.0) and checks["reached"] == pytest.approx(1.0)
    lk, tw, wr, axial = (np.array([getattr(r, f) for r in rows]) for f in ("lk", "tw", "wr", "axial"))
    assert np.allclose(lk, np.minimum(t / 0.5, 1.0))
    assert np.allclose(axial, 2000.0 - 1700.0 * np.clip((t - 0.5) / 0.5, 0, 1), rtol=1e-6)
    assert np.abs(wr).max() < 1e-3 and np.allclose(tw + wr, lk, atol=1e-6)


@pytest.mark.slow
def test_extension_controlled_pair_passes_five_turns_through_the_pop_of_its_loop():
    """The documented run (docstring: ``--length 0.06 --pull 50 --elements 24 --steps 50
    --stabilize 5e-2 --approach 0.3 --min-step-ratio 1e-7``): the loop that forms at mid-height pops
    at about 3.98 turns (it stalled there before the crossing kinds of docs/theory.md section 20) and
    the run reaches the 5 turns, its arms pressed together, with Lk = Tw + Wr within 2 %."""
    sol, rows, _, checks = plectoneme.main(turns=5.0, steps=50, n_elements=24, length=0.06, pull=50.0,
                                           stabilize=5e-2, approach=0.3, min_step_ratio=1e-7)
    assert checks["t_end"] == 1.0 and checks["reached"] == pytest.approx(5.0)
    assert checks["lk_error"] < 0.02
    assert checks["writhe"] > 0.15                       # the loop: about a fifth of Lk is writhe
    lk, wr = np.array([r.lk for r in rows]), np.array([r.wr for r in rows])
    gain = wr - wr[np.searchsorted(lk, lk - 0.01)]      # writhe gained over the last 0.01 turn
    assert wr[-1] > 1.0 and gain.max() > 0.25           # the pop: Wr 0.58 -> 0.87 within 4e-4 turn


@pytest.mark.slow
def test_exact_stick_passes_where_a_sliver_group_stalled_it():
    """The extension-controlled run of the five-turn test with exact stick, to t = 0.3 (1.5 turns), steps cut to
    1e-3 of 0.02 at most: it stalled at t = 0.2839 (multiplier steps of 1e22: a group of the slave node next to
    the joint of the master's pieces had one Gauss point with a shape function of 0.047, shared with its
    neighbour, ``mortar.slivers``); then 607 Newton iterations, about 11 s of CPU.  Since the mortar groups follow the
    master's chain (session 8, ``contact.system.CHAIN_GROUPS``) the joint makes no sliver: 645 iterations (10 cut-backs)
    with the fold, 663 (12) without it (650 / 665 before the normal law's active set, ``newton.NORMAL_SWITCHES``)."""
    import beamsolver as bs
    model, _, _ = plectoneme.build(turns=5.0, n_elements=24, length=0.06, pull=50.0, approach=0.3, stick="exact")
    sol = bs.solve(model, steps=15, t_end=0.3, stabilize=5e-2, min_step_ratio=1e-3, verbose=False)
    assert sol.times[-1] == pytest.approx(0.3)
