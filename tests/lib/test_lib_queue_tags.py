"""Non-blended completions under the robot's four-tag rule (TMscript 2.24 §13.2: the robot keeps the status
of the last four queue tags only): 16 motions in flight per robot, up to 4 robots, pushes lost to bad
checksums, and a stop in the middle. Every mover ends exactly once; Done never before its motion ended."""
import pytest
from rig import LIB, SEC, ST

from tmsim.net.server import SimServer
from vplc.api import load_plc

PUSH = "$TMSTA,10,01,"          # a tag push (and a TMSTA 01 'true' answer): 01,NN,true


class TagRig:
    def __init__(self, robots=1, speed=100):
        self.srv = SimServer(host="127.0.0.1", port=0, robots=robots, auto_enter=True)
        self.srv.start()
        self.plc = load_plc([str(LIB), str(ST / "Main_Tags.st")], task="Main@1ms")
        self.robots = robots
        for r, port in enumerate(self.srv.ports, start=1):
            self.plc.write(f"Main.Ports[{r}]", port)
        self.plc.write("Main.Robots", robots)
        self.plc.write("Main.Speed", speed)
        self.plc.write("Main.ConnExec", True)
        assert self.until(lambda: all(self.read(f"conns[{r}].Connected") for r in range(1, robots + 1)), 5)

    def read(self, path):
        return self.plc.read("Main." + path)

    def until(self, pred, seconds, on_scan=None):
        def hook(now_ns):
            self.srv.poll(now_ns / 1e9)
            if on_scan:
                on_scan(now_ns)
        return self.plc.run_until(pred, timeout_ns=int(seconds * SEC), on_scan=hook)

    def start_all(self):
        for i in range(1, 16 * self.robots + 1):
            self.plc.write(f"Main.Exec[{i}]", True)

    def ended(self, i):
        return self.read(f"Edges[{i}]") > 0

    def motion_ends(self, r):
        """{mover k: sim time (s) its motion ended} of robot r (mover k moves J6 to 5k degrees)."""
        return {round(e["joints"][5] / 5): e["t"] for e in self.srv.robots[r - 1].events if e["kind"] == "motion_end"}

    def scan_time(self, scan):
        """Virtual time (s) of the scan with Main.Scans = scan."""
        return (self.plc.now_ns / 1e6 - (self.read("Scans") - scan)) / 1000.0

    def close(self):
        self.plc.close()
        self.srv.close()


@pytest.fixture
def rig(request):
    r = TagRig(**getattr(request, "param", {}))
    yield r
    r.close()


def assert_every_mover_done_once_after_its_motion(rig, r, late=1.5):
    ends = rig.motion_ends(r)
    for k in range(1, 17):
        i = (r - 1) * 16 + k
        assert rig.read(f"Edges[{i}]") == 1 and rig.read(f"ErrorIDs[{i}]") == 0, (r, k)
        assert rig.read(f"DoneScan[{i}]") > 0, (r, k)
        done = rig.scan_time(rig.read(f"DoneScan[{i}]"))
        assert ends[k] <= done <= ends[k] + late, (r, k, ends[k], done)


def test_manual_13_2_sixteen_non_blended_motions_in_flight_complete_in_order_exactly_once(rig):
    rig.start_all()
    assert rig.until(lambda: all(rig.ended(i) for i in range(1, 17)), 30)
    assert_every_mover_done_once_after_its_motion(rig, 1, late=0.01)
    queries = [e for e in rig.srv.robots[0].events if e["kind"] == "frame_in" and e.get("data", "").startswith("01,")]
    assert queries == []                                    # every push arrived: no status query was needed


def test_manual_13_2_lost_pushes_are_made_good_by_the_next_push_or_a_query_of_a_tag_the_robot_still_knows(rig):
    rig.srv.robots[0].inject("corrupt_checksum", count=6, match=PUSH)       # the first six completions lost
    rig.start_all()
    assert rig.until(lambda: all(rig.ended(i) for i in range(1, 17)), 30)
    assert_every_mover_done_once_after_its_motion(rig, 1)
    assert rig.read("Cobot[1].BadFrames") == 6


def test_the_last_push_lost_is_recovered_by_a_status_query_after_one_second_of_silence(rig):
    rig.srv.robots[0].inject("corrupt_checksum", count=1, match=PUSH)
    rig.plc.write("Main.Exec[1]", True)
    assert rig.until(lambda: rig.ended(1), 5)
    end = rig.motion_ends(1)[1]
    done = rig.scan_time(rig.read("DoneScan[1]"))
    assert end < done <= end + 1.1 and done >= 1.0
    queried = [e["data"] for e in rig.srv.robots[0].events
               if e["kind"] == "frame_in" and e.get("data", "").startswith("01,")]
    assert queried == ["01,01"]


@pytest.mark.parametrize("rig", [{"robots": 4}], indirect=True)
def test_four_robots_sharing_nothing_each_with_sixteen_motions_and_lost_pushes(rig):
    for r, count in ((2, 3), (3, 16), (4, 1)):
        rig.srv.robots[r - 1].inject("corrupt_checksum", count=count, match=PUSH)
    rig.start_all()
    assert rig.until(lambda: all(rig.ended(i) for i in range(1, 65)), 60)
    for r in range(1, 5):
        assert_every_mover_done_once_after_its_motion(rig, r, late=2.5)


@pytest.mark.parametrize("rig", [{"speed": 20}], indirect=True)
def test_a_stop_in_the_middle_aborts_exactly_the_motions_it_cleared(rig):
    rig.srv.robots[0].inject("corrupt_checksum", count=2, match=PUSH)
    rig.start_all()
    assert rig.until(lambda: len(rig.motion_ends(1)) == 5, 30)
    rig.plc.write("Main.StopPar[1].Mode", "StopImmediate")
    rig.plc.write("Main.StopExec[1]", True)
    assert rig.until(lambda: all(rig.ended(i) for i in range(1, 17)), 10)
    ends = rig.motion_ends(1)
    assert len(ends) in (5, 6)
    for k in range(1, 17):
        if k in ends:
            assert rig.read(f"DoneScan[{k}]") > 0 and rig.scan_time(rig.read(f"DoneScan[{k}]")) >= ends[k], k
        else:
            assert rig.read(f"Aborted[{k}]") and rig.read(f"ErrorIDs[{k}]") == 0, k
        assert rig.read(f"Edges[{k}]") == 1, k
    rig.plc.write("Main.StopExec[1]", False)
    for k in range(1, 17):                          # the same movers again: tags were all given back
        rig.plc.write(f"Main.Exec[{k}]", False)
    rig.until(lambda: False, 0.01)
    for k in range(1, 17):
        rig.plc.write(f"Main.Exec[{k}]", True)
    assert rig.until(lambda: all(rig.read(f"mv[{k}].Done") for k in range(1, 17)), 60)


def test_a_stop_the_library_did_not_send_ends_waiting_motions_with_4004_never_done(rig):
    """Another client clears the queue: the last four tags answer 'none' (not existed), and the older ones
    were reached or cleared - the library cannot tell which, so none of them reports Done."""
    import socket

    from tmsim.protocol import codec
    rig.plc.write("Main.Speed", 20)
    rig.start_all()
    assert rig.until(lambda: len(rig.motion_ends(1)) == 2, 30)
    other = socket.create_connection(("127.0.0.1", rig.srv.ports[0]))
    try:
        other.sendall(codec.encode("TMSCT", "X,StopAndClearBuffer(0)"))
        assert rig.until(lambda: all(rig.ended(i) for i in range(1, 17)), 10)
    finally:
        other.close()
    ends = rig.motion_ends(1)
    for k in range(1, 17):
        if k in ends:
            assert rig.read(f"DoneScan[{k}]") > 0, k
        else:
            assert rig.read(f"DoneScan[{k}]") == 0 and rig.read(f"ErrorIDs[{k}]") == 0x4004, k
