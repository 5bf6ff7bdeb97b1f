"""The contact history's public state (``ContactSystem.get_state`` / ``set_state``), which
``restart`` and ``linearize`` use instead of private attributes."""
import inspect
import sys

import numpy as np

import beamsolver as bs
from beamsolver.nonlinear.problem import Problem
from beamsolver.stepping import restart


import rolling


def _contact_residual(contact, H):
    """The contact's blocks at ``H`` through the generic assembler, ``(6 n,)``."""
    return contact.sys.assemble_blocks(H, contact.evaluate(H, tangent=False)[0])[0]


def test_state_round_trip_gives_the_same_contact_forces():
    model, slave, _ = rolling.build(mu=0.5, n_elements=3)
    sol = bs.solve(model, steps=2)
    assert all(k.startswith("contact/") for k in sol.contact_state)     # Problem.get_state: name/key
    state = {k[len("contact/"):]: v for k, v in sol.contact_state.items()}
    assert len(state["history.key"]) > 0 and "prev_owners" in state
    fresh = Problem.from_model(model).contact
    fresh.set_state(state)
    back = fresh.get_state()
    assert back.keys() == state.keys()
    for k in state:
        np.testing.assert_array_equal(back[k], state[k])
    # the restored history acts: forces at a moved pose equal those of the original system
    H = sol.poses[-1].copy()
    H[slave.nodes, 0, 3] += 1e-4
    original = Problem.from_model(model).contact
    original.set_state(state)
    original.begin_step(sol.poses[-1], 1.0)
    fresh.begin_step(sol.poses[-1], 1.0)
    r1, r2 = _contact_residual(original, H), _contact_residual(fresh, H)
    np.testing.assert_array_equal(r1, r2)
    empty = Problem.from_model(model).contact                # no history: other tangential forces
    empty.begin_step(sol.poses[-1], 1.0)
    r0 = _contact_residual(empty, H)
    assert np.abs(r1 - r0).max() > 1e-6 * np.abs(r1).max()


def test_restart_uses_only_the_public_state():
    src = inspect.getsource(restart.contact_snapshot) + inspect.getsource(restart.contact_restore)
    assert "._" not in src
