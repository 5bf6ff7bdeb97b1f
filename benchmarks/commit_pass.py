"""Exact stick's commit at the end of the overlap-free strands' loaded step: its CPU with the point data alone
(``contact.system.LIGHT_COMMIT``, the default) and with the evaluation of every point's forces (before), and the
loaded step's, interleaved (markdown table; ``time.process_time``, the machine is shared; least of ``--repeat``, the
others in brackets).

    MKL_NUM_THREADS=1 python benchmarks/commit_pass.py [--strands 19 37] [--repeat 2]

The strands are ``scaling_scenes.strand_model`` stretched by ``STRAIN`` in one step (as ``scaling.py --step-parts``);
the loaded step is timed from its ``begin_step`` to the end of its commit.  Each run is a fresh subprocess.
"""
import argparse
import json
import subprocess
import sys
import time


def _one(name, light):
    import beamsolver as bs
    import scaling_scenes as ss
    from beamsolver.contact import system
    from scaling import warm_up
    warm_up()
    system.LIGHT_COMMIT = light
    m, wires, length = ss.strand_model(name)
    for w in wires:
        m.prescribe(w.last, bs.motion.translation(lambda t: (0.0, 0.0, ss.STRAIN * length * t)))
    commit, begin = system.ContactSystem.commit, system.ContactSystem.begin_step
    marks = dict(begin=None, commit=[])

    def timed_commit(self, H):
        c0 = time.process_time()
        out = commit(self, H)
        marks["commit"].append((c0, time.process_time()))
        return out

    def timed_begin(self, H, t):
        if t > 0 and marks["begin"] is None:
            marks["begin"] = time.process_time()
        return begin(self, H, t)

    system.ContactSystem.commit, system.ContactSystem.begin_step = timed_commit, timed_begin
    sol = bs.solve(m, steps=1, verbose=False, min_step_ratio=ss.STEP_FLOOR)
    c0, c1 = marks["commit"][-1]
    return dict(its=[s["iterations"] for s in sol.stats], commit=c1 - c0, step=c1 - marks["begin"])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--strands", nargs="+", default=["19", "37"])
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--one", nargs=2, help=argparse.SUPPRESS)       # (a subprocess's run: name, light)
    a = ap.parse_args()
    if a.one:
        print(json.dumps(_one(a.one[0], a.one[1] == "1")))
        return
    print("| strand | its | commit, evaluation [s] | commit, point data [s] | loaded step, evaluation [s] "
          "| loaded step, point data [s] |")
    print("|---|---|---:|---:|---:|---:|")
    for name in a.strands:
        runs = {False: [], True: []}
        for _ in range(a.repeat):
            for light in (False, True):
                out = subprocess.run([sys.executable, __file__, "--one", name, "1" if light else "0"],
                                     capture_output=True, text=True, check=True).stdout
                runs[light].append(json.loads(out.strip().splitlines()[-1]))
        its = runs[True][0]["its"]
        same = all(r["its"] == its for v in runs.values() for r in v)

        def cell(light, part):
            v = sorted(r[part] for r in runs[light])
            return f"{v[0]:.3f}" + (f" ({', '.join(f'{x:.3f}' for x in v[1:])})" if len(v) > 1 else "")
        print(f"| {name} | {', '.join(map(str, its))}{'' if same else ' (differ!)'} | {cell(False, 'commit')} | "
              f"{cell(True, 'commit')} | {cell(False, 'step')} | {cell(True, 'step')} |", flush=True)


if __name__ == "__main__":
    main()
