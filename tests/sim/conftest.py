"""Fixtures of the simulator tests."""
import pytest
from session_rig import S
from sim_harness import Harness


@pytest.fixture
def harness():
    h = Harness()
    yield h
    h.close()


@pytest.fixture
def node():
    """A Listen-node session without sockets, client 1 connected (a test file may extend it under the same name)."""
    n = S()
    n.connect(1)
    return n
