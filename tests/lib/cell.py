"""Shared fixture of the issue 26 tests (CBT_ReadIO, CBT_SetOverride, CBT_WaitQueue, motion status): one robot with
its Ethernet Slave, tests/lib/st/Main_Cell.st connected, CBT_RobotStatus and CBT_ReadIO enabled and Valid."""
import pytest
from rig import Rig


@pytest.fixture
def svr():
    r = Rig(program="Main_Cell.st", svr_port=0)
    r.write("StatusEnable", True)
    r.write("IOEnable", True)
    assert r.until(lambda: r.read("status.Valid") and r.read("io.Valid"), 1)
    yield r
    r.close()
