"""Bad input raises ``InputError`` (a ``ValueError``) with a message naming the object and value."""
import warnings

import numpy as np
import pytest

import beamsolver as bs
from beamsolver import InputError, geometry


def _sec(**kw):
    args = dict(EA=1e3, GA2=4e2, GA3=4e2, GJ=10.0, EI2=20.0, EI3=20.0, radius=0.05)
    args.update(kw)
    return bs.Section(**args)


def _model(n=3):
    m = bs.Model()
    b = m.add_beam(geometry.straight((0, 0, 0), (1, 0, 0), n), _sec())
    return m, b


def test_input_error_is_value_error():
    assert issubclass(InputError, ValueError)


@pytest.mark.parametrize("key,value", [("radius", -0.1), ("radius", 0.0), ("EA", -5.0), ("GJ", 0.0),
                                       ("EI3", float("nan")), ("GA2", float("inf"))])
def test_section_rejects_non_positive(key, value):
    with pytest.raises(InputError, match=rf"Section: {key} must be positive.*{value!r}"):
        _sec(**{key: value})


def test_section_names_itself_and_checks_matrix():
    with pytest.raises(InputError, match=r"Section 'wire'.*EI2.*-1"):
        _sec(EI2=-1.0, name="wire")
    C = np.eye(6)
    C[0, 1] = 0.5
    with pytest.raises(InputError, match="symmetric"):
        bs.Section.from_matrix(C, radius=0.1)
    with pytest.raises(InputError, match="positive definite"):
        bs.Section.from_matrix(np.diag([1, 1, 1, 1, 1, -1.0]), radius=0.1)
    with pytest.raises(InputError, match=r"radius must be positive.*-0\.2"):
        bs.Section.from_matrix(np.eye(6), radius=-0.2)
    with pytest.raises(InputError, match=r"nu must lie in \(-1, 0.5\), got 0.7"):
        bs.Section.circular(radius=0.1, E=1e9, nu=0.7)


def test_nan_coordinates():
    P = geometry.straight((0, 0, 0), (1, 0, 0), 3)
    P[2, 1, 3] = np.nan
    with pytest.raises(InputError, match=r"Beam 0 'cable': node 2 has non-finite coordinates"):
        bs.Model().add_beam(P, _sec(), name="cable")
    with pytest.raises(InputError, match=r"polyline: point 1 is not finite"):
        geometry.polyline([[0, 0, 0], [np.inf, 0, 0], [2, 0, 0]])
    with pytest.raises(InputError, match=r"add_load\(3\): force must be 3 finite numbers"):
        _model()[0].add_load(3, force=(0, np.nan, 0))


def test_zero_length_element():
    P = geometry.straight((0, 0, 0), (1, 0, 0), 3)
    P[2] = P[1]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)   # 0/0 in the strain of the bad element
        with pytest.raises(InputError, match=r"Beam 0: element 1 has zero length \(nodes 1 and 2 coincide"):
            bs.Model().add_beam(P, _sec())
    with pytest.raises(InputError, match="start and end coincide"):
        geometry.straight((1, 2, 3), (1, 2, 3), 2)
    with pytest.raises(InputError, match="points 1 and 2 coincide"):
        geometry.polyline([[0, 0, 0], [1, 0, 0], [1, 0, 0]])


def test_non_orthonormal_pose():
    P = geometry.straight((0, 0, 0), (1, 0, 0), 3)
    P[1, :3, :3] *= 1.001
    with pytest.raises(InputError, match=r"Beam 0: pose of node 1 is not a rotation \(\|R\^T R - I\| = 0.002"):
        bs.Model().add_beam(P, _sec())
    P = geometry.straight((0, 0, 0), (1, 0, 0), 3)
    P[3, :3, 2] *= -1.0      # a reflection
    with pytest.raises(InputError, match=r"pose of node 3 is not a rotation.*det = -1"):
        bs.Model().add_beam(P, _sec())


def test_element_turning_too_far_in_reference():
    P = geometry.arc(radius=1.0, angle=3.0, n_elements=2)[::2]   # one element of 3 rad (geometry.arc refuses it)
    with pytest.raises(InputError, match=r"Beam 0: element 0 turns by 3.000 rad .*limit 2.356.*more elements"):
        bs.Model().add_beam(P, _sec())
    bs.Model().add_beam(geometry.arc(radius=1.0, angle=3.0, n_elements=2), _sec())   # 1.5 rad each: fine


def test_unconstrained_model():
    m, b = _model()
    with pytest.raises(InputError, match=r"beam\(s\) \[0\]: 6 rigid-body mode\(s\) are not constrained"):
        bs.solve(m, steps=1)
    m.fix(b.first, ("ux", "uy", "uz"))
    with pytest.raises(InputError, match=r"3 rigid-body mode\(s\) are not constrained"):
        bs.solve(m, steps=1)
    m2, b2 = _model()
    m2.fix(b2.first, ("ux", "uy", "uz"))
    m2.fix(b2.last, ("uy", "uz"))
    with pytest.raises(InputError, match=r"1 rigid-body mode\(s\) are not constrained"):   # twist about x
        bs.solve(m2, steps=1)


def test_contact_of_a_beam_with_itself():
    m, b = _model()
    with pytest.raises(InputError, match="beam 0 is declared in contact with itself"):
        m.add_contact(b, b)
    b2 = m.add_beam(geometry.straight((0, 1, 0), (1, 1, 0), 2), _sec())
    with pytest.raises(InputError, match="beam 1 is declared in contact with itself"):
        m.add_contact([b, b2], b2)


@pytest.mark.parametrize("call", ["clamp", "fix", "load", "join", "prescribe"])
def test_unknown_node_ids(call):
    m, b = _model()     # nodes 0..3
    with pytest.raises(InputError, match=r"unknown node id 17 \(the model has nodes 0\.\.3\)"):
        {"clamp": lambda: m.clamp(17),
         "fix": lambda: m.fix(17, ("ux",)),
         "load": lambda: m.add_load(17, force=(1, 0, 0)),
         "join": lambda: m.join(0, 17),
         "prescribe": lambda: m.prescribe(17, lambda t: np.eye(4))}[call]()
    with pytest.raises(InputError, match=r"unknown node id -1"):
        m.clamp(-1)
    with pytest.raises(InputError, match=r"expected a node id, got Beam 0"):
        m.clamp(b)


def test_bad_dof_names_in_fix():
    m, b = _model()
    with pytest.raises(InputError, match=r"fix\(0\): unknown dofs \['uq'\]"):
        m.fix(0, ("ux", "uq"))
    with pytest.raises(InputError, match=r"fix\(0\): unknown dofs \['x'\]"):
        m.fix(0, "x")
    with pytest.raises(InputError, match=r"fix\(0\): unknown dofs \(\)"):
        m.fix(0, ())


@pytest.mark.parametrize("steps", [0, -3, 2.5])
def test_solve_bad_steps(steps):
    m, b = _model()
    m.clamp(b.first)
    with pytest.raises(InputError, match=rf"solve: steps must be a positive integer, got {steps!r}"):
        bs.solve(m, steps=steps)


def test_solve_bad_time_interval():
    m, b = _model()
    m.clamp(b.first)
    with pytest.raises(InputError, match=r"need t_end > t_start"):
        bs.solve(m, t_end=0.0)
