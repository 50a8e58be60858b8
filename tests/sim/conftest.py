"""Fixtures of the simulator tests."""
import pytest

from sim_harness import Harness


@pytest.fixture
def harness():
    h = Harness()
    yield h
    h.close()
