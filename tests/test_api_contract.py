"""The public API contract (DESIGN.md section 3): names, parameter names and defaults users rely on.

A rename, a removed argument or a changed default fails here.  New optional
arguments may be added (after the listed ones); the listed prefix must stay.
"""
import inspect

import numpy as np
import pytest

import beamsolver as bs

EMPTY = inspect.Parameter.empty

# callable -> leading parameters (name, default or EMPTY), self omitted
CONTRACT = {
    "Section": [("EA", EMPTY), ("GA2", EMPTY), ("GA3", EMPTY), ("GJ", EMPTY), ("EI2", EMPTY), ("EI3", EMPTY),
                ("radius", EMPTY)],
    "Section.circular": [("radius", EMPTY), ("E", EMPTY), ("nu", 0.3)],
    "geometry.straight": [("start", (0.0, 0.0, 0.0)), ("end", (1.0, 0.0, 0.0)), ("n_elements", 10)],
    "geometry.arc": [("radius", EMPTY), ("angle", EMPTY), ("n_elements", EMPTY)],
    "geometry.helix": [("radius", EMPTY), ("pitch", EMPTY), ("length", EMPTY), ("n_elements", EMPTY),
                       ("phase", 0.0)],
    "geometry.polyline": [("points", EMPTY), ("n_elements", None)],
    "Model": [],
    "Model.add_beam": [("poses", EMPTY), ("section", EMPTY), ("name", None), ("element", None)],
    "elements.get": [("spec", None)],
    "Model.clamp": [("node", EMPTY)],
    "Model.fix": [("node", EMPTY), ("dofs", ("ux", "uy", "uz", "rx", "ry", "rz"))],
    "Model.prescribe": [("node", EMPTY), ("motion", EMPTY)],
    "Model.join": [("node_a", EMPTY), ("node_b", EMPTY)],
    "Model.add_load": [("node", EMPTY), ("force", None), ("moment", None), ("follower", False), ("scale", ...)],
    "Model.add_contact": [("slave", EMPTY), ("master", EMPTY), ("mu", 0.0)],
    "solve": [("model", EMPTY), ("steps", 20), ("t_end", 1.0), ("output", None)],
    "Solution.position": [("node", EMPTY), ("step", -1)],
    "Solution.reaction": [("node", EMPTY), ("step", -1)],
    "Solution.contact": [("step", -1)],
    "Solution.save": [("path", EMPTY)],
    "Solution.step": [("k", -1)],
    "Solution.append": [("t", EMPTY), ("H", EMPTY), ("reactions", EMPTY), ("sigma", EMPTY), ("strain", EMPTY),
                        ("stats", EMPTY), ("contact", None), ("extra", None)],
    "Solution.from_steps": [("description", EMPTY), ("times", EMPTY), ("poses", EMPTY), ("reactions", EMPTY),
                            ("section_forces", EMPTY), ("strains", EMPTY)],
    "load": [("path", EMPTY)],
    "linearize": [("model", EMPTY), ("solution", EMPTY), ("step", -1)],
    "se3.exp": [("h", EMPTY)],
    "se3.log": [("H", EMPTY)],
    "se3.tangent": [("h", EMPTY)],
    "se3.tangent_inv": [("h", EMPTY)],
    "contact.slip_increment": [("H_LK_prev", EMPTY), ("H_LK", EMPTY)],
    "motion.rotation": [("axis", EMPTY), ("angle_of_t", EMPTY), ("center", (0.0, 0.0, 0.0))],
    "motion.translation": [("vector_of_t", EMPTY)],
}
KEYWORD_ONLY_SOLVE = ("t_start", "rtol", "dtol", "max_iter", "line_search", "min_step_ratio", "callback",
                      "check_rigid_modes", "verbose", "initial_poses", "restart", "checkpoint", "linear_solver")


def _get(path):
    obj = bs
    for part in path.split("."):
        obj = getattr(obj, part)
    return obj


@pytest.mark.parametrize("path", sorted(CONTRACT))
def test_signature(path):
    params = [p for p in inspect.signature(_get(path)).parameters.values() if p.name != "self"]
    expected = CONTRACT[path]
    assert [p.name for p in params[:len(expected)]] == [name for name, _ in expected]
    for p, (name, default) in zip(params, expected):
        if default is not ...:
            assert p.default == default, (path, name, p.default)
    for p in params[len(expected):]:                 # anything added later must be optional
        assert p.default is not EMPTY or p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD), (path, p.name)


def test_solve_options_are_keyword_only():
    params = inspect.signature(bs.solve).parameters
    for name in KEYWORD_ONLY_SOLVE:
        assert params[name].kind is inspect.Parameter.KEYWORD_ONLY, name


def test_top_level_names_and_errors():
    for name in ("Model", "Beam", "Section", "Solution", "solve", "Convergence", "InputError", "ConvergenceError",
                 "load", "linearize", "Linearization", "se3", "geometry", "motion", "contact", "__version__"):
        assert hasattr(bs, name), name
    assert issubclass(bs.InputError, ValueError)
    assert issubclass(bs.ConvergenceError, Exception)


def test_solution_and_beam_data_model():
    """``Beam.nodes/first/last``; ``Solution.times, poses, stats`` with the documented shapes."""
    m = bs.Model()
    beam = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), 3), bs.Section.circular(radius=0.01, E=1e9))
    assert beam.nodes.dtype.kind == "i" and beam.first == beam.nodes[0] and beam.last == beam.nodes[-1]
    m.clamp(beam.first)
    m.add_load(beam.last, force=(0, 0, -1.0))
    sol = bs.solve(m, steps=2, verbose=False)
    assert sol.times.shape == (3,) and sol.poses.shape == (3, 4, 4, 4)
    assert sol.position(beam.last).shape == (3,) and sol.reaction(beam.first).shape == (6,)
    assert len(sol.stats) == 3 and "iterations" in sol.stats[-1]
    np.testing.assert_allclose(sol.reaction(beam.first)[:3], (0, 0, 1.0), atol=1e-9)


def test_se3_public_kernels():
    """The SE(3) kernels of one home (``se3``), public and batched."""
    for name in ("exp", "log", "tangent", "tangent_inv", "adjoint", "inverse", "compose", "relative", "interpolate",
                 "log_relative", "log_and_tangent_inv", "coefficient", "coefficients", "cross", "dot", "SERIES",
                 "SWITCH"):
        assert name in bs.se3.__all__ and hasattr(bs.se3, name), name
    h = np.array([[0.1, -0.2, 0.3, 0.4, -0.5, 0.6]] * 2)
    H = bs.se3.exp(h)
    h2, Tp, Tm = bs.se3.log_and_tangent_inv(H)
    np.testing.assert_allclose(h2, h, atol=1e-14)
    np.testing.assert_allclose(Tp, bs.se3.tangent_inv(h), atol=1e-14)
    np.testing.assert_allclose(Tm, bs.se3.tangent_inv(-h), atol=1e-14)
    np.testing.assert_allclose(bs.se3.log_relative(H[:1], H[1:]), 0.0, atol=1e-15)
