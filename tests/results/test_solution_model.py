"""``Solution`` as a public, validated data model (issue 13 item 4).

Every bad field gives an ``InputError`` naming the field and the value; appending is cheap
(views, amortised O(1)); save/load round trips every public field, and version-1 archives
(written before ``extra`` existed) still load; the consumers (VTK, pictures, command line,
``linearize``, restart) work on a ``Solution`` built only through the public API; and no
module outside ``results.py`` touches its private attributes.
"""
import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.results.solution import Solution, Step, describe_model

ROOT = Path(__file__).resolve().parents[2]
L, EI = 10.0, 1e2


def cantilever(n_elements=4):
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=EI, EI3=EI, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (L, 0, 0), n_elements), sec, name="arm")
    m.clamp(b.first)
    m.add_load(b.last, force=(0, 0.3 * EI / L**2, 0.0), scale=lambda t: t)
    return m, b


@pytest.fixture(scope="module")
def solved():
    m, b = cantilever()
    return m, b, bs.solve(m, steps=2)


def step_args(sol, k):
    return (sol.times[k], sol.poses[k], sol.reactions[k], sol.section_forces[k], sol.strains[k], dict(sol.stats[k]))


def empty_like(sol):
    return Solution(None, None, sol.description)


# ------------------------------------------------------------------ validation
FIELDS = ("times", "poses", "reactions", "section_forces", "strains", "stats")


@pytest.mark.parametrize("field, bad, match", [
    ("times", lambda v: -1.0, r"times must increase, got t = -1\.0 after 0\.0"),
    ("times", lambda v: float("nan"), r"times must be finite numbers, got t = nan"),
    ("times", lambda v: "0.5", r"times must be finite numbers, got t = '0.5'"),
    ("poses", lambda v: v[1:], r"poses must have shape \(5, 4, 4\) \(one pose per node\), got \(4, 4, 4\)"),
    ("poses", lambda v: np.where(np.arange(16).reshape(4, 4) == 3, np.inf, v),
     r"poses must be finite, got inf at index \(0, 0, 3\)"),
    ("reactions", lambda v: v[:, :3], r"reactions must have shape \(5, 6\) .*got \(5, 3\)"),
    ("reactions", lambda v: v * np.nan, r"reactions must be finite, got nan at index \(0, 0\)"),
    ("section_forces", lambda v: v[:2], r"section_forces must have shape \(4, 6\) .*got \(2, 6\)"),
    ("strains", lambda v: np.full((4, 6), -np.inf), r"strains must be finite, got -inf at index \(0, 0\)"),
    ("strains", lambda v: "x", r"strains must be an array of numbers of shape \(4, 6\) .*got str"),
    ("stats", lambda v: [1, 2], r"stats must be a dict, got list"),
])
def test_append_names_the_bad_field_and_value(solved, field, bad, match):
    _, _, sol = solved
    new = empty_like(sol)
    new.append(*step_args(sol, 0))
    args = list(step_args(sol, 1))
    i = FIELDS.index(field)
    args[i] = bad(args[i])
    with pytest.raises(bs.InputError, match=r"Solution\.append: " + match):
        new.append(*args)
    assert len(new) == 1 and len(new.stats) == 1 and len(new.contacts) == 1   # nothing half-recorded
    new.append(*step_args(sol, 1))                                            # and it goes on
    assert new.n_steps == 1


def test_an_append_interrupted_halfway_records_nothing(solved, monkeypatch):
    """Ctrl-C inside ``append`` (here: while writing the third array): the step is not recorded,
    every field keeps the same number of steps, and the next append goes on from there."""
    from beamsolver.results import solution as results
    _, _, sol = solved
    new = empty_like(sol)
    new.append(*step_args(sol, 0))
    put, calls = results._Growing.put, []

    def interrupted(self, k, value):
        calls.append(k)
        if len(calls) == 3:
            raise KeyboardInterrupt
        put(self, k, value)
    monkeypatch.setattr(results._Growing, "put", interrupted)
    with pytest.raises(KeyboardInterrupt):
        new.append(*step_args(sol, 1), contact=None, extra={"x": 1.0})
    monkeypatch.setattr(results._Growing, "put", put)
    assert len(new) == 1 and [len(new.times), len(new.poses), len(new.stats), len(new.contacts)] == [1] * 4
    new.append(*step_args(sol, 1), extra={"x": 2.0})
    assert len(new.stats) == 2 and new.extra == {"x": [None, 2.0]}
    np.testing.assert_array_equal(new.reactions, sol.reactions[:2])


def test_huge_finite_values_are_accepted(solved):
    """The finiteness check sums first; a sum that overflows from finite values is not an error."""
    _, _, sol = solved
    new = empty_like(sol)
    t, H, R, S, E, st = step_args(sol, 0)
    new.append(t, H, np.full_like(R, 1e308), S, E, st)
    assert np.all(new.reactions == 1e308)


def test_contact_and_extra_are_checked(solved):
    _, _, sol = solved
    new = empty_like(sol)
    with pytest.raises(bs.InputError, match=r"contact arrays must have one row per contact point, got rows "
                                            r"\{'gap': 2, 'normal_force': 3\}"):
        new.append(*step_args(sol, 0), contact=dict(gap=np.zeros(2), normal_force=np.ones(3)))
    with pytest.raises(bs.InputError, match=r"contact must be a dict of arrays .* got list"):
        new.append(*step_args(sol, 0), contact=[1.0])
    with pytest.raises(bs.InputError, match=r"extra must be a dict keyed by non-empty names, got \{'': 1\}"):
        new.append(*step_args(sol, 0), extra={"": 1})
    with pytest.raises(bs.InputError, match=r"extra\['info'\] must be a number, bool, string or array of them, "
                                            r"got \{'a': 1\}"):
        new.append(*step_args(sol, 0), extra={"info": {"a": 1}})
    assert len(new) == 0


def test_from_steps_checks_lengths_and_every_step(solved):
    _, _, sol = solved
    f = dict(description=sol.description, times=sol.times, poses=sol.poses, reactions=sol.reactions,
             section_forces=sol.section_forces, strains=sol.strains)
    with pytest.raises(bs.InputError, match=r"from_steps: reactions must have one entry per step \(3 times\), got 2"):
        Solution.from_steps(**dict(f, reactions=sol.reactions[:2]))
    with pytest.raises(bs.InputError, match=r"from_steps: extra\['mode'\] must have one entry per step"):
        Solution.from_steps(**f, extra={"mode": [None]})
    with pytest.raises(bs.InputError, match=r"from_steps \(step 2\): times must increase, got t = 0\.5 after 0\.5"):
        Solution.from_steps(**dict(f, times=[0.0, 0.5, 0.5]))
    bad = sol.poses.copy()
    bad[1, 2, 0, 0] = np.nan
    with pytest.raises(bs.InputError, match=r"from_steps \(step 1\): poses must be finite, got nan at index \(2, 0, 0\)"):
        Solution.from_steps(**dict(f, poses=bad))
    with pytest.raises(bs.InputError, match=r"from_steps \(step 0\): poses must have shape \(5, 4, 4\)"):
        Solution.from_steps(**dict(f, poses=sol.poses[:, :3]))


def test_an_arc_length_path_may_go_back_in_time(solved, tmp_path):
    """Steps along an equilibrium path (``resume["path"] == "arc-length"``) may decrease ``t``
    past a limit point; they stay finite, and the order survives save/load."""
    _, _, sol = solved
    new = empty_like(sol)
    assert new.path == "load"
    new.append(*step_args(sol, 0))
    new.resume = dict(path="arc-length", t0=0.0, t_end=1.0)
    args = list(step_args(sol, 1))
    for t in (0.5, 0.75, 0.25, 0.25 + 1e-3):
        args[0] = t
        new.append(*args)
    args[0] = np.nan
    with pytest.raises(bs.InputError, match=r"times must be finite numbers, got t = nan"):
        new.append(*args)
    back = bs.load(new.save(tmp_path / "arc"))
    assert back.path == "arc-length" and back.times.tolist() == [0.0, 0.5, 0.75, 0.25, 0.25 + 1e-3]
    with pytest.raises(bs.InputError, match=r"times must increase, got t = 0\.25 after 0\.75"):
        Solution.from_steps(new.description, new.times, new.poses, new.reactions, new.section_forces,
                            new.strains)                                   # without its resume: load path


def test_step_and_node_arguments_are_checked(solved):
    _, _, sol = solved
    for bad in (3, -4, 1.5, True):
        with pytest.raises(bs.InputError, match=rf"step {bad!r} out of range \(the solution has steps 0..2\)"):
            sol.position(0, bad)
    with pytest.raises(bs.InputError, match=r"unknown node id 9"):
        sol.reaction(9)


# ------------------------------------------------------------------ cheap appending, views
def test_fields_are_read_only_views_and_appending_reallocates_rarely(solved):
    _, _, sol = solved
    with pytest.raises(ValueError):
        sol.poses[0, 0, 0, 3] = 1.0
    with pytest.raises(AttributeError):
        sol.times = np.zeros(3)
    assert np.shares_memory(sol.poses, sol.poses) and np.shares_memory(sol.step(1).poses, sol.poses)
    new = empty_like(sol)
    args = list(step_args(sol, 0))
    buffers = set()
    for k in range(1000):
        args[0] = float(k)
        new.append(*args)
        buffers.add(new.poses.__array_interface__["data"][0])
    assert len(new) == 1000 and len(buffers) <= 10        # capacity doubles: log2(1000) copies, not 1000
    np.testing.assert_array_equal(new.times, np.arange(1000.0))


def test_steps_written_without_reads_read_back_in_order(solved):
    """Steps go to chunks (none copied while appending); the first read joins them in order, and a
    view taken earlier keeps its values after later appends."""
    _, _, sol = solved
    new = empty_like(sol)
    t, H, R, S, E, st = step_args(sol, 0)
    early = None
    for k in range(70):
        HK = H.copy()
        HK[:, :3, 3] += k
        new.append(float(k), HK, R + k, S - k, E, dict(st, k=k))
        if k == 5:
            early = new.poses
    assert np.array_equal(new.times, np.arange(70.0)) and [s["k"] for s in new.stats] == list(range(70))
    np.testing.assert_array_equal(new.poses[:, :, :3, 3] - H[:, :3, 3], np.arange(70.0)[:, None, None]
                                  * np.ones((70, 5, 3)))
    np.testing.assert_array_equal(new.reactions[:, 0, 0], np.arange(70.0) + R[0, 0])
    np.testing.assert_array_equal(new.section_forces[:, 1, 2], S[1, 2] - np.arange(70.0))
    assert early.shape[0] == 6 and np.array_equal(early, new.poses[:6])
    copy = new.copy_steps()
    copy.append(70.0, H, R, S, E, st)
    assert len(copy) == 71 and len(new) == 70 and np.array_equal(copy.poses[:70], new.poses)


def test_step_record_and_extra(solved):
    _, _, sol = solved
    new = empty_like(sol)
    new.append(*step_args(sol, 0))
    new.append(*step_args(sol, 1), extra=dict(mode=np.ones((5, 6)), load_factor=0.5))
    new.append(*step_args(sol, 2), extra=dict(load_factor=1.0))
    assert set(new.extra) == {"mode", "load_factor"} and new.extra["load_factor"] == [None, 0.5, 1.0]
    assert new.extra["mode"][0] is None and new.extra["mode"][2] is None and new.extra["mode"][1].shape == (5, 6)
    rec = new.step(1)
    assert isinstance(rec, Step) and rec.index == 1 and rec.time == sol.times[1]
    assert set(rec.extra) == {"mode", "load_factor"} and set(new.step(-1).extra) == {"load_factor"}
    np.testing.assert_array_equal(rec.section_forces, sol.section_forces[1])


# ------------------------------------------------------------------ save / load
def with_everything(sol):
    """A copy of ``sol`` with contact tables, extras of every kind and a failure message."""
    new = empty_like(sol)
    tables = [{}, dict(gap=np.array([1e-3, -2e-4]), position=np.arange(6.0).reshape(2, 3),
                       stick=np.array([True, False])), dict(gap=np.zeros(0), position=np.zeros((0, 3)))]
    extras = [dict(stable=True, branch="main"), dict(mode=np.arange(30.0).reshape(5, 6), n_neg=np.int64(1)),
              dict(mode=np.zeros((0, 6)), arc=0.125)]
    for k in range(3):
        new.append(*step_args(sol, k), contact=tables[k], extra=extras[k])
    new.converged, new.message = False, "stopped: a test"
    new.resume = dict(sol.resume)
    new.contact_state = dict(lam=np.array([0.5, 1.5]))
    return new


def assert_all_fields_equal(a, b):
    for name in ("times", "poses", "reactions", "section_forces", "strains"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and np.array_equal(x, y), name
    assert a.stats == b.stats and a.resume == b.resume
    assert a.converged == b.converged and a.message == b.message
    for ta, tb in zip(a.contacts, b.contacts, strict=True):
        assert ta.keys() == tb.keys() and all(np.array_equal(ta[k], tb[k]) and ta[k].dtype == tb[k].dtype
                                              for k in ta)
    assert a.extra.keys() == b.extra.keys()
    for name in a.extra:
        for va, vb in zip(a.extra[name], b.extra[name], strict=True):
            assert (va is None and vb is None) or (np.array_equal(va, vb) and np.shape(va) == np.shape(vb)
                                                    and type(va) is type(vb)), (name, va, vb)
    assert a.contact_state.keys() == b.contact_state.keys()
    assert all(np.array_equal(a.contact_state[k], b.contact_state[k]) for k in a.contact_state)
    for k, v in a.description.items():
        assert np.array_equal(v, b.description[k]), k


def test_save_load_round_trips_every_public_field(solved, tmp_path):
    _, _, sol = solved
    full = with_everything(sol)
    back = bs.load(full.save(tmp_path / "full"))
    assert_all_fields_equal(full, back)
    assert back.extra["arc"] == [None, None, 0.125] and isinstance(back.extra["stable"][0], bool)
    assert back.extra["mode"][2].shape == (0, 6)
    assert_all_fields_equal(back, bs.load(back.save(tmp_path / "again")))


def write_version_1(sol, path):
    """An archive laid out as format version 1 (beamsolver 0.1.0, before ``extra``), key by key."""
    import json
    arrays = {"format": np.array("beamsolver-solution"), "format_version": np.int64(1),
              "beamsolver_version": np.array("0.1.0"), "times": np.array(sol.times),
              "poses": np.array(sol.poses), "reactions": np.array(sol.reactions),
              "section_forces": np.array(sol.section_forces), "strains": np.array(sol.strains),
              "stats": np.array(json.dumps(sol.stats)), "converged": np.bool_(True), "message": np.array(""),
              "resume": np.array(json.dumps(sol.resume)),
              "contact/gap": np.array([1e-3, 2e-3, 3e-3]), "contact_count/gap": np.array([-1, 1, 2]),
              "contact_state/lam": np.array([0.25])}
    arrays.update({f"model/{k}": np.asarray(v) for k, v in sol.description.items()})
    np.savez_compressed(path, **arrays)


def test_a_version_1_archive_still_loads(solved, tmp_path):
    m, b, sol = solved
    write_version_1(sol, tmp_path / "old.npz")
    old = bs.load(tmp_path / "old.npz")
    for name in ("times", "poses", "reactions", "section_forces", "strains"):
        np.testing.assert_array_equal(getattr(old, name), getattr(sol, name))
    assert old.stats == sol.stats and old.extra == {} and old.converged
    assert [c.get("gap", np.zeros(0)).tolist() for c in old.contacts] == [[], [1e-3], [2e-3, 3e-3]]
    assert old.contacts[0] == {} and old.contact_state["lam"].tolist() == [0.25]
    np.testing.assert_array_equal(old.position(b.last), sol.position(b.last))


def test_a_damaged_extra_is_named(solved, tmp_path):
    _, _, sol = solved
    path = with_everything(sol).save(tmp_path / "x")
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["extra_shape/mode"] = arrays["extra_shape/mode"][:2]
    np.savez_compressed(path, **arrays)
    with pytest.raises(bs.InputError, match=r"damaged beamsolver result: 'extra_shape/mode' must be an integer "
                                            r"table with one row per step \(3 steps\)"):
        bs.load(path)


def test_a_file_with_times_out_of_order_is_damaged(solved, tmp_path):
    _, _, sol = solved
    path = sol.save(tmp_path / "x")
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["times"] = arrays["times"][::-1].copy()
    np.savez_compressed(path, **arrays)
    with pytest.raises(bs.InputError, match=r"x\.npz'\): damaged beamsolver result: .*times must increase"):
        bs.load(path)


# ------------------------------------------------------------------ consumers on a public-API solution
def public_solution(model, sol):
    """A ``Solution`` made only through public names: ``describe_model`` and ``from_steps``."""
    return Solution.from_steps(describe_model(model), sol.times, sol.poses, sol.reactions, sol.section_forces,
                               sol.strains, stats=[dict(s) for s in sol.stats], resume=dict(sol.resume))


def test_consumers_use_only_public_fields(solved, tmp_path):
    m, b, sol = solved
    pub = public_solution(m, sol)
    pvd = bs.io.write_vtk(pub, tmp_path / "vtk")
    assert pvd.exists() and len(list((tmp_path / "vtk").glob("beams_*.vtu"))) == 3
    lin = bs.linearize(m, pub, step=1)
    ref = bs.linearize(m, sol, step=1)
    assert lin.t == ref.t and abs(lin.K - ref.K).max() == 0.0
    more = bs.solve(m, steps=4, t_end=2.0, restart=pub)               # restart from it
    assert more.times[-1] == 2.0 and np.array_equal(more.poses[:3], sol.poses)
    pytest.importorskip("matplotlib")
    from beamsolver import viz
    fig = viz.plot_history(pub, "reaction", node=b.first, component="fy")
    np.testing.assert_array_equal(fig.axes[0].lines[0].get_ydata(), sol.reactions[:, b.first, 1])
    if importlib.util.find_spec("pyvista") is not None:
        img = viz.render(pub, step=[0, -1], window_size=(64, 48))
        assert img.shape == (48, 64, 3) and np.array_equal(img, viz.render(sol, step=[0, -1], window_size=(64, 48)))
    pub.save(tmp_path / "pub")
    out = subprocess.run([sys.executable, "-m", "beamsolver.app.cli", "info", str(tmp_path / "pub.npz")],
                         capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert out.returncode == 0 and "2 steps to t = 1," in out.stdout, out.stderr


# ------------------------------------------------------------------ nobody reaches inside
def private_names():
    sol = Solution(None, None, {"poses0": np.zeros((0, 4, 4)), "enodes": np.zeros((0, 2))})
    names = {k for k in list(vars(Solution)) + list(vars(sol)) if k.startswith("_") and not k.startswith("__")}
    return names | {"_times", "_poses", "_reactions", "_sigma", "_strain"}     # the old private lists


def test_no_module_outside_results_touches_private_attributes():
    names = private_names()
    assert {"_arrays", "_n", "_stats", "_append"} <= names
    pattern = re.compile(r"\b(?!self\b|cls\b)[A-Za-z_]\w*\s*\.\s*(" + "|".join(sorted(names)) + r")\b"
                         r"|[\"'](" + "|".join(sorted(names)) + r")[\"']")
    hits = []
    for folder in ("beamsolver", "benchmarks", "examples"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            if path == ROOT / "beamsolver" / "results" / "solution.py":
                continue
            for i, line in enumerate(path.read_text().splitlines(), 1):
                if pattern.search(line):
                    hits.append(f"{path.relative_to(ROOT)}:{i}: {line.strip()}")
    assert hits == []


def test_the_private_attribute_check_finds_what_it_must():
    """The check itself: the reads that were there before this change are found."""
    names = private_names()
    pattern = re.compile(r"\b(?!self\b|cls\b)[A-Za-z_]\w*\s*\.\s*(" + "|".join(sorted(names)) + r")\b"
                         r"|[\"'](" + "|".join(sorted(names)) + r")[\"']")
    assert pattern.search("t = sol._times[-1]") and pattern.search('hasattr(restart, "_times")')
    assert pattern.search("solution._arrays['poses']") and not pattern.search("self._poses.append(P)")
