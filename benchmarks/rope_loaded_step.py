"""The rope piece's loaded step (``tests/nonlinear/test_rope_loaded_step.py``'s scene: six 1+6+12 strands around a
1+6+12 core, 133 wires, one step of strain 1e-4) with each stick and each setting of the normal law's active set
(``nonlinear.newton.NORMAL_SWITCHES``, an option): Newton iterations, the last scaled residual and CPU time
(``time.process_time``; the machine is shared).  Rows print as they finish (markdown table).

    python benchmarks/rope_loaded_step.py [--lengths 0.02 0.04] [--sticks exact penalty] [--switches 0 4]
"""
import argparse
import time

import beamsolver as bs
from beamsolver.nonlinear import newton

L = bs.cables.Layer
STRAIN = 1e-4


def rope(length, stick):
    """The test's rope piece of ``length`` (m), its wires clamped below and pulled by ``STRAIN`` above."""
    core = [L(0.6e-3), L(0.55e-3, 6, lay_length=0.05), L(0.55e-3, 12, lay_length=0.05)]
    strand = [L(0.55e-3), L(0.5e-3, 6, lay_length=0.04, direction="left"),
              L(0.5e-3, 12, lay_length=0.04, direction="left")]
    r = bs.cables.build_rope(strand, length=length, E=2e11, lay_length=0.1, core=core, elements_per_lay=48,
                             mu=0.3, contact_options=dict(gauss_points=5, stick=stick))
    for w in r.all_wires:
        r.model.clamp(w.first)
        r.model.prescribe(w.last, bs.motion.translation(lambda t: (0.0, 0.0, STRAIN * length * t)))
    return r.model


def row(length, stick, switches):
    """``(iterations, last scaled residual, converged, CPU s)`` of the loaded step (``"-"``, nan when it failed)."""
    newton.NORMAL_SWITCHES = switches
    t0 = time.process_time()
    try:
        st = bs.solve(rope(length, stick), steps=1, min_step_ratio=1.0, verbose=False).stats[-1]
        out = st["iterations"], st["residuals"][-1], True
    except bs.ConvergenceError:
        out = "-", float("nan"), False              # (the failed step's iterations are not in the solution)
    return (*out, time.process_time() - t0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lengths", type=float, nargs="+", default=[0.02, 0.04])
    ap.add_argument("--sticks", nargs="+", default=["exact", "penalty"])
    ap.add_argument("--switches", type=int, nargs="+", default=[0, 4])
    a = ap.parse_args()
    print("| length [mm] | stick | NORMAL_SWITCHES | Newton it. | last scaled residual | converged | CPU [s] |")
    print("|---:|---|---:|---:|---:|---|---:|")
    for length in a.lengths:
        for stick in a.sticks:
            for n in a.switches:
                it, res, ok, cpu = row(length, stick, n)
                print(f"| {length * 1e3:g} | {stick} | {n} | {it} | {res:.2e} | {'yes' if ok else 'no'} | {cpu:.1f} |",
                      flush=True)


if __name__ == "__main__":
    main()
