"""SE(3) slip increment versus a centre-line slip measure, from coarse to fine steps.

Kinematic scenes (exact frames, no FE), total motion split into ``N`` steps,
slip accumulated step by step (``sum |dg_T|``) and compared with the exact slip:

- ``rolling``: a cylinder (R = 1) rolls without slipping on a plane by 1 rad
  (exact slip 0);
- ``rolling_on_cylinder``: the same on a fixed cylinder of radius 3;
- ``rolling_with_slip``: rolls by 1 rad while its centre moves 1.2 R (exact slip 0.2 R);
- ``sliding_around_post``: a section carried by 1 rad around a post (surface
  radius 1, centre line at 1.25): exact slip = 1 (the arc on the post surface).

Centre-line measure: ``|x_C(t) - x_C(t - dt)|`` projected on the tangent
plane of the previous contact frame, minus the same for the master centre
(fixed here).  One FE scene (``examples/rolling.py``: error of the distance
rolled) shows the same rate inside the solver.

Writes ``benchmarks/results/slip_measures.md`` and ``.csv``.
"""
import sys
from pathlib import Path

import numpy as np

from beamsolver import se3
from beamsolver.contact import slip_increment

OUT = Path(__file__).resolve().parent / "results"
FRAME0 = np.eye(4)
FRAME0[:3, :3] = np.stack([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]], axis=1)


def _rot_y(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _pose(R, x):
    H = np.eye(4)
    H[:3, :3], H[:3, 3] = R, x
    return H


def _slave_motion(scene, s):
    """Rigid motion of the slave at progress ``s`` in [0, 1] and its centre, (G, x_C)."""
    R1 = 1.0
    c0 = np.array([0.0, 0.0, R1])
    if scene in ("rolling", "rolling_with_slip"):
        beta = s
        travel = R1 * beta * (1.2 if scene == "rolling_with_slip" else 1.0)
        c1 = c0 + [travel, 0.0, 0.0]
        Q = _rot_y(beta)
    elif scene == "rolling_on_cylinder":
        R2 = 3.0
        beta = s
        D = R1 + R2
        alpha = beta * R1 / D
        c1 = np.array([D * np.sin(alpha), 0.0, D * np.cos(alpha) - R2])
        Q = _rot_y(beta)
    elif scene == "sliding_around_post":
        # post axis along e_y through (0, 0, 1 + 0.25); the slave section (radius 0.25)
        # below it, carried around the axis: its contour point slides on the post surface
        axis_pt = np.array([0.0, 0.0, 1.0])
        Q = _rot_y(s)
        c0 = np.array([0.0, 0.0, -0.25])
        return _pose(Q, axis_pt - Q @ axis_pt), Q @ (c0 - axis_pt) + axis_pt
    else:
        raise ValueError(scene)
    return _pose(Q, c1 - Q @ c0), c1


EXACT = dict(rolling=0.0, rolling_on_cylinder=0.0, rolling_with_slip=0.2, sliding_around_post=1.0)


def accumulate(scene, n_steps):
    """Total SE(3) slip and total centre-line slip over ``n_steps`` equal steps."""
    s = np.linspace(0.0, 1.0, n_steps + 1)
    total_se3, total_cl = 0.0, 0.0
    for k in range(n_steps):
        G0, c0 = _slave_motion(scene, s[k])
        G1, c1 = _slave_motion(scene, s[k + 1])
        # material frames of the step: the contact frame at the start of the step,
        # carried by the slave ({L}) and fixed on the master ({K})
        H_K = _contact_frame(scene, s[k], _contact_point(scene, s[k]))
        H_L0 = H_K
        H_L1 = G1 @ np.linalg.inv(G0) @ H_L0
        H_K_fixed = H_K
        dg = slip_increment(se3.relative(H_L0, H_K_fixed), se3.relative(H_L1, H_K_fixed))
        total_se3 += np.linalg.norm(dg)
        t1, t2 = H_L0[:3, 1], H_L0[:3, 2]
        dc = c1 - c0
        total_cl += np.hypot(dc @ t1, dc @ t2)
    return total_se3, total_cl


def _contact_point(scene, s):
    G, c = _slave_motion(scene, s)
    if scene in ("rolling_on_cylinder", "sliding_around_post"):
        R2, axis = (3.0, np.array([0.0, 0.0, -3.0])) if scene == "rolling_on_cylinder" else \
            (1.0, np.array([0.0, 0.0, 1.0]))
        d = c - axis
        return axis + R2 * d / np.linalg.norm(d)
    return np.array([c[0], 0.0, 0.0])


def _contact_frame(scene, s, x):
    G, c = _slave_motion(scene, s)
    n = (x - c) / np.linalg.norm(x - c)
    t1 = np.array([0.0, 1.0, 0.0])
    return _pose(np.stack([n, t1, np.cross(n, t1)], axis=1), x)


def fe_rolling(steps_list=(6, 11, 21, 41)):
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
    import rolling
    rows = []
    for n in steps_list:
        d, exact, _, _ = rolling.main(mu=0.5, theta=1.0, steps=n)
        dtheta = 1.0 / (0.9 * n)        # the ends turn by theta over 0.1 <= t <= 1
        rows.append(dict(scene="FE rolling (examples/rolling.py)", steps=n, dtheta=dtheta,
                         se3_error=abs(d - exact), centre_line_error=np.nan,
                         predicted=exact * dtheta**2 / 12.0))
    return rows


def main(steps_list=(1, 2, 4, 8, 16, 32, 64), fe=True, out=OUT):
    rows = []
    for scene in EXACT:
        for n in steps_list:
            a, b = accumulate(scene, n)
            rows.append(dict(scene=scene, steps=n, dtheta=1.0 / n, se3_error=abs(a - EXACT[scene]),
                             centre_line_error=abs(b - EXACT[scene]),
                             predicted=(1.0 / 12.0) / n**2 if scene == "rolling" else np.nan))
    if fe:
        rows += fe_rolling()
    md = ["| scene | steps | dtheta | SE(3) slip error | centre-line slip error | R theta dtheta^2/12 |",
          "|---|---:|---:|---:|---:|---:|"]
    for r in rows:
        md.append(f"| {r['scene']} | {r['steps']} | {r['dtheta']:.4g} | {r['se3_error']:.3e} | "
                  f"{r['centre_line_error']:.3e} | {r['predicted']:.3e} |")
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        (out / "slip_measures.md").write_text("\n".join(md) + "\n")
        keys = list(rows[0])
        with open(out / "slip_measures.csv", "w") as f:
            f.write(",".join(keys) + "\n")
            for r in rows:
                f.write(",".join(str(r[k]) if isinstance(r[k], str) else f"{r[k]:.6g}" for k in keys) + "\n")
    return rows, "\n".join(md)


if __name__ == "__main__":
    print(main(fe="--no-fe" not in sys.argv)[1])
