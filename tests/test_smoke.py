import numpy as np

import beamsolver as bs


def test_public_api_names():
    for name in ["Model", "Section", "solve", "InputError", "ConvergenceError", "se3", "geometry",
                 "contact", "motion"]:
        assert hasattr(bs, name)
    for name in ["exp", "log", "tangent", "tangent_inv"]:
        assert callable(getattr(bs.se3, name))
    assert callable(bs.contact.slip_increment)


def test_roll_up_one_step_is_exact_circle():
    L, EI = 10.0, 1e2
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=EI, EI3=EI, radius=0.1)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (L, 0, 0), 8), sec)
    m.clamp(b.first)
    m.add_load(b.last, moment=(0, 0, 2 * np.pi * EI / L), follower=True)
    sol = bs.solve(m, steps=1)
    x = sol.poses[-1][:, :3, 3]
    R = L / (2 * np.pi)
    assert np.abs(np.linalg.norm(x - [0, R, 0], axis=1) - R).max() < 1e-9 * L
