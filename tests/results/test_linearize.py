"""Linearised system at a converged step: symmetry at equilibrium, Euler buckling, DOF map."""

import numpy as np
import pytest
import scipy.linalg as sl
import scipy.sparse as sp

import beamsolver as bs

import crossing_beams

L, E, RADIUS = 1.0, 1e7, 0.01
SEC = bs.Section.circular(radius=RADIUS, E=E)
EI = SEC.C[5, 5]
P_EULER = np.pi**2 * EI / (4 * L**2)        # clamped-free column


def column(P, n=16):
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (L, 0, 0), n), SEC)
    m.clamp(b.first)
    m.add_load(b.last, force=(-P, 0, 0))
    return m, b


def test_tangent_symmetric_at_a_conservative_equilibrium():
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (L, 0, 0), 10), SEC)
    m.clamp(b.first)
    m.add_load(b.last, force=(0, 3 * EI / L**2, EI / L**2))
    m.add_load(b.nodes[5], force=(0, 0, -2 * EI / L**2))
    sol = bs.solve(m, steps=4)
    K, r, dofs = bs.linearize(m, sol)
    assert sp.isspmatrix_csr(K) or isinstance(K, sp.csr_array)
    assert K.shape == (6 * 10, 6 * 10) and r.shape == (60,)
    assert np.abs(sol.position(b.last) - [L, 0, 0]).max() > 0.3 * L      # a large deflection
    Kd = K.toarray()
    assert np.abs(Kd - Kd.T).max() < 1e-10 * np.abs(Kd).max()
    assert np.abs(r).max() < 1e-6 * 3 * EI / L**2
    assert np.linalg.eigvalsh(Kd).min() > 0
    # the DOF map: node 0 is clamped, the others carry six body increments each
    assert set(dofs.node.tolist()) == set(range(1, 11))
    np.testing.assert_array_equal(dofs.free_of(b.last), np.arange(54, 60))
    assert dofs.names()[:2] == ["ux@1", "uy@1"] and not dofs.global_frame.any()
    lin = bs.linearize(m, sol, step=0)
    assert lin.t == 0.0 and lin.K_full.shape == (6 * 11, 6 * 11)


def test_euler_buckling_load_from_the_tangent():
    Ks = {}
    for f in (0.0, 0.5, 0.9, 1.1):
        m, _ = column(f * P_EULER)
        Ks[f] = bs.linearize(m, bs.solve(m, steps=1)).K.toarray()
    # linear buckling: K(P) = K0 + P Kg  ->  det(K0 + P Kg) = 0
    Kg = (Ks[0.5] - Ks[0.0]) / (0.5 * P_EULER)
    w = sl.eigvals(Ks[0.0], -Kg)
    w = np.real(w[np.isfinite(w) & (np.abs(np.imag(w)) < 1e-8 * np.abs(w))])
    P_cr = w[w > 0].min()
    assert abs(P_cr / P_EULER - 1.0) < 5e-3
    # the smallest eigenvalue of the tangent changes sign at the critical load
    assert np.linalg.eigvalsh(Ks[0.9]).min() > 0 > np.linalg.eigvalsh(Ks[1.1]).min()


def test_contact_tangent_is_included():
    model, slave, master = crossing_beams.build(n_elements=4)
    sol = bs.solve(model, steps=2)
    lin = bs.linearize(model, sol)
    rows, cols = np.flatnonzero(lin.dofs.beam == slave.id), np.flatnonzero(lin.dofs.beam == master.id)
    coupling = lin.K[rows][:, cols]
    assert abs(coupling).max() > 0                      # only contact couples the two beams
    assert np.abs(lin.r).max() < 1e-5 * 50.0
    with pytest.raises(bs.InputError):
        bs.linearize(model, sol, step=7)
