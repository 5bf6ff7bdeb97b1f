"""A restart's contact state is checked before it is used (issue 28 item 3): shifted element ids
restarted "successfully" with the friction force reversed, other damage gave a raw IndexError."""

import numpy as np
import pytest

import beamsolver as bs

import rolling


class _Stop(Exception):
    pass


def _stop(info):
    if info["t"] > 0.6:
        raise _Stop


@pytest.fixture(scope="module")
def runs():
    """The uninterrupted run and the part of it stopped after t = 0.5 (friction history committed)."""
    model, _, _ = rolling.build(mu=0.5, n_elements=3)
    full = bs.solve(model, steps=4, verbose=False)
    model, _, _ = rolling.build(mu=0.5, n_elements=3)
    with pytest.raises(_Stop) as e:
        bs.solve(model, steps=4, callback=_stop, verbose=False)
    return full, e.value.solution


def _restart(part, change):
    bad = part.copy_steps(part.model, part.system)
    state = dict(bad.contact_state)
    change(state)
    bad.contact_state = state
    model, _, _ = rolling.build(mu=0.5, n_elements=3)
    return bs.solve(model, steps=4, restart=bad, verbose=False)


def test_intact_state_restarts_exactly(runs):
    full, part = runs
    assert len(part.contact_state["contact/history.key"]) > 0
    rest = _restart(part, lambda s: None)
    np.testing.assert_array_equal(rest.contact()["tangential_force"], full.contact()["tangential_force"])


def _shift(name, by=1):
    def change(s):
        s[name] = np.asarray(s[name]) + by
    return change


def _set(name, value):
    def change(s):
        s[name] = value(np.asarray(s[name]))
    return change


@pytest.mark.parametrize("change, words", [
    (lambda s: (_shift("contact/history.e")(s), _shift("contact/history.m")(s)), "disagree with 'history.key'"),
    (_shift("contact/history.e", -1), "'history.e'"),
    (_shift("contact/history.e", 10**6), "'history.e' has ids outside"),
    (lambda s: s.update({k: np.concatenate([v, v]) for k, v in s.items() if k.startswith("contact/history.")}),
     "'history.key' is not strictly increasing"),
    (_set("contact/history.H_CL", lambda a: a[:, :3]), r"'history.H_CL' has shape"),
    (_set("contact/history.lam_t", lambda a: a * np.nan), "'history.lam_t' is not finite"),
    (_set("contact/history.xi1", lambda a: a[:-1]), r"'history.xi1' has shape"),
    (_set("contact/history.e", lambda a: a.astype(float) + 0.5), "'history.e' must hold integers"),
    (_set("contact/prev_owners", lambda a: np.r_[a, -1]), "'prev_owners' has ids outside"),
    (_set("contact/prev_points", lambda a: np.r_[a, 10**12]), "'prev_points' has ids outside"),
    (_set("contact/mult_values", lambda a: np.r_[a, 1.0]), r"'mult_values' has shape"),
    (lambda s: s.pop("contact/history.H_FK"), "history has"),
    (lambda s: s.update({"friction/" + k.split("/", 1)[1]: s.pop(k) for k in list(s)}),
     r"entries of \['friction'\], which this model does not have"),
])
def test_damaged_state_is_refused_naming_the_entry(runs, change, words):
    _, part = runs
    with pytest.raises(bs.InputError, match=words):
        _restart(part, change)
