"""Small defects found in review: each bad input gives an ``InputError`` naming the object and the value.

``bs.motion.rotation`` / ``translation`` with bad arguments, sections whose stiffness
overflows, and ``beamsolver render -o`` into a folder that does not exist yet.
"""
import subprocess
import sys
import warnings

import numpy as np
import pytest

import beamsolver as bs
from helpers import placed_crossing


# ------------------------------------------------------------------ motions
@pytest.mark.parametrize("args, match", [
    (((0, 0, 0), 1.0), r"motion\.rotation: axis must be a non-zero vector, got \(0, 0, 0\)"),
    (((0, np.nan, 1), 1.0), r"motion\.rotation: axis must be 3 finite numbers, got \(0, nan, 1\)"),
    (((0, 0, 1, 2), 1.0), r"motion\.rotation: axis must be 3 finite numbers, got \(0, 0, 1, 2\)"),
    (("z", 1.0), r"motion\.rotation: axis must be 3 finite numbers, got 'z'"),
    (((0, 0, 1), "a"), r"motion\.rotation: angle_of_t must be a callable t -> angle or a finite number "
                       r"\(angle \* t\), got 'a'"),
    (((0, 0, 1), np.nan), r"motion\.rotation: angle_of_t must be .* got nan"),
    (((0, 0, 1), 1.0, (1, 2)), r"motion\.rotation: center must be 3 finite numbers, got \(1, 2\)"),
    (((0, 0, 1), 1.0, (1, 2, np.inf)), r"motion\.rotation: center must be 3 finite numbers, got \(1, 2, inf\)"),
])
def test_rotation_arguments(args, match):
    with pytest.raises(bs.InputError, match=match):
        bs.motion.rotation(*args)


@pytest.mark.parametrize("value, match", [
    ((1, 2), r"motion\.translation: vector_of_t must be a callable t -> vector or 3 finite numbers "
             r"\(vector \* t\), got \(1, 2\)"),
    ("abc", r"motion\.translation: vector_of_t must be .* got 'abc'"),
    ((1, np.inf, 0), r"motion\.translation: vector_of_t must be .* got \(1, inf, 0\)"),
])
def test_translation_arguments(value, match):
    with pytest.raises(bs.InputError, match=match):
        bs.motion.translation(value)


def test_callables_returning_bad_values_are_named():
    with pytest.raises(bs.InputError, match=r"motion\.rotation: angle_of_t\(0\.5\) must be a finite number, "
                                            r"got 'x'"):
        bs.motion.rotation((0, 0, 1), lambda t: "x")(0.5)
    with pytest.raises(bs.InputError, match=r"motion\.rotation: angle_of_t\(0\.5\) must be a finite number, got nan"):
        bs.motion.rotation((0, 0, 1), lambda t: np.nan)(0.5)
    with pytest.raises(bs.InputError, match=r"motion\.translation: vector_of_t\(0\.5\) must be 3 finite numbers, "
                                            r"got \(1, 2\)"):
        bs.motion.translation(lambda t: (1, 2))(0.5)


def test_good_motions_are_unchanged():
    G = bs.motion.rotation((0, 0, 2.0), 0.5 * np.pi, center=(1.0, 0.0, 0.0))(1.0)
    np.testing.assert_allclose(G[:3, :3], [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)
    np.testing.assert_allclose(G[:3, 3], [1.0, -1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(bs.motion.translation([1, 2, 3])(0.5)[:3, 3], [0.5, 1.0, 1.5])
    np.testing.assert_allclose(bs.motion.rotation([0, 0, 1], lambda t: np.float32(t))(0.25)[:3, :3],
                               bs.motion.rotation([0, 0, 1], 1.0)(0.25)[:3, :3], atol=1e-7)


def test_a_bad_motion_is_named_when_the_model_is_solved():
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 2), sec)
    m.clamp(b.first)
    with pytest.raises(bs.InputError, match=r"vector_of_t\(0\) must be 3 finite numbers, got \(0, 0\)"):
        m.prescribe(b.last, bs.motion.translation(lambda t: (t, 0)))       # checked at t = 0 here
    m.prescribe(b.last, bs.motion.translation(lambda t: (t, 0, 0) if t < 0.5 else (t, 0)))
    with pytest.raises(bs.InputError, match=r"vector_of_t\(([\d.]+)\) must be 3 finite numbers, got \(\1, 0\)"):
        bs.solve(m, steps=1)


# ------------------------------------------------------------------ sections
@pytest.mark.parametrize("make, match", [
    (lambda: bs.Section.rectangular(1e300, 1e-3, E=2e11),
     r"Section\.rectangular: width=1e\+300, height=0\.001, E=2e\+11 give a stiffness that is not a finite "
     r"positive number \((EA|.*EI3) = inf"),
    (lambda: bs.Section.rectangular(1e-3, 1e300, E=2e11), r"Section\.rectangular: width=0\.001, height=1e\+300"),
    (lambda: bs.Section.rectangular(1e100, 1e100, E=2e11), r"Section\.rectangular: .* = inf"),
    (lambda: bs.Section.rectangular(1e-120, 1e-120, E=2e11), r"Section\.rectangular: .* = 0"),
    (lambda: bs.Section.circular(1e300, E=2e11), r"Section\.circular: radius=1e\+300, E=2e\+11 give .* = inf"),
    (lambda: bs.Section.circular(1e100, E=2e11), r"Section\.circular: .* = inf"),
    (lambda: bs.Section.circular(1e3, E=1e308), r"Section\.circular: radius=1000, E=1e\+308 give .*EA = inf"),
    (lambda: bs.Section(EA=1e308 * 10, GA2=1, GA3=1, GJ=1, EI2=1, EI3=1, radius=1),
     r"Section: EA must be positive, got inf"),
])
def test_section_stiffness_overflow(make, match):
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # no RuntimeWarning on the way either
        with pytest.raises(bs.InputError, match=match):
            make()


def test_large_but_finite_sections_still_work():
    s = bs.Section.rectangular(2e-3, 1e-3, E=2e11)
    assert np.all(np.isfinite(s.C)) and s.radius == 0.5e-3
    np.testing.assert_allclose(s.C[4, 4], 2e11 * 2e-3 * 1e-9 / 12.0)
    assert np.isfinite(bs.Section.circular(1e30, E=1e10).C).all()


# ------------------------------------------------------------------ render into a new folder
@pytest.mark.slow
def test_render_creates_the_output_folder(tmp_path):
    pytest.importorskip("pyvista")
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 2), sec)
    m.clamp(b.first)
    bs.solve(m, steps=1).save(tmp_path / "r.npz")
    target = tmp_path / "missing" / "deeper" / "x.png"
    out = subprocess.run([sys.executable, "-m", "beamsolver.app.cli", "render", str(tmp_path / "r.npz"), "-o",
                          str(target), "--size", "64", "48"], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_render_into_a_file_as_folder_names_it(tmp_path):
    pytest.importorskip("pyvista")
    from beamsolver import viz
    (tmp_path / "afile").write_text("x")
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 2), sec)
    m.clamp(b.first)
    sol = bs.solve(m, steps=1)
    with pytest.raises(bs.InputError, match=r"render: cannot create the folder of path '.*afile/x\.png' \("):
        viz.render(sol, path=tmp_path / "afile" / "x.png", window_size=(64, 48))


# ------------------------------------------------------------------ packaging
def test_pyproject_license_and_extras():
    """SPDX license string (no setuptools deprecation warning on install; needs setuptools >= 77)
    and bokeh in ``[distributed]`` (the dashboard every sweep prints the address of)."""
    tomllib = pytest.importorskip("tomllib")
    from pathlib import Path
    meta = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())
    assert meta["project"]["license"] == "MIT"
    assert "setuptools>=77" in meta["build-system"]["requires"]
    assert any(r.replace(" ", "").startswith("bokeh>=3.1") for r in meta["project"]["optional-dependencies"]
               ["distributed"])


# ------------------------------------------------------------------ contact projection
def test_projection_branches_not_taken_never_overflow():
    """Two crossing beams in small units, rotated by a rotation vector of 1e-300 (the case
    hypothesis found in tests/test_invariance_property.py): the LINE step of the crossing
    pairs divides by ``x2' . e1`` ~ 1e-303, a value ``where`` then throws away.  It must not
    warn (overflow), and the answer is that of the unrotated scene."""
    def crossing(G):
        sol, node, _ = placed_crossing(G, lam=0.01, steps=1, swap=True)
        return sol, node
    G = np.eye(4)
    G[:3, 3] = (0.0, 0.0, -1.0)
    ref, node = crossing(G)
    G[:3, :3] = bs.se3.exp_so3(np.array([1e-300, 0.0, 0.0]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol, _ = crossing(G)
    assert sol.contact()["normal_force"].sum() > 1.0
    np.testing.assert_allclose(sol.position(node), ref.position(node), rtol=0, atol=1e-12)
