"""Stability along the path, critical modes and branch switching (issue 15 items 1, 2).

References: the elastica (Timoshenko & Gere, Theory of Elastic Stability, 2nd ed., sec. 2.7):
a clamped-free column of length ``L`` under an axial tip load ``P`` beyond
``P_cr = pi^2 EI / (4 L^2)`` has, with ``k = sin(alpha / 2)`` (``alpha`` the tip rotation),

    sqrt(P / P_cr) = 2 K(k) / pi,   tip deflection f / L = 2 k / K(k),
    tip position along the axis x / L = 2 E(k) / K(k) - 1,

``K``, ``E`` the complete elliptic integrals of modulus ``k``.  A pinned-pinned column of
length ``L`` is two such columns of length ``L / 2`` (``P_cr = pi^2 EI / L^2``): midspan
deflection ``k / K(k) L``, end shortening ``delta / L = 2 - 2 E(k) / K(k)``, end rotation ``alpha``.
"""
import warnings

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

import beamsolver as bs
from beamsolver import bifurcation
from beamsolver.assembly import System
from beamsolver.definiteness import DENSE_MAX
from beamsolver.modes import lowest_modes

EI = 1.0


def _section(EA=1e6, EI3=EI):
    return bs.Section(EA=EA, GA2=EA, GA3=EA, GJ=1.0, EI2=EI, EI3=EI3, radius=0.01)


def _cantilever_column(ratio, n, EA=1e6, EI3=EI):
    """Clamped-free column, L = 1, tip load ``ratio`` P_cr along -x (straight, no imperfection)."""
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (1, 0, 0), n), _section(EA, EI3))
    m.clamp(b.first)
    m.add_load(b.last, force=(-ratio * np.pi**2 * EI / 4.0, 0.0, 0.0))
    return m, b


def elastica_k(ratio):
    """Modulus ``k = sin(alpha / 2)`` of the elastica at ``P / P_cr = ratio`` (> 1)."""
    return brentq(lambda k: 2.0 * ellipk(k * k) / np.pi - np.sqrt(ratio), 1e-12, 1.0 - 1e-15)


def elastica_tip(ratio):
    """Clamped-free column (L = 1): ``(x, f, alpha)`` of the tip at ``P / P_cr = ratio``."""
    k = elastica_k(ratio)
    K, E = ellipk(k * k), ellipe(k * k)
    return np.array([2.0 * E / K - 1.0, 2.0 * k / K, 2.0 * np.arcsin(k)])


def _tip(sol, node):
    x, R = sol.position(node), sol.rotation(node)
    return np.array([x[0], np.hypot(x[1], x[2]), np.arccos(np.clip(R[0, 0], -1.0, 1.0))])


# ------------------------------------------------------------------ the stability check itself
def test_slender_straight_column_beyond_euler_is_unstable_whatever_the_mesh():
    """A slender column (EA L^2 / EI = 1e8) at 2 P_cr on 32 elements: the scaled eigenvalue of the
    buckling mode is about -7e-11, which a fixed round-off allowance of 1e-10 called 'stable'."""
    m, _ = _cantilever_column(2.0, 32, EA=1e8)
    with pytest.warns(bs.StabilityWarning, match="unstable"):
        sol = bs.solve(m, steps=2, verbose=False, check_stability=True)
    assert sol.stats[2]["stable"] is False and sol.stats[2]["negative_eigenvalues"] == 2
