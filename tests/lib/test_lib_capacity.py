"""Capacity limits of one connection: 16 pending requests; 15 queue tags, handed out as frames are sent."""
from rig import Rig


def test_request_beyond_the_table_of_16_is_refused_and_nothing_is_sent():
    r = Rig(program="Main_Many.st")
    try:
        r.robot.inject("black_hole")              # no replies: every request stays pending
        r.write("Blend", True)
        for k in range(1, 17):
            r.write(f"Exec[{k}]", True)
        r.scans(2)
        assert all(r.read(f"mv[{k}].Busy") for k in range(1, 17))
        r.write("Exec[17]", True)
        r.scans(2)
        assert r.read("mv[17].Error") and r.read("mv[17].ErrorID") == 0x2002
        assert r.read("Cobot.FramesOut") == 16
    finally:
        r.close()


def test_a_sixteenth_non_blended_motion_waits_busy_for_a_free_tag_and_goes_when_one_is_reached():
    r = Rig(program="Main_Many.st")
    try:
        for k in range(1, 17):
            r.write(f"Exec[{k}]", True)
        r.scans(2)
        assert all(r.read(f"mv[{k}].Busy") for k in range(1, 17))
        assert len(r.scripts_in()) == 15 and r.read("Cobot.FramesOut") == 15     # 15 tags in use
        assert r.until(lambda: len(r.scripts_in()) == 16, 10)
        assert r.read("mv[1].Done") and r.scripts_in()[-1][1].endswith("QueueTag(1)")
        assert r.until(lambda: all(r.read(f"mv[{k}].Done") for k in range(1, 17)), 60)
    finally:
        r.close()
