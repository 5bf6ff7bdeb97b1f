"""``bs.sweep`` on Dask: two local worker processes give exactly the serial results, failures are
recorded, a dying worker's point is retried once, an interrupted study resumes, and the CLI runs a
study on a ``dask scheduler`` + ``dask worker`` started here (127.0.0.1 only)."""
import json
import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

import beamsolver as bs
from beamsolver.app import study

pytest.importorskip("distributed")

from beamsolver.app.sweep_engine import local_client

ROOT = Path(__file__).resolve().parents[2]
OPTIONS = dict(steps=4)


def cantilever(turns=0.25, n_elements=4, radius=0.1):
    """Roll-up of a cantilever by a follower end moment of ``turns`` full circles."""
    sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=radius)
    m = bs.Model()
    b = m.add_beam(bs.geometry.straight((0, 0, 0), (10, 0, 0), n_elements), sec)
    m.clamp(b.first)
    m.add_load(b.last, moment=(0, 0, turns * 2 * np.pi * 1e2 / 10), follower=True)
    return m, b


def tip(sol, model, beam):
    x = sol.position(beam.last)
    return {"tip_x": x[0], "tip_y": x[1], "reaction_mz": sol.reaction(beam.first)[5]}


def fragile(mode, marker):
    """Kills its worker process: always, or on its first call only (counted in the file ``marker``)."""
    with open(marker, "a") as f:
        f.write("x")
    if mode == "always" or Path(marker).stat().st_size == 1:
        os._exit(3)
    return cantilever()


def counted(turns, log, delay=0.0):
    """``cantilever`` that appends ``turns`` to the file ``log`` and takes ``delay`` seconds more."""
    with open(log, "a") as f:
        f.write(f"{turns}\n")
    time.sleep(delay)
    return cantilever(turns, 8)


@pytest.fixture(scope="module")
def client():
    c = local_client(2)
    yield c
    c.close()
    c._beamsolver_cluster.close()


@pytest.mark.slow
def test_local_workers_single_threaded_with_one_blas_thread(client):
    assert list(client.nthreads().values()) == [1, 1]
    env = client.run(lambda: [os.environ.get(v) for v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                                                          "MKL_NUM_THREADS")])
    assert all(v == ["1", "1", "1"] for v in env.values()), env
    pids = client.run(os.getpid)
    assert os.getpid() not in pids.values() and len(set(pids.values())) == 2   # worker processes


@pytest.mark.slow
def test_two_workers_give_the_serial_results_and_record_failures(client, tmp_path):
    grid = study.points({"turns": [0.25, 1.0], "n_elements": [2, 8]})
    grid.append(dict(turns=0.25, n_elements=4, radius=-1.0))                    # bad input
    rows = bs.sweep(cantilever, grid, summary=tip, client=client, output=tmp_path, solve_options=OPTIONS,
                    verbose=False)
    assert [{k: r[k] for k in p} for r, p in zip(rows, grid)] == grid           # grid order
    assert [r["status"] for r in rows] == ["converged", "converged", "ConvergenceError", "converged",
                                           "InputError"]
    for p, r in zip(grid[:4], rows):
        archive = bs.load(tmp_path / r["id"])
        model, beam = cantilever(**p)
        try:
            serial = bs.solve(model, verbose=False, **OPTIONS)
        except bs.ConvergenceError as e:                        # (1 turn, 2 elements): refused near pi
            serial = e.solution
            assert r["message"] == str(e) and not archive.converged
            assert r["steps"] == serial.n_steps > 0 and "tip_x" not in r
        else:
            assert r["tip_x"] == serial.position(beam.last)[0] and r["tip_y"] == serial.position(beam.last)[1]
            assert r["reaction_mz"] == serial.reaction(beam.first)[5]
        assert np.array_equal(archive.poses, serial.poses) and np.array_equal(archive.times, serial.times)
        assert np.array_equal(archive.reactions, serial.reactions)
        assert r["iterations"] == serial.iterations.sum() and r["wall"] > 0
    assert "radius" in rows[4]["message"] and not (tmp_path / rows[4]["id"] / "solution.npz").exists()
    lines = (tmp_path / "summary.csv").read_text().splitlines()
    assert lines[0] == "id,turns,n_elements,radius,status,iterations,steps,wall,tip_x,tip_y,reaction_mz,message"
    assert len(lines) == 6 and lines[3].split(",")[4] == "ConvergenceError"
    assert abs(rows[3]["tip_x"]) < 1e-9 and abs(rows[0]["tip_x"] - 20 / np.pi) < 1e-9   # full circle, quarter


@pytest.mark.slow
def test_a_dying_worker_is_retried_once_then_recorded(client, tmp_path):
    grid = [dict(mode="always", marker=str(tmp_path / "a")), dict(mode="once", marker=str(tmp_path / "b"))]
    rows = bs.sweep(fragile, grid, client=client, output=tmp_path / "s", solve_options=OPTIONS, verbose=False)
    assert rows[0]["status"] == "KilledWorker" and "died twice" in rows[0]["message"]
    assert rows[1]["status"] == "converged"
    assert (tmp_path / "a").read_text() == "xx" and (tmp_path / "b").read_text() == "xx"   # two attempts each
    rec = study.read_point(tmp_path / "s", rows[0]["id"])
    assert rec["row"]["status"] == "KilledWorker"                # recorded, but re-run by a later sweep
    assert not study.is_complete(rec, grid[0], OPTIONS)


def test_a_scene_the_workers_cannot_import_is_recorded(client, tmp_path, monkeypatch):
    (tmp_path / "only_here.py").write_text("from test_sweep import cantilever\n\n\n"
                                           "def scene(turns):\n    return cantilever(turns)\n")
    monkeypatch.syspath_prepend(str(tmp_path))               # importable here, not in the workers
    import only_here
    rows = bs.sweep(only_here.scene, {"turns": [0.25, 0.5]}, client=client, output=tmp_path / "s",
                    solve_options=OPTIONS, verbose=False)
    assert [r["status"] for r in rows] == ["SceneLoadError"] * 2
    assert "No module named 'only_here'" in rows[0]["message"] and "upload_file" in rows[0]["message"]
    assert bs.sweep(cantilever, {"turns": [0.25]}, client=client, solve_options=OPTIONS,
                    verbose=False)[0]["status"] == "converged"           # the workers survived


@pytest.mark.slow
def test_an_interrupted_study_resumes(client, tmp_path, monkeypatch):
    log = tmp_path / "log"
    grid = [dict(turns=t, log=str(log), delay=0.0 if t == 0.25 else 0.3) for t in (0.25, 0.5, 0.75, 1.0)]
    real = study.write_summary

    def interrupt(*args):                                       # Ctrl-C after the first finished point
        real(*args)
        raise KeyboardInterrupt
    monkeypatch.setattr(study, "write_summary", interrupt)
    with pytest.raises(KeyboardInterrupt):
        bs.sweep(counted, grid, summary=tip, client=client, output=tmp_path / "s", solve_options=OPTIONS,
                 verbose=False)
    monkeypatch.setattr(study, "write_summary", real)
    time.sleep(1.5)                                             # points already running finish
    first = [study.read_point(tmp_path / "s", study.point_id(p)) for p in grid]
    n_done = sum(r is not None for r in first)
    assert 1 <= n_done < 4 and first[0] is not None
    assert len((tmp_path / "s" / "summary.csv").read_text().splitlines()) == 2
    rows = bs.sweep(counted, grid, summary=tip, client=client, output=tmp_path / "s", solve_options=OPTIONS,
                    verbose=False)
    runs = log.read_text().split()
    assert sorted(runs) == ["0.25", "0.5", "0.75", "1.0"]      # every point solved exactly once
    assert all(r["status"] == "converged" for r in rows)
    assert rows[0] == first[0]["row"]                            # the finished point's row, as recorded
    assert len((tmp_path / "s" / "summary.csv").read_text().splitlines()) == 5
    again = bs.sweep(counted, grid, summary=tip, client=client, output=tmp_path / "s", solve_options=OPTIONS,
                     verbose=False)
    assert again == rows and len(log.read_text().split()) == 4  # complete: nothing runs
    bs.sweep(counted, grid[:2], client=client, output=tmp_path / "s", solve_options=dict(steps=2), verbose=False)
    assert len(log.read_text().split()) == 6                    # other solve options: solved again


@pytest.mark.slow
def test_default_local_cluster_and_progress_lines(capsys):
    rows = bs.sweep(cantilever, {"turns": [0.25, 0.5]}, summary=tip, solve_options=OPTIONS, verbose=True)
    assert [r["status"] for r in rows] == ["converged", "converged"]
    assert abs(rows[1]["tip_x"]) < 1e-9 and abs(rows[1]["tip_y"] - 20 / np.pi) < 1e-9   # half a circle
    err = capsys.readouterr()
    assert "Dask dashboard at http://127.0.0.1:" in err.err
    assert "sweep: 2/2 points, failed 0" in err.out


SCENE = textwrap.dedent("""
    import numpy as np
    import beamsolver as bs

    solve_options = dict(steps=4)


    def build(turns=0.25, n_elements=4):
        sec = bs.Section(EA=1e4, GA2=1e4, GA3=1e4, GJ=1e2, EI2=1e2, EI3=1e2, radius=0.1)
        m = bs.Model()
        b = m.add_beam(bs.geometry.straight((0, 0, 0), (10, 0, 0), n_elements), sec)
        m.clamp(b.first)
        m.add_load(b.last, moment=(0, 0, turns * 2 * np.pi * 1e2 / 10), follower=True)
        return m, b


    def summary(sol, model, beam):
        return {"tip_x": sol.position(beam.last)[0]}
""")


def _start(args, env, cwd):
    return subprocess.Popen([sys.executable, "-m", "dask", *args], env=env, cwd=cwd,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


@pytest.mark.slow
def test_cli_sweep_on_a_scheduler_and_worker_started_here(tmp_path):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    sched_file = tmp_path / "scheduler.json"
    procs = [_start(["scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                     "--scheduler-file", str(sched_file)], env, tmp_path)]
    try:
        for _ in range(300):
            if sched_file.exists() and sched_file.stat().st_size:
                break
            time.sleep(0.1)
        address = json.loads(sched_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        procs.append(_start(["worker", address, "--host", "127.0.0.1", "--nthreads", "1", "--nworkers", "1",
                             "--no-dashboard"], env, tmp_path))
        (tmp_path / "scene.py").write_text(SCENE)
        run = [sys.executable, "-m", "beamsolver.app.cli"]
        out = subprocess.run(run + ["sweep", "scene.py", "--param", "turns=0.25,1.0", "--param", "n_elements=2,8",
                                    "-o", "study", "--scheduler", address, "--paraview"],
                             cwd=tmp_path, env=env, capture_output=True, text=True, timeout=180)
        assert out.returncode == 2, out.stderr                  # one point stops: exit status 2
        assert "4 points over turns, n_elements" in out.stdout and "3 converged, 1 ConvergenceError" in out.stdout
        folder = tmp_path / "study" / "turns=1.0_n_elements=8"
        assert (folder / "beams.pvd").exists() and (folder / "beams_0004.vtu").exists()
        sol = bs.load(folder)
        model, beam = cantilever(1.0, 8)
        assert np.array_equal(sol.poses, bs.solve(model, verbose=False, **OPTIONS).poses)
        info = subprocess.run(run + ["info", "study"], cwd=tmp_path, env=env, capture_output=True, text=True,
                              timeout=60)
        assert info.returncode == 0 and "3 converged, 1 ConvergenceError" in info.stdout
        assert "turns=1.0_n_elements=2: ConvergenceError: solve: could not advance" in info.stdout
    finally:
        for p in reversed(procs):
            p.terminate()
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


@pytest.mark.slow
def test_strand_sweep_example_against_strand_theory(client, tmp_path):
    import strand_sweep
    client.upload_file(str(ROOT / "examples" / "strand_sweep.py"))     # the workers import the scene's module
    table = strand_sweep.main(angles=(5.0, 20.0), client=client, output=tmp_path / "s", verbose=False)
    for t in table:
        assert t["K_fixed"] == pytest.approx(t["rod_K_fixed"], rel=0.01), t
        assert t["K_fixed"] <= t["fibre_K_fixed"] * 1.0001, t         # the fibre limit bounds it here
        assert t["C"] == pytest.approx(t["rod_C"], rel=0.03), t
        assert t["C"] == pytest.approx(t["fibre_C"], rel=0.04), t
        assert t["rod_K_free"] < t["K_free"] < 1.1 * t["rod_K_free"], t   # the plates stiffen the twist
        assert t["K_free"] > 1.4 * t["fibre_K_free"]                 # the fibre K_ww omits wire torsion
        assert t["twist"] == pytest.approx(t["rod_twist"], rel=0.1), t   # a right-hand lay untwists
        assert t["twist"] < 0 and t["K_free"] < t["K_fixed"]
    assert table[1]["K_fixed"] < table[0]["K_fixed"] and table[1]["C"] > table[0]["C"]
    pytest.importorskip("matplotlib")
    assert strand_sweep.plot(table, tmp_path / "p.png").stat().st_size > 0


@pytest.mark.slow
def test_sweep_overhead_benchmark_pieces(client, tmp_path):
    import cloudpickle
    import sweep_overhead as so
    pts = [dict(load=x, n_elements=so.SIZES["small"]) for x in so.LOADS[:2]]
    (tmp_path / "serial").mkdir()
    assert so.serial(pts, tmp_path / "serial") > 0 and len(list((tmp_path / "serial").iterdir())) == 2
    cloudpickle.register_pickle_by_value(so)                  # as when the script runs as __main__
    try:
        wall, inside = so.swept(client, pts, tmp_path / "s")
    finally:
        cloudpickle.unregister_pickle_by_value(so)
    assert wall > 0 and inside > 0
