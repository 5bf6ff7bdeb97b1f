"""Fixtures shared by all tests (the helper functions are in ``helpers.py``)."""
import numpy as np
import pytest


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
