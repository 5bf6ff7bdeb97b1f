"""Saved results (npz) round trip exactly; a restarted run ends where an uninterrupted one does."""

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.io import archive

import crossing_beams
import rolling

L, EI = 10.0, 1e2


def cantilever(n_elements=6):
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=EI, EI3=EI, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (L, 0, 0), n_elements), sec, name="arm")
    m.clamp(b.first)
    m.add_load(b.last, force=(0, 3 * EI / L**2, 2 * EI / L**2), moment=(0, 0, 0.5 * EI / L))
    return m, b


def assert_same(a, b, wall_time=True):
    np.testing.assert_array_equal(a.times, b.times)
    for name in ("poses", "reactions", "section_forces", "strains"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    if wall_time:
        assert a.stats == b.stats
    else:
        clock = ("wall_time", "timings")      # wall-clock measures differ between runs
        assert [{k: v for k, v in s.items() if k not in clock} for s in a.stats] == \
            [{k: v for k, v in s.items() if k not in clock} for s in b.stats]
    assert len(a.contacts) == len(b.contacts)
    for ca, cb in zip(a.contacts, b.contacts):
        assert ca.keys() == cb.keys()
        for k in ca:
            assert np.asarray(ca[k]).dtype == cb[k].dtype and np.array_equal(ca[k], cb[k]), k
    assert a.converged == b.converged and a.message == b.message


def test_save_load_exact_round_trip(tmp_path):
    m, b = cantilever()
    sol = bs.solve(m, steps=3)
    path = sol.save(tmp_path / "cantilever")              # .npz appended
    assert path.name == "cantilever.npz"
    back = bs.load(path)
    assert back.model is None and back.system is None
    assert_same(sol, back)
    assert back.resume == sol.resume
    for k, v in sol.description.items():
        assert np.array_equal(v, back.description[k]) and np.asarray(v).dtype == back.description[k].dtype, k
    assert back.description["beam_name"].tolist() == ["arm"]
    assert back.description["constraint_kind"].tolist() == ["clamp"]
    np.testing.assert_array_equal(back.position(b.last), sol.position(b.last))
    np.testing.assert_array_equal(back.reaction(b.first, 2), sol.reaction(b.first, 2))
    with np.load(path) as data:                              # plain numpy, no pickle
        assert str(data["format"]) == archive.FORMAT and int(data["format_version"]) == archive.FORMAT_VERSION


def test_contact_tables_round_trip(tmp_path):
    model, _, _ = crossing_beams.build(n_elements=4, mu=0.2)
    sol = bs.solve(model, steps=2)
    back = bs.load(sol.save(tmp_path / "c.npz"))
    assert_same(sol, back)
    assert sol.contacts[0] == {} and len(back.contact(-1)["gap"]) >= 1
    assert back.contact_state.keys() == sol.contact_state.keys()


def test_load_refuses_newer_format_and_other_files(tmp_path):
    m, _ = cantilever(2)
    path = bs.solve(m, steps=1).save(tmp_path / "s.npz")
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["format_version"] = np.int64(archive.FORMAT_VERSION + 1)
    np.savez(tmp_path / "newer.npz", **arrays)
    with pytest.raises(bs.InputError, match="newer"):
        bs.load(tmp_path / "newer.npz")
    np.savez(tmp_path / "other.npz", x=np.zeros(3))
    with pytest.raises(bs.InputError, match="not a saved"):
        bs.load(tmp_path / "other.npz")
    with pytest.raises(bs.InputError):
        bs.load(tmp_path / "missing.npz")


class _Stop(Exception):
    pass


def _stop_after(t_stop):
    def callback(info):
        if info["t"] > t_stop:
            raise _Stop
    return callback


def test_restart_from_checkpoint_gives_same_final_state(tmp_path):
    m, b = cantilever()
    full = bs.solve(m, steps=6)
    m, b = cantilever()
    with pytest.raises(_Stop):      # a crash mid-run; checkpoint=0 saves after every step
        bs.solve(m, steps=6, output=tmp_path, checkpoint=0, callback=_stop_after(0.55))
    part = bs.load(tmp_path)
    assert part.times[-1] == pytest.approx(0.5)
    m, b = cantilever()
    rest = bs.solve(m, steps=6, restart=tmp_path / "solution.npz", output=tmp_path)
    assert_same(full, rest, wall_time=False)
    assert bs.load(tmp_path).n_steps == 6


def test_restart_with_friction_history_is_exact(tmp_path):
    model, slave, _ = rolling.build(mu=0.5, n_elements=3)
    full = bs.solve(model, steps=4)
    model, slave, _ = rolling.build(mu=0.5, n_elements=3)
    with pytest.raises(_Stop):
        bs.solve(model, steps=4, output=tmp_path, checkpoint=0, callback=_stop_after(0.6))
    model, slave, _ = rolling.build(mu=0.5, n_elements=3)
    rest = bs.solve(model, steps=4, restart=tmp_path)
    np.testing.assert_array_equal(rest.poses[-1], full.poses[-1])
    np.testing.assert_array_equal(rest.contact()["tangential_force"], full.contact()["tangential_force"])


def test_restart_continues_a_solution_object_and_checks_the_model():
    m, b = cantilever()
    half = bs.solve(m, steps=2, t_end=0.5)
    assert half.resume["steps"] == 2
    m2, _ = cantilever()
    more = bs.solve(m2, steps=4, t_end=1.0, restart=half)       # the grid starts at half.times[0]
    np.testing.assert_allclose(more.times, [0, 0.25, 0.5, 0.75, 1.0])
    np.testing.assert_array_equal(more.poses[:3], half.poses)
    assert half.n_steps == 2                                      # the restart source is not modified
    other, _ = cantilever(n_elements=3)
    with pytest.raises(bs.InputError, match="does not belong"):
        bs.solve(other, steps=4, restart=half)


def test_restart_reads_archives_with_the_contact_state_not_namespaced(tmp_path):
    """Archives written before ``Problem.get_state`` namespaced its keys (``contact_state/<key>``, the
    contact history alone) restart exactly as the namespaced ones (``contact_state/contact/<key>``)."""
    model, slave, _ = rolling.build(mu=0.5, n_elements=3)
    full = bs.solve(model, steps=4)
    model, slave, _ = rolling.build(mu=0.5, n_elements=3)
    with pytest.raises(_Stop):
        bs.solve(model, steps=4, output=tmp_path, checkpoint=0, callback=_stop_after(0.6))
    with np.load(tmp_path / "solution.npz") as z:
        arrays = dict(z)
    keys = [k for k in arrays if k.startswith("contact_state/")]
    assert keys and all(k.startswith("contact_state/contact/") for k in keys)
    for k in keys:                                    # the layout of the archives written before
        arrays["contact_state/" + k[len("contact_state/contact/"):]] = arrays.pop(k)
    np.savez_compressed(tmp_path / "old.npz", **arrays)
    assert bs.load(tmp_path / "old.npz").contact_state.keys() >= {"history.key", "prev_owners"}
    model, slave, _ = rolling.build(mu=0.5, n_elements=3)
    rest = bs.solve(model, steps=4, restart=tmp_path / "old.npz")
    np.testing.assert_array_equal(rest.poses[-1], full.poses[-1])
    np.testing.assert_array_equal(rest.contact()["tangential_force"], full.contact()["tangential_force"])
