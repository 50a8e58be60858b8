import pytest
from rig import Rig


@pytest.fixture
def rig():
    r = Rig()
    yield r
    r.close()
