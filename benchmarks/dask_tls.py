"""Start-up cost of the sweep's local Dask cluster with TLS (the default, ``local_client(secure=True)``)
and without (``secure=False``), and the round trip of one small task.

For each setting, ``REPEATS`` times alternately: start ``local_client(n_workers)`` (scheduler in this
process, worker processes started and registered, the TLS credentials made by
``Security.temporary()``), run one task and wait for its result, close client and cluster.  The table
gives the best (least disturbed on a shared machine) and the median of each.  Run:
``python benchmarks/dask_tls.py [--write]`` (``--write``: the ``dask_tls`` section of docs/benchmarks.md).
"""
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine, single_thread, table, write_section  # noqa: E402

single_thread()

from beamsolver.app.sweep_engine import local_client  # noqa: E402

REPEATS = 3
N_WORKERS = 2


def once(secure):
    t0 = time.perf_counter()
    client = local_client(N_WORKERS, secure=secure)
    t1 = time.perf_counter()
    client.submit(abs, -1, pure=False).result()
    t2 = time.perf_counter()
    for _ in range(20):
        client.submit(abs, -1, pure=False).result()
    t3 = time.perf_counter()
    cluster = client._beamsolver_cluster
    client.close()
    cluster.close()
    return t1 - t0, t2 - t1, (t3 - t2) / 20


def main(write=False):
    runs = {True: [], False: []}
    for _ in range(REPEATS):
        for secure in (True, False):
            runs[secure].append(once(secure))
    rows = []
    for secure in (True, False):
        start, first, task = zip(*runs[secure])
        rows.append(["TLS (default)" if secure else "plain TCP", min(start), statistics.median(start), min(first),
                     1e3 * min(task)])
    rows.append(["TLS - TCP", rows[0][1] - rows[1][1], rows[0][2] - rows[1][2], rows[0][3] - rows[1][3],
                 rows[0][4] - rows[1][4]])
    text = table(["local cluster", "start best [s]", "start median [s]", "first task [s]", "task round trip [ms]"],
                 rows, {1: ".2f", 2: ".2f", 3: ".3f", 4: ".2f"})
    print(text)
    if write:
        write_section("dask_tls", f"""## Secured local Dask cluster (`python benchmarks/dask_tls.py`)

{machine()}; {N_WORKERS} worker processes, {REPEATS} starts of each kind, alternating. A sweep's local cluster
uses TLS with credentials made for it (`Security.temporary()`): other processes of the machine cannot connect to
its scheduler (tests/app/test_sweep_security.py). Start: client and cluster up, workers registered.

{text}""")


if __name__ == "__main__":
    main(write="--write" in sys.argv)
