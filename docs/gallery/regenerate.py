"""Regenerate the gallery's printed outputs and pictures.

    python docs/gallery/regenerate.py [NAME ...]      # all examples, or the named ones

For each example, ``python examples/NAME.py`` runs in a scratch folder and its printed output
goes to ``docs/gallery/printed/NAME.txt``.  The picture ``docs/gallery/NAME.png`` is drawn by
``beamsolver.viz.render`` from ``beamsolver run examples/NAME.py`` (the example's ``build()``
with its defaults) for the examples in ``RENDER``; the others show a picture they make
themselves (``OWN``).  Needs the ``[viz]`` extra; with the kernels compiled about three minutes
in all, ``plectoneme`` excepted (``LONG``: only when named).  The docs build executes nothing:
it shows the committed files.
"""
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
GALLERY = ROOT / "docs" / "gallery"

# viz.render options of the picture of each example drawn from its solution
RENDER = {
    "twisted_pair": dict(color_by="utilisation", view="xz", scale=(1, 1, 0.02), window_size=(300, 640)),
    "three_wires": dict(color_by="T", view="iso", window_size=(300, 640), zoom=2.2),
    "seven_wire_strand": dict(color_by="beam_id", view="iso", window_size=(480, 640), zoom=1.4),
    "bend45": dict(color_by="displacement", view="iso", window_size=(640, 480)),
    "capstan": dict(color_by="N", view="iso", window_size=(640, 480), zoom=0.9),
    "crossing_beams": dict(color_by="M3", view="iso", window_size=(640, 480)),
    "rolling": dict(color_by="displacement", view="iso", window_size=(640, 480)),
}
# examples whose picture is one they write (arguments added to their command line)
OWN = {"strand_sweep": ["--plot", str(GALLERY / "strand_sweep.png"), "-o", "strand_study"]}
ALL = ["twisted_pair", "plectoneme", "three_wires", "seven_wire_strand", "strand_sweep", "capstan",
       "rolling", "crossing_beams", "roll_up", "bend45", "limit_points"]
LONG = {"plectoneme"}


def run_example(name, scratch):
    """Print-out of ``python examples/NAME.py`` run in ``scratch`` (exit status checked)."""
    cmd = [sys.executable, str(ROOT / "examples" / f"{name}.py"), *OWN.get(name, [])]
    out = subprocess.run(cmd, cwd=scratch, capture_output=True, text=True, check=True)
    (GALLERY / "printed" / f"{name}.txt").write_text(out.stdout)


def draw(name, scratch):
    """``docs/gallery/NAME.png``: the last step of ``beamsolver run examples/NAME.py``."""
    import beamsolver as bs
    from beamsolver import viz
    folder = Path(scratch) / f"{name}_run"
    subprocess.run(["beamsolver", "run", str(ROOT / "examples" / f"{name}.py"),
                    "-o", str(folder)], cwd=scratch, capture_output=True, check=True)
    viz.render(bs.load(folder), step=-1, path=str(GALLERY / f"{name}.png"), **RENDER[name])


def main(names):
    for name in names or [n for n in ALL if n not in LONG]:
        with tempfile.TemporaryDirectory() as scratch:
            run_example(name, scratch)
            if name in RENDER:
                draw(name, scratch)
        print(f"{name}: printed/{name}.txt" + (f", {name}.png" if name in RENDER or name in OWN else ""))


if __name__ == "__main__":
    main(sys.argv[1:])
