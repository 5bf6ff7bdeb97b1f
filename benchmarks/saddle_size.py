"""From which size exact stick's saddle systems go through the augmented matrix (``augmented.MIN_UNKNOWNS``).

``python benchmarks/saddle_size.py [--sizes 16,32,64,128] [--thresholds 1500,300,0]``

The main job's scene (``examples/twisted_pair.py``, 16 steps) at ``n`` elements per wire, solved twice in one
process per threshold (the second solve timed: CPU seconds by ``time.process_time``, caches warm), with
``augmented.MIN_UNKNOWNS`` set: below it the condensed saddle system is factorised directly (SuperLU with the saddle
settings), from it through ``A = K' + Kq E Kl`` and GMRES (``nonlinear/augmented.py``).  Prints the Newton
iterations and CPU ms per iteration; the same iterations at every threshold mean the same iterates.
"""
import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def child(n, threshold):
    sys.path.insert(0, str(ROOT / "examples"))
    import beamsolver as bs
    from beamsolver.nonlinear import augmented
    from twisted_pair import build
    augmented.MIN_UNKNOWNS = threshold
    model = build(n_elements=n)[0]
    bs.solve(build(n_elements=n)[0], steps=16, verbose=False)
    t0 = time.process_time()
    sol = bs.solve(model, steps=16, verbose=False)
    cpu = time.process_time() - t0
    its = sum(s["iterations"] for s in sol.stats)
    cuts = sum(s.get("cutbacks", 0) for s in sol.stats)
    print(json.dumps(dict(n=n, threshold=threshold, dofs=int(model_dofs(sol)), its=its, cuts=cuts, cpu=cpu)))


def model_dofs(sol):
    return 6 * sol.poses.shape[1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="16,32,64,128")
    ap.add_argument("--thresholds", default="1500,300,0")
    ap.add_argument("--child", nargs=2, type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        return child(*args.child)
    print("| el/wire | dofs | MIN_UNKNOWNS | Newton it. (cut-backs) | CPU s | ms / iteration |")
    print("|---:|---:|---:|---:|---:|---:|")
    for n in map(int, args.sizes.split(",")):
        for th in map(int, args.thresholds.split(",")):
            out = subprocess.run([sys.executable, __file__, "--child", str(n), str(th)], capture_output=True,
                                 text=True, check=True).stdout.strip().splitlines()[-1]
            r = json.loads(out)
            print(f"| {n} | {r['dofs']} | {th} | {r['its']} ({r['cuts']}) | {r['cpu']:.2f} | "
                  f"{1e3 * r['cpu'] / r['its']:.2f} |", flush=True)


if __name__ == "__main__":
    main()
