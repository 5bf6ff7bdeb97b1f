"""A ParaView Python script that shows an output folder in one step (``beamsolver paraview OUT``).

``paraview_script(folder)`` writes ``folder/view.py``: it opens ``beams.pvd`` (and
``contact.pvd`` when there is one) with the recipe of smooth tubes at the real radii
(Cell Data to Point Data, Extract Surface, Triangle Strips to join the two-point line cells
into poly-lines, Tube with the radius taken from the point data ``radius``), draws the
contact points as spheres of half the smallest wire radius coloured by ``stick`` (stick red,
slip yellow), colours the tubes by a section force or moment, goes to the last step and looks at
the scene across its longest side (a scene more than 20 times longer than wide is drawn with its
length squeezed, and says so).  Run it with

- ``paraview --script=OUT/view.py`` (the GUI, with the pipeline to edit), or
- ``pvbatch OUT/view.py --screenshot shot.png`` (no window: a PNG; Debian's ``pvbatch``
  needs an X display, e.g. ``xvfb-run -a pvbatch ...``).

The script reads the files next to itself, so the folder can be moved or copied.
"""
import os
from pathlib import Path

from ..errors import InputError

__all__ = ["paraview_script", "FIELDS"]

FIELDS = ("N", "Q2", "Q3", "T", "M2", "M3", "utilisation", "equivalent_strain")   # cell data of beams_<k>.vtu

_TEMPLATE = '''"""ParaView view of a beamsolver output folder (written by beamsolver.io.paraview_script).

paraview --script=view.py            the GUI, with this pipeline
pvbatch view.py --screenshot a.png   a picture without a window (xvfb-run -a pvbatch ... on a server)
"""
import argparse
import os
import sys

from paraview import simple as pv

HERE = os.path.dirname(os.path.abspath(__file__))
COLOR_BY = {color_by!r}          # None: utilisation where sections have a material range, else the largest moment
SIZE = [{width}, {height}]
MAX_ASPECT = 20.0                # longer scenes are drawn with their length squeezed to this aspect


def arguments():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--screenshot", help="save a PNG here and quit")
    p.add_argument("--step", type=int, default=-1, help="step to show (default: the last)")
    p.add_argument("--color-by", default=COLOR_BY, choices={fields!r})
    argv = [a for a in sys.argv[1:] if not a.startswith("--script")]
    return p.parse_known_args(argv)[0]


def array_range(source, name):
    info = source.CellData.GetArray(name) or source.PointData.GetArray(name)
    return info.GetRange(-1) if info is not None else (0.0, 0.0)


def main():
    args = arguments()
    beams = pv.PVDReader(registrationName="beams", FileName=os.path.join(HERE, "beams.pvd"))
    times = list(beams.TimestepValues) if beams.TimestepValues else [0.0]
    time = times[args.step]
    beams.UpdatePipeline(time)
    if args.color_by:
        color = args.color_by
    elif beams.CellData.GetArray("utilisation") is not None:     # sections with a material range
        color = "utilisation"
    else:
        color = max(("T", "M2", "M3"), key=lambda n: max(abs(v) for v in array_range(beams, n)))
    radius = array_range(beams, "radius")

    points = pv.CellDatatoPointData(registrationName="point data", Input=beams)
    points.PassCellData = 1
    surface = pv.ExtractSurface(registrationName="surface", Input=points)
    lines = pv.TriangleStrips(registrationName="poly-lines", Input=surface)
    lines.MaximumLength = 100000                      # one poly-line per beam, however long
    tubes = pv.Tube(registrationName="tubes", Input=lines)
    tubes.Scalars = ["POINTS", "radius"]
    tubes.VaryRadius = "By Absolute Scalar"
    tubes.NumberofSides = 24
    tubes.Capping = 1

    view = pv.GetActiveViewOrCreate("RenderView")
    view.ViewSize = SIZE
    view.OrientationAxesVisibility = 1
    shown = pv.Show(tubes, view)
    pv.ColorBy(shown, ("POINTS", color))
    shown.SetScalarBarVisibility(view, True)

    contact_file = os.path.join(HERE, "contact.pvd")
    if os.path.exists(contact_file):
        contact = pv.PVDReader(registrationName="contact", FileName=contact_file)
        glyphs = pv.Glyph(registrationName="contact points", Input=contact, GlyphType="Sphere")
        glyphs.ScaleArray = ["POINTS", "No scale array"]
        glyphs.ScaleFactor = 1.0 * radius[0]          # sphere of radius 0.5 x the smallest wire radius
        glyphs.GlyphMode = "All Points"
        dots = pv.Show(glyphs, view)
        pv.ColorBy(dots, ("POINTS", "stick"))
        lut = pv.GetColorTransferFunction("stick")
        lut.InterpretValuesAsCategories = 1
        lut.Annotations = ["0", "slip", "1", "stick"]
        lut.IndexedColors = [1.0, 0.85, 0.0, 0.0, 0.6, 0.0]
        dots.SetScalarBarVisibility(view, True)

    scene = pv.GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()
    scene.AnimationTime = time
    shown.RescaleTransferFunctionToDataRange(False, True)
    lut = pv.GetColorTransferFunction(color)
    low, high = lut.RGBPoints[0], lut.RGBPoints[-4]
    if color in ("utilisation", "equivalent_strain"):
        lut.ApplyPreset("Inferno (matplotlib)", True)
        lut.RescaleTransferFunction(0.0, max(high, 1.0) if color == "utilisation" else high)
    else:
        lut.RescaleTransferFunction(-max(abs(low), abs(high)), max(abs(low), abs(high)))   # zero in the middle

    # look across the longest side of the bounding box, from the direction of its thinnest side
    b = beams.GetDataInformation().GetBounds()
    extent = [b[1] - b[0], b[3] - b[2], b[5] - b[4]]
    up = max(range(3), key=lambda i: extent[i])
    across = min((i for i in range(3) if i != up), key=lambda i: extent[i])
    width = max(extent[i] for i in range(3) if i != up) + 2 * radius[1]
    if extent[up] > MAX_ASPECT * width:       # a slender scene (a 1 m cable of 1 mm wires): squeeze its length
        squeeze = [1.0, 1.0, 1.0]
        squeeze[up] = MAX_ASPECT * width / extent[up]
        for source in [tubes] + ([glyphs] if os.path.exists(contact_file) else []):
            pv.GetDisplayProperties(source, view).Scale = squeeze
        note = pv.Text(registrationName="note", Text=f"length squeezed {{1 / squeeze[up]:.0f}} times")
        pv.Show(note, view).WindowLocation = "Upper Left Corner"
        extent[up] *= squeeze[up]
        b = [b[2 * i + j] * squeeze[i] for i in range(3) for j in range(2)]
    centre = [(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2]
    direction = [0.0, 0.0, 0.0]
    direction[across] = 1.0
    view_up = [0.0, 0.0, 0.0]
    view_up[up] = 1.0
    view.CameraFocalPoint = centre
    view.CameraPosition = [c + 3 * max(extent) * d for c, d in zip(centre, direction)]
    view.CameraViewUp = view_up
    view.ResetCamera(False)
    pv.Render(view)
    if args.screenshot:
        pv.SaveScreenshot(args.screenshot, view, ImageResolution=SIZE)


main()
'''


def paraview_script(folder, path=None, color_by=None, size=(1200, 800)):
    """Write a ParaView Python script showing the output ``folder``; returns its path.

    ``path``: where to write it (default ``folder/view.py``); it reads ``beams.pvd`` and
    ``contact.pvd`` from ``folder`` given relative to itself when written in ``folder``.
    ``color_by``: one of ``FIELDS`` (None: ``utilisation`` when written, else the largest moment).  ``size``: pixels.
    """
    folder = Path(folder)
    if not (folder / "beams.pvd").is_file():
        raise InputError(f"paraview_script: {str(folder)!r} has no beams.pvd (write output with "
                         f"solve(..., output=folder) or beamsolver export)")
    if color_by is not None and color_by not in FIELDS:
        raise InputError(f"paraview_script: color_by must be one of {', '.join(FIELDS)}, got {color_by!r}")
    width, height = (int(v) for v in size)
    if width <= 0 or height <= 0:
        raise InputError(f"paraview_script: size must be two positive pixel counts, got {size!r}")
    path = Path(path) if path is not None else folder / "view.py"
    text = _TEMPLATE.format(color_by=color_by, width=width, height=height, fields=FIELDS)
    if path.resolve().parent != folder.resolve():
        text = text.replace('HERE = os.path.dirname(os.path.abspath(__file__))',
                            f'HERE = {str(folder.resolve())!r}')
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(text)                   # mode 0666 & ~umask, as open() gives
    os.replace(tmp, path)
    return path


def screenshot(script, png, step=-1, timeout=300):
    """Run ``script`` (from ``paraview_script``) in ParaView's ``pvbatch`` to save ``png``.

    Without a display (no ``DISPLAY``), runs it under ``xvfb-run -a`` when that exists
    (Debian's ``pvbatch`` is built for X).  Raises ``InputError`` when ``pvbatch`` is not
    installed (Debian/Ubuntu: ``apt-get install paraview``) and ``RuntimeError`` with
    ParaView's messages when it fails.
    """
    import shutil
    import subprocess
    pvbatch = shutil.which("pvbatch")
    if pvbatch is None:
        raise InputError("paraview screenshot: pvbatch (ParaView's batch interpreter) is not on PATH; "
                         "install ParaView (Debian/Ubuntu: apt-get install paraview) or open "
                         f"{script} in the ParaView GUI (paraview --script={script})")
    cmd = [pvbatch, str(script), "--screenshot", str(Path(png).resolve()), "--step", str(int(step))]
    if not os.environ.get("DISPLAY") and shutil.which("xvfb-run"):
        cmd = ["xvfb-run", "-a"] + cmd
    # viz sets vtkEGLRenderWindow for the vtk wheel; ParaView's own VTK may have no EGL (Debian's aborts)
    env = {k: v for k, v in os.environ.items() if k != "VTK_DEFAULT_OPENGL_WINDOW"}
    for attempt in range(3 if cmd[0] == "xvfb-run" else 1):    # pvbatch under xvfb-run fails now and then (1 in ~10 here)
        out = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env)
        if out.returncode == 0 and Path(png).is_file():
            return Path(png)
    errors = [line for line in out.stderr.splitlines() if "ERR" in line or "FATL" in line or "rror" in line]
    raise RuntimeError(f"pvbatch failed (exit {out.returncode}): " + "\n".join(errors[:10])
                       + f"\n{out.stdout[-1000:]}\n{out.stderr[-1000:]}")
