"""Fixtures shared by all tests (the helper functions are in ``helpers.py``)."""
import numpy as np
import pytest


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


def pytest_sessionfinish(session, exitstatus):
    """Clear a compile bar still open (the last tests compiled on an empty cache): pytest would print its last
    state after the summary, with the output it captured outside the tests (``jit_warmup._Announcer.at_exit``
    runs later, at the interpreter's exit)."""
    from beamsolver.nonlinear import jit_warmup
    for announcer in jit_warmup._LISTENER:
        announcer.at_exit()
