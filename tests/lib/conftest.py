import pytest
from edges import cell_rig, var_rig, vision_rig
from rig import Rig


@pytest.fixture
def rig():
    r = Rig()
    yield r
    r.close()


# the input- and command-edge probes (test_lib_input_edges, test_lib_command_edges): besides the library alone
# (rig), with the Ethernet Slave's variables, with the virtual camera, and the whole cell
@pytest.fixture
def var():
    r = var_rig()
    yield r
    r.close()


@pytest.fixture
def vis():
    r = vision_rig()
    yield r
    r.close()


@pytest.fixture
def cell():
    r = cell_rig()
    yield r
    r.close()
