"""The documentation site: built with warnings as errors, then looked at in a real browser.

Builds ``docs/`` with ``python -m sphinx -W --keep-going -b html`` (the ``[docs]`` extra; skipped
with the reason when it is not installed), checks that the API reference documents the public
names under their public paths, then takes headless Chromium screenshots (Debian's ``chromium``,
installed by ``.ci/run``) of the front page and of the twisted pair's gallery page and checks that
they show text and the committed picture, not a blank or broken page.
"""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
CHROMIUM = "/usr/bin/chromium"
# documented objects the API reference must hold, as anchors of their public paths
API = {
    "api/beamsolver.html": ["beamsolver.Model", "beamsolver.Model.add_contact", "beamsolver.Section",
                            "beamsolver.Solution", "beamsolver.solve", "beamsolver.Convergence",
                            "beamsolver.InputError", "beamsolver.ConvergenceError", "beamsolver.load",
                            "beamsolver.linearize", "beamsolver.sweep", "beamsolver.ArcLength"],
    "api/geometry.html": ["beamsolver.geometry.helix"],
    "api/motion.html": ["beamsolver.motion.rotation"],
    "api/cables.html": ["beamsolver.cables.build_strand"],
    "api/se3.html": ["beamsolver.se3.exp", "beamsolver.se3.tangent_inv"],
    "api/contact.html": ["beamsolver.contact.slip_increment"],
    "api/io.html": ["beamsolver.io.save", "beamsolver.io.vtk.StepWriter", "beamsolver.io.paraview.paraview_script"],
    "api/topology.html": ["beamsolver.topology.writhe_closed"],
    "api/stabilize.html": ["beamsolver.stabilize.Stabilization"],
    "api/viz.html": ["beamsolver.viz.render"],
    "api/elements.html": ["beamsolver.elements.ElementType"],
}


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    for module in ("sphinx", "myst_parser", "pydata_sphinx_theme"):
        pytest.importorskip(module, reason=f"{module} not installed: pip install -e \".[docs]\"")
    out = tmp_path_factory.mktemp("html")
    run = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
                          str(ROOT / "docs"), str(out)], capture_output=True, text=True)
    assert run.returncode == 0, f"docs build failed (warnings are errors):\n{run.stderr[-5000:]}"
    return out


def screenshot(page, tmp_path):
    """RGB array ``(900, 1200, 3)`` of ``page`` in headless Chromium at 1200 x 900."""
    if not Path(CHROMIUM).exists():
        pytest.skip(f"{CHROMIUM} not installed (apt-get install chromium)")
    PIL = pytest.importorskip("PIL.Image", reason="Pillow not installed (the [viz] extra brings it)")
    png = tmp_path / f"{page.stem}.png"
    profile = tmp_path / "chromium-profile"
    subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                    "--no-first-run", "--disable-background-networking", "--disable-component-update",
                    "--disable-sync", f"--user-data-dir={profile}", f"--screenshot={png}",
                    "--window-size=1200,900", page.as_uri()],
                   capture_output=True, timeout=120, check=True)
    return np.asarray(PIL.open(png).convert("RGB"))


def looks_like_a_page_with_the_picture(img):
    """Dark text on a light page, and the twisted pair picture: its wires coloured by utilisation
    (mostly the dark purple of viridis' low end) and red contact points.  A broken image, or a page
    of text and code without it (the API reference: 0 and 0), has neither."""
    grey = img.mean(axis=2)
    assert img.shape == (900, 1200, 3)
    assert (grey > 230).mean() > 0.5, "not a light page"
    assert (grey < 100).mean() > 0.005, "no text on the page"
    r, g, b = np.moveaxis(img.astype(int), 2, 0)
    purple = ((r > 40) & (r < 110) & (g < 40) & (b > 60) & (b < 140)).sum()
    red = ((r > 120) & (g < 50) & (b < 50)).sum()
    assert purple > 300 and red > 100, f"the twisted pair picture is not shown ({purple} purple, {red} red pixels)"


@pytest.mark.slow
def test_api_reference_documents_public_paths(site):
    for page, names in API.items():
        html = (site / page).read_text()
        missing = [n for n in names if f'id="{n}"' not in html]
        assert not missing, f"{page} lacks {missing}"
        assert 'id="beamsolver.driver' not in html and 'id="beamsolver.assembly.system' not in html


@pytest.mark.slow
def test_docstring_citations_link_to_the_topic_page(site):
    """``docs/theory.md eq. 2.1`` in ``se3.exp_so3``'s docstring links to the SE(3) page, and
    ``section 15`` in ``Model.add_contact``'s to the contact-laws page (the section map)."""
    link = '<a class="reference internal" href="../theory/{}.html"><span class="doc">docs/theory.md</span></a>'
    assert link.format("se3") + " eq. 2.1" in (site / "api" / "se3.html").read_text()
    assert link.format("contact_laws") + " section 15" in (site / "api" / "beamsolver.html").read_text()


@pytest.mark.slow
def test_theory_pages_and_section_map(site):
    """Every numbered section of the old docs/theory.md is on one topic page and in the map."""
    text = "".join(p.read_text() for p in sorted((ROOT / "docs" / "theory").glob("*.md")))
    text += (ROOT / "docs" / "theory.md").read_text()
    for n in range(1, 23):
        assert text.count(f"\n## {n}. ") == 1, f"section {n}"
        assert f"\n| {n} | " in (ROOT / "docs" / "theory.md").read_text(), f"section {n} not in the map"


@pytest.mark.slow
def test_front_page_in_a_browser(site, tmp_path):
    looks_like_a_page_with_the_picture(screenshot(site / "index.html", tmp_path))


@pytest.mark.slow
def test_gallery_page_in_a_browser(site, tmp_path):
    looks_like_a_page_with_the_picture(screenshot(site / "gallery" / "twisted_pair.html", tmp_path))
