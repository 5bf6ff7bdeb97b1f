"""Smoke test of ``benchmarks/error_vs_runtime.py``: each problem function at a tiny size (about 15 s).

Asserts the key numbers the benchmark reports: second order of the 45-degree
bend, path independence of its load steps, round-off error of the exact
constant-strain states (roll-up circle, helix), the capstan's discretisation
error falling with refinement, and the strand's stiffness next to the fibre limit.
"""

import numpy as np
import pytest

import error_vs_runtime as ev


@pytest.fixture(scope="module", autouse=True)
def one_run_each():
    old, ev.REPEATS = ev.REPEATS, 1
    yield
    ev.REPEATS = old


@pytest.fixture(scope="module")
def results():
    ref, p, _ = ev.bend45_reference((64, 128, 256))
    return dict(
        bend_ref=(ref, p, (64, 128, 256)),
        bend_mesh=ev.bend45_mesh((8, 16, 32), reference=ref),
        bend_steps=ev.bend45_steps(8, (1, 3), reference=ref),
        roll_up=ev.roll_up_rows((4, 64), rtols=(1e-12,)),
        helix=ev.helix_rows((4, 32)),
        capstan_mesh=ev.capstan_mesh((3, 6), steps=4, theta=0.5 * np.pi),   # quarter turn: cheaper
        capstan_steps=[],
        strand=ev.strand_rows((4, 8, 16)),
    )


def test_bend45_second_order_and_reference(results):
    ref, p, _ = results["bend_ref"]
    assert 1.95 < p < 2.05, p
    assert np.abs(ref - ev.TEST_CONVERGED_600).max() < 1e-4, ref
    rows = results["bend_mesh"]
    order = ev.fit_order([r["h"] for r in rows], [r["error"] for r in rows])
    assert 1.8 < order < 2.2, order
    e8 = next(r for r in rows if r["n_elements"] == 8)["abs_error"]
    assert 0.1 < e8 < 0.2, e8                      # as in tests/published/test_reference_problems.py


def test_bend45_load_steps_do_not_change_the_answer(results):
    one, three = results["bend_steps"]
    assert three["change_vs_first"] < 1e-9
    assert three["iterations"] > one["iterations"]


def test_roll_up_and_helix_at_round_off(results):
    for r in results["roll_up"] + results["helix"]:
        assert r["error"] < 1e-10, r
        assert r["rotation_error"] < 1e-10, r


def test_capstan_error_falls_with_refinement(results):
    coarse, fine = results["capstan_mesh"]
    flexible, thick = ev.capstan_exact(0.5 * np.pi)
    assert thick < flexible
    assert fine["thick_error"] < coarse["thick_error"]        # discretisation error against the limit
    assert fine["thick_error"] < 0.005 and fine["error"] < 0.02
    assert fine["change_vs_finest"] == 0.0 and coarse["change_vs_finest"] > 0.0


def test_strand_stiffness_near_fibre_limit_and_converging(results):
    rows = results["strand"]
    assert [r["n_elements"] for r in rows] == [2, 4, 8]     # elements_per_lay honoured (half a lay)
    d = [r["discretisation_error"] for r in rows]
    assert d[0] > d[1] > d[2], d
    assert np.isfinite(rows[0]["richardson_order"])
    assert abs(rows[-1]["K_ratio"] - 1.0) < 1e-3            # model error of the fibre limit: a few 1e-4


def test_report_csv_and_plot(results, tmp_path):
    text, orders = ev.report(results, quick=True, total_wall=0.0)
    assert "45-degree bend" in text and "Capstan" in text and "strand" in text
    assert 1.8 < orders["bend45"] < 2.2
    rows = [r for k in ("bend_mesh", "bend_steps", "roll_up", "helix", "capstan_mesh", "strand")
            for r in results[k]]
    path = ev.write_csv(rows, tmp_path / "e.csv")
    lines = path.read_text().splitlines()
    assert len(lines) == len(rows) + 1 and lines[0].startswith("problem,case,n_elements")
    pytest.importorskip("matplotlib")
    written = ev.plot([("bend", results["bend_mesh"], "error", "o-")], [(tmp_path / "p.png", 40)])
    assert written and written[0].stat().st_size > 0
