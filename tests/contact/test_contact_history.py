"""``ContactHistory``: committed and trial copies, step life cycle, kinds of a step, restart state."""
import numpy as np
import pytest

from beamsolver.contact.frames import LINE, POINT
from beamsolver.contact.history import ContactHistory, empty_friction, lookup
from beamsolver.contact.state import KeyLayout
from beamsolver.errors import InputError

# 4 elements (beams 0, 0, 1, 1), 2 Gauss points, 2 declarations
LAYOUT = KeyLayout(n_el=4, max_gp=2, n_decls=2, el_beam=np.array([0, 0, 1, 1]), n_beams=2)


def _gauss_key(decl, e, g, m):
    return ((decl * LAYOUT.n_el + e) * LAYOUT.max_gp + g) * LAYOUT.n_beams + LAYOUT.el_beam[m]


def _friction(rows):
    """A friction history with one row per ``(decl, e, g, m)`` (sorted by key), values from the row."""
    rng = np.random.default_rng(len(rows))
    key = np.array([_gauss_key(*r) for r in rows], dtype=np.int64)
    order = np.argsort(key)
    k = len(rows)
    H = np.tile(np.eye(4), (k, 1, 1))
    H[:, :3, 3] = rng.normal(size=(k, 3))
    return dict(key=key[order], H_CL=H[order], H_FK=H[order] * 1.0, H_LK=H[order] * 1.0,
                e=np.array([r[1] for r in rows])[order], m=np.array([r[3] for r in rows])[order],
                xi1=rng.uniform(size=k)[order], xi2=rng.uniform(size=k)[order],
                lam_t=rng.normal(size=(k, 3))[order])


def test_lookup_finds_keys_by_binary_search():
    idx, found = lookup(np.array([2, 5, 9]), np.array([5, 3, 9, 10, 2]))
    assert found.tolist() == [True, False, True, False, True]
    assert idx[found].tolist() == [1, 2, 0]
    assert not lookup(np.zeros(0, dtype=np.int64), np.array([1]))[1].any()


def test_trial_multipliers_are_kept_only_by_commit():
    h = ContactHistory(LAYOUT)
    keys = np.array([1, 7], dtype=np.int64)
    h.update_multipliers(mult=(keys, np.array([3.0, 4.0])), tmult=(keys, np.ones((2, 3))))
    np.testing.assert_array_equal(h.normal_multipliers(np.array([7, 2, 1])), [4.0, 0.0, 3.0])
    np.testing.assert_array_equal(h.tangential_multipliers(np.array([2, 7])), [[0, 0, 0], [1, 1, 1]])
    assert len(h.state()["mult_keys"]) == 0            # the state is the committed part only
    h.rollback()                                       # a failed step: the trial copy is dropped
    np.testing.assert_array_equal(h.normal_multipliers(keys), 0.0)
    assert h.rollback == h.begin_step
    h.update_multipliers(mult=(keys, np.array([3.0, 4.0])))
    h.commit(np.array([0.3, 0.0]), tmult=(keys, 2 * np.ones((2, 3))))
    h.update_multipliers(mult=(keys, np.array([5.0, 6.0])))
    h.begin_step()                                     # the next step starts from the committed copy
    np.testing.assert_array_equal(h.normal_multipliers(keys), [3.0, 4.0])
    np.testing.assert_array_equal(h.tangential_multipliers(keys), 2.0)
    s = h.state()
    np.testing.assert_array_equal(s["mult_values"], [3.0, 4.0])
    np.testing.assert_array_equal(s["tmult_values"], 2.0)


def test_frictional_parameters_from_the_rows_found():
    h = ContactHistory(LAYOUT)
    rows = [(0, 0, 1, 2), (1, 3, 0, 1)]
    h.commit(np.array([0.3, 0.3]), _friction(rows))
    f = h.friction
    keys = np.array([_gauss_key(1, 3, 0, 1), _gauss_key(0, 1, 0, 2)], dtype=np.int64)   # found, not found
    p = dict(xi1=np.array([0.1, 0.2]), xi2=np.array([0.3, 0.4]))
    found = h.frictional(p, keys, np.array([2, 1]), np.array([1, 2]))
    assert found.tolist() == [True, False]
    i = int(np.flatnonzero(f["key"] == keys[0])[0])
    np.testing.assert_array_equal(p["H_CL"][0], f["H_CL"][i])
    np.testing.assert_array_equal(p["H_LK_prev"][1], np.eye(4))
    assert p["xi1_prev"][0] == f["xi1"][i] + f["e"][i] - 2            # re-expressed on element 2
    assert p["xi1_prev"][1] == 0.2 and p["xi2_prev"][1] == 0.4
    np.testing.assert_array_equal(p["lam_t_prev"], [f["lam_t"][i], np.zeros(3)])


def test_friction_starting_drops_its_declarations_rows_except_after_a_restart():
    rows = [(0, 0, 1, 2), (1, 3, 0, 1), (1, 2, 1, 0)]
    h = ContactHistory(LAYOUT)
    h.commit(np.array([0.3, 0.0]), _friction(rows))
    np.testing.assert_array_equal(h.friction_decl(), [0, 1, 1])
    state = h.state()
    h.start_friction(np.array([0.3, 0.0]))            # nothing starts
    assert len(h.friction["key"]) == 3
    h.start_friction(np.array([0.3, 0.5]))            # declaration 1's friction starts: its rows go
    np.testing.assert_array_equal(h.friction_decl(), [0])
    r = ContactHistory(LAYOUT)
    r.restore(state)
    r.start_friction(np.array([0.3, 0.5]))            # a restart keeps its history
    assert len(r.friction["key"]) == 3


def test_kinds_of_crossings_are_kept_within_a_step():
    h = ContactHistory(LAYOUT)
    e, m = np.array([0, 1, 2]), np.array([2, 3, 0])
    first = h.step_kinds(1, e, m, np.array([POINT, LINE, 1]))
    np.testing.assert_array_equal(first, [POINT, LINE, 1])
    again = h.step_kinds(1, e, m, np.array([1, LINE, POINT]))      # flipped crossings keep their kind
    np.testing.assert_array_equal(again, [POINT, LINE, 1])
    other = h.step_kinds(0, e, m, np.array([1, LINE, POINT]))      # another declaration: its own
    np.testing.assert_array_equal(other, [1, LINE, POINT])
    saved = h.memory()
    h.begin_step()                                                  # a new step decides afresh
    np.testing.assert_array_equal(h.step_kinds(1, e, m, np.array([1, LINE, POINT])), [1, LINE, POINT])
    h.recall(saved)
    np.testing.assert_array_equal(h.step_kinds(1, e, m, np.array([1, LINE, POINT])), [POINT, LINE, 1])


def test_state_round_trip_and_a_damaged_state():
    h = ContactHistory(LAYOUT)
    keys = np.array([_gauss_key(0, 0, 1, 2), _gauss_key(1, 3, 0, 1)], dtype=np.int64)
    h.update_multipliers(mult=(keys, np.array([1.0, 2.0])), tmult=(np.array([4], dtype=np.int64), np.ones((1, 3))))
    h.commit(np.array([0.3, 0.3]), _friction([(0, 0, 1, 2), (1, 3, 0, 1)]), (np.array([4]), np.ones((1, 3))))
    h.prev_points = np.array([3, 9], dtype=np.int64)
    s = h.state()
    r = ContactHistory(LAYOUT)
    r.restore(s)
    t = r.state()
    assert sorted(s) == sorted(t)
    for k in s:
        np.testing.assert_array_equal(s[k], t[k])
    np.testing.assert_array_equal(r.normal_multipliers(keys), [1.0, 2.0])     # trial = restored
    empty = ContactHistory(LAYOUT)
    empty.restore({})
    assert all(len(v) == 0 for v in empty.state().values())
    assert sorted(empty.friction) == sorted(empty_friction())
    bad = dict(s)
    bad["history.xi1"] = s["history.xi1"][:1]
    with pytest.raises(InputError, match="history.xi1"):
        ContactHistory(LAYOUT).restore(bad)
