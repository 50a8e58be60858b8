"""Capacity limits of one connection: 16 pending requests, 15 queue tags."""
import pytest

from rig import Rig


@pytest.mark.parametrize("blend,limit,error_id", [(True, 16, 0x2002), (False, 15, 0x2007)])
def test_request_beyond_capacity_is_refused_and_nothing_is_sent(blend, limit, error_id):
    r = Rig(program="Main_Many.st")
    try:
        r.robot.inject("black_hole")              # no replies: every request stays pending
        r.write("Blend", blend)
        for k in range(1, limit + 1):
            r.write(f"Exec[{k}]", True)
        r.scans(2)
        assert all(r.read(f"mv[{k}].Busy") for k in range(1, limit + 1))
        r.write(f"Exec[{limit + 1}]", True)
        r.scans(2)
        assert r.read(f"mv[{limit + 1}].Error") and r.read(f"mv[{limit + 1}].ErrorID") == error_id
        assert r.read("Cobot.FramesOut") == limit
    finally:
        r.close()
