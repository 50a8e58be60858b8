"""Non-blended completions under the robot's four-tag rule (TMscript 2.24 §13.2: the robot keeps the status
of the last four queue tags only): 16 motions in flight per robot, up to 4 robots, pushes lost to bad
checksums, and a stop in the middle. Every mover ends exactly once; Done never before its motion ended."""
import pytest
from rig import Rig

PUSH = "$TMSTA,10,01,"          # a tag push (and a TMSTA 01 'true' answer): 01,NN,true


@pytest.fixture
def tags(request):
    """Rig of Main_Tags.st: 16 movers per robot; ``robots`` (1..4) and ``speed`` (%) by indirect parameter."""
    param = dict(getattr(request, "param", {}))
    speed = param.pop("speed", 100)
    r = Rig(program="Main_Tags.st", **param)
    r.write("Speed", speed)
    yield r
    r.close()


def start_all(rig):
    for i in range(1, 16 * len(rig.srv.robots) + 1):
        rig.write(f"Exec[{i}]", True)


def ended(rig, i):
    return rig.read(f"Edges[{i}]") > 0


def motion_ends(rig, r):
    """{mover k: sim time (s) its motion ended} of robot r (mover k moves J6 to 5k degrees)."""
    return {round(e["joints"][5] / 5): e["t"] for e in rig.srv.robots[r - 1].events if e["kind"] == "motion_end"}


def scan_time(rig, scan):
    """Virtual time (s) of the scan with Main.Scans = scan."""
    return (rig.plc.now_ns / 1e6 - (rig.read("Scans") - scan)) / 1000.0


def assert_every_mover_done_once_after_its_motion(tags, r, late=1.5):
    ends = motion_ends(tags, r)
    for k in range(1, 17):
        i = (r - 1) * 16 + k
        assert tags.read(f"Edges[{i}]") == 1 and tags.read(f"ErrorIDs[{i}]") == 0, (r, k)
        assert tags.read(f"DoneScan[{i}]") > 0, (r, k)
        done = scan_time(tags, tags.read(f"DoneScan[{i}]"))
        assert ends[k] <= done <= ends[k] + late, (r, k, ends[k], done)


def test_manual_13_2_sixteen_non_blended_motions_in_flight_complete_in_order_exactly_once(tags):
    start_all(tags)
    assert tags.until(lambda: all(ended(tags, i) for i in range(1, 17)), 30)
    assert_every_mover_done_once_after_its_motion(tags, 1, late=0.01)
    queries = [e for e in tags.srv.robots[0].events if e["kind"] == "frame_in" and e.get("data", "").startswith("01,")]
    assert queries == []                                    # every push arrived: no status query was needed


def test_manual_13_2_lost_pushes_are_made_good_by_the_next_push_or_a_query_of_a_tag_the_robot_still_knows(tags):
    tags.srv.robots[0].inject("corrupt_checksum", count=6, match=PUSH)       # the first six completions lost
    start_all(tags)
    assert tags.until(lambda: all(ended(tags, i) for i in range(1, 17)), 30)
    assert_every_mover_done_once_after_its_motion(tags, 1)
    assert tags.read("Cobot[1].BadFrames") == 6


def test_the_last_push_lost_is_recovered_by_a_status_query_after_one_second_of_silence(tags):
    tags.srv.robots[0].inject("corrupt_checksum", count=1, match=PUSH)
    tags.plc.write("Main.Exec[1]", True)
    assert tags.until(lambda: ended(tags, 1), 5)
    end = motion_ends(tags, 1)[1]
    done = scan_time(tags, tags.read("DoneScan[1]"))
    assert end < done <= end + 1.1 and done >= 1.0
    queried = [e["data"] for e in tags.srv.robots[0].events
               if e["kind"] == "frame_in" and e.get("data", "").startswith("01,")]
    assert queried == ["01,01"]


@pytest.mark.parametrize("tags", [{"robots": 4}], indirect=True)
def test_four_robots_sharing_nothing_each_with_sixteen_motions_and_lost_pushes(tags):
    for r, count in ((2, 3), (3, 16), (4, 1)):
        tags.srv.robots[r - 1].inject("corrupt_checksum", count=count, match=PUSH)
    start_all(tags)
    assert tags.until(lambda: all(ended(tags, i) for i in range(1, 65)), 60)
    for r in range(1, 5):
        assert_every_mover_done_once_after_its_motion(tags, r, late=2.5)


@pytest.mark.parametrize("tags", [{"speed": 20}], indirect=True)
def test_a_stop_in_the_middle_aborts_exactly_the_motions_it_cleared(tags):
    tags.srv.robots[0].inject("corrupt_checksum", count=2, match=PUSH)
    start_all(tags)
    assert tags.until(lambda: len(motion_ends(tags, 1)) == 5, 30)
    tags.plc.write("Main.StopPar[1].Mode", "StopImmediate")
    tags.plc.write("Main.StopExec[1]", True)
    assert tags.until(lambda: all(ended(tags, i) for i in range(1, 17)), 10)
    ends = motion_ends(tags, 1)
    assert len(ends) in (5, 6)
    for k in range(1, 17):
        if k in ends:
            assert tags.read(f"DoneScan[{k}]") > 0 and scan_time(tags, tags.read(f"DoneScan[{k}]")) >= ends[k], k
        else:
            assert tags.read(f"Aborted[{k}]") and tags.read(f"ErrorIDs[{k}]") == 0, k
        assert tags.read(f"Edges[{k}]") == 1, k
    tags.plc.write("Main.StopExec[1]", False)
    for k in range(1, 17):                          # the same movers again: tags were all given back
        tags.plc.write(f"Main.Exec[{k}]", False)
    tags.until(lambda: False, 0.01)
    for k in range(1, 17):
        tags.plc.write(f"Main.Exec[{k}]", True)
    assert tags.until(lambda: all(tags.read(f"mv[{k}].Done") for k in range(1, 17)), 60)


def test_a_stop_the_library_did_not_send_ends_waiting_motions_with_4004_never_done(tags):
    """Another client clears the queue: the last four tags answer 'none' (not existed), and the older ones
    were reached or cleared - the library cannot tell which, so none of them reports Done."""
    import socket

    from tmsim.protocol import codec
    tags.plc.write("Main.Speed", 20)
    start_all(tags)
    assert tags.until(lambda: len(motion_ends(tags, 1)) == 2, 30)
    other = socket.create_connection(("127.0.0.1", tags.srv.ports[0]))
    try:
        other.sendall(codec.encode("TMSCT", "X,StopAndClearBuffer(0)"))
        assert tags.until(lambda: all(ended(tags, i) for i in range(1, 17)), 10)
    finally:
        other.close()
    ends = motion_ends(tags, 1)
    for k in range(1, 17):
        if k in ends:
            assert tags.read(f"DoneScan[{k}]") > 0, k
        else:
            assert tags.read(f"DoneScan[{k}]") == 0 and tags.read(f"ErrorIDs[{k}]") == 0x4004, k
