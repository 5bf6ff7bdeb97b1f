"""One Newton loop (issue 25 item 2): ``nonlinear.newton.Newton.iterate`` under a pluggable constraint
serves load and arc-length stepping; the verdict is an enum; one factorise wrapper."""
import ast
from pathlib import Path

import numpy as np
import pytest

import beamsolver as bs
from beamsolver import failures
from beamsolver.nonlinear import linsolve
from beamsolver.nonlinear.convergence import Convergence, Verdict
from beamsolver.nonlinear.newton import Newton

PACKAGE = Path(__file__).resolve().parents[2] / "beamsolver"


def _calls(attr):
    """``(module, line)`` of every call ``x.attr(...)`` in the package (read with ``ast``)."""
    out = []
    for p in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == attr:
                out.append((p.relative_to(PACKAGE).as_posix(), node.lineno))
    return out


@pytest.mark.slow
def test_only_the_newton_loop_decides_and_only_the_wrapper_factorises():
    """A second Newton loop would call ``Convergence.decide``; a second factorise wrapper would call a
    back-end's ``factorize`` and catch ``SingularMatrixError`` itself."""
    assert [m for m, _ in _calls("decide")] == ["nonlinear/newton.py"]
    assert {m for m, _ in _calls("factorize")} == {"nonlinear/linsolve.py"}
    for p in PACKAGE.rglob("*.py"):
        if p.name != "linsolve.py":
            assert "SingularMatrixError" not in p.read_text(), p


def test_the_verdict_is_an_enum():
    c = Convergence(max_iter=3)
    assert c.decide(1e-9, np.inf, 1) is Verdict.CONVERGED
    assert c.decide(1.0, np.inf, 3) is Verdict.MAX_ITER and c.decide(1.0, np.inf, 1) is Verdict.CONTINUE
    assert c.decide(1e13, np.inf, 1) is Verdict.DIVERGED and not isinstance(Verdict.CONVERGED, str)


def test_factorize_tangent_gives_the_typed_failure():
    import scipy.sparse as sp
    with pytest.raises(failures.SingularTangent, match="my label"):
        linsolve.factorize_tangent(sp.csc_matrix(np.zeros((2, 2))), what="my label")
    lu = linsolve.factorize_tangent(sp.csc_matrix(np.diag([2.0, -4.0])))
    np.testing.assert_array_equal(lu.solve(np.array([2.0, 4.0])), [1.0, -1.0])
    assert lu.det_sign() < 0            # the back-end's determinant sign passes through


def _column():
    sec = bs.Section.circular(radius=0.01, E=2e11)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (0, 0, 1), 6), sec)
    m.clamp(b.first)
    m.add_load(b.last, force=(2.0 * sec.C[4, 4], 0, 0))
    return m


@pytest.mark.parametrize("path", ["load", "arc-length"])
def test_both_steppers_run_through_iterate(path, monkeypatch):
    """Every Newton iteration of either stepper is one of ``Newton.iterate``: its constraint is
    ``FixedTime`` under load control and the arc-length ``Sphere`` otherwise (also for the last step,
    ``t`` held at ``t_end``), and the iterations it counts are the solution's."""
    seen = []
    original = Newton.iterate

    def spy(self, H, t, constraint):
        out = original(self, H, t, constraint)
        seen.append((type(constraint).__name__, out[3]["iterations"]))
        return out
    monkeypatch.setattr(Newton, "iterate", spy)
    sol = bs.solve(_column(), steps=4, path=path, verbose=False)
    kinds = {k for k, _ in seen}
    assert kinds == ({"FixedTime"} if path == "load" else {"Sphere"})
    assert sum(n for _, n in seen) == int(sum(s["iterations"] for s in sol.stats))
    assert len(seen) >= 4
