"""A pick-and-place run of 1,000 motions loses nothing and executes nothing twice."""
import pytest
from rig import Rig


@pytest.mark.slow
def test_thousand_motion_pick_and_place_run_loses_nothing():
    r = Rig(program="Main_PnP.st", speedup=20.0)
    try:
        r.write("Run", True)
        assert r.until(lambda: r.read("Count") >= 1000 or r.read("Errors") > 0, 400)
        assert r.read("Errors") == 0 and r.read("Count") == 1000
        assert r.until(lambda: len(r.events("motion_end")) == 1000, 10)
        ids = [i for i, _ in r.scripts_in()]
        assert len(ids) == 1000 and len(set(ids)) == 1000
        assert len(r.events("motion_start")) == 1000
    finally:
        r.close()
