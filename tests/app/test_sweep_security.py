"""The local Dask cluster of a sweep talks TLS with credentials made for it (issue 28 item 15): another
process of the machine that finds the scheduler's port can no longer connect and run code in the
workers, neither in plain TCP nor with TLS credentials of its own."""
import subprocess
import sys

import pytest

pytest.importorskip("distributed")
pytest.importorskip("cryptography")

from beamsolver.app.sweep_engine import local_client  # noqa: E402

INTRUDER = """
import sys
import distributed
kw = dict(security=distributed.security.Security.temporary()) if sys.argv[2] == "own-tls" else {}
try:
    with distributed.Client(sys.argv[1], timeout="5s", **kw) as c:
        print(c.submit(lambda: "ran in a worker", pure=False).result(timeout=20))
except Exception as e:
    print("refused:", type(e).__name__)
"""


def _intrude(address, how="plain"):
    """What another local process prints when it connects to ``address`` and submits code."""
    out = subprocess.run([sys.executable, "-c", INTRUDER, address, how], capture_output=True, text=True, timeout=120)
    return out.stdout.strip()


@pytest.mark.slow
def test_local_cluster_refuses_other_local_processes():
    client = local_client(1)
    try:
        address = client.scheduler.address
        assert address.startswith("tls://127.0.0.1:")
        assert client.submit(lambda x: x + 1, 1).result() == 2           # the sweep's own client works
        assert _intrude(address).startswith("refused")                    # no credentials
        assert _intrude(address, "own-tls").startswith("refused")         # credentials of another CA
        assert _intrude(address.replace("tls://", "tcp://")).startswith("refused")
    finally:
        cluster = client._beamsolver_cluster
        client.close()
        cluster.close()


@pytest.mark.slow
def test_unsecured_cluster_is_still_open_to_them():
    """The test's witness: without TLS (``secure=False``, the former default) the intruder runs its code."""
    client = local_client(1, secure=False)
    try:
        assert _intrude(client.scheduler.address) == "ran in a worker"
    finally:
        cluster = client._beamsolver_cluster
        client.close()
        cluster.close()
