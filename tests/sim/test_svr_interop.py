"""The Ethernet Slave read by the two public clients: techmanpy 1.2's TMSVR_client (unmodified, real time) and
a byte-faithful model of the official Techman ROS driver's SVR client (TechmanRobotInc/tmr_ros2, C++, not
buildable here): its packet parser (tm_packet.cpp TmPacket::build_packet_from_bytes, TmSvrData::
build_TmSvrData), its data-table reader (tm_robot_state.cpp TmDataTable and _deserialize_first_time, which
memcpy each known item into a fixed C field) and what it sends (tm_svr_communication.cpp send_stick_play,
tm_ros2_svr.cpp write_item / ask_item)."""
import asyncio
import math
import struct

import pytest
from sim_harness import Harness, sct

from tmsim.net.server import SimServer
from tmsim.protocol import codec

# tm_robot_state.h TmRobotStateData: the C field each item is copied into, its size in bytes, and whether the
# driver requires the item (TmDataTable: Item::NOT_REQUIRE marks the optional ones).
DRIVER_FIELDS = {
    "Robot_Link": (1, True), "Robot_Error": (1, True), "Project_Run": (1, True), "Project_Pause": (1, True),
    "Safeguard_A": (1, True), "ESTOP": (1, True), "Camera_Light": (1, True), "Error_Code": (4, True),
    "Joint_Angle": (24, True), "Coord_Robot_Flange": (24, True), "Coord_Robot_Tool": (24, True),
    "TCP_Force": (12, True), "TCP_Force3D": (4, True), "TCP_Speed": (24, True), "TCP_Speed3D": (4, True),
    "Joint_Speed": (24, True), "Joint_Torque": (24, True), "Joint_Torque_Average": (24, False),
    "Joint_Torque_Min": (24, False), "Joint_Torque_Max": (24, False), "Project_Speed": (4, True),
    "MA_Mode": (4, True), "Robot_Light": (4, True),
    **{f"Ctrl_DO{i}": (1, i < 8) for i in range(16)}, **{f"Ctrl_DI{i}": (1, i < 8) for i in range(16)},
    "Ctrl_AO0": (4, True), "Ctrl_AO1": (4, False), "Ctrl_AI0": (4, True), "Ctrl_AI1": (4, False),
    **{f"End_DO{i}": (1, True) for i in range(4)}, **{f"End_DI{i}": (1, i < 3) for i in range(4)},
    "End_AO0": (4, False), "End_AO1": (4, False), "End_AI0": (4, True), "End_AI1": (4, False),
}


def driver_packets(buf):
    """tm_packet.cpp TmPacket::build_packet_from_bytes (decimal length via std::stoi, ',' after the data, '*',
    two hex digits, CR LF), applied to the front of the receive buffer; complete packets are removed."""
    out = []
    while True:
        start = buf.find(b"$")
        if start < 0 or len(buf) - start < 9:
            return out
        del buf[:start]
        comma1 = buf.find(b",", 1)
        comma2 = buf.find(b",", comma1 + 1)
        if comma1 < 0 or comma2 < 0:
            return out
        length = int(buf[comma1 + 1:comma2])
        end = comma2 + 1 + length
        if len(buf) < end + 6:
            return out
        assert buf[end:end + 2] == b",*" and buf[end + 4:end + 6] == b"\r\n", "driver: end not valid"
        assert int(buf[end + 2:end + 4], 16) == codec.checksum(bytes(buf[1:end + 1])), "driver: checksum"
        out.append((buf[1:comma1].decode(), bytes(buf[comma2 + 1:end])))
        del buf[:end + 6]



class DriverSvrClient:
    """What tmr_ros2's TmSvrCommunication + TmRobotState do with the bytes of port 5891."""

    def __init__(self, peer):
        self.peer = peer
        self.buf = bytearray()
        self.fields = {}            # item -> raw bytes copied into the C field
        self.checked = set()
        self.responses, self.read_strings = [], []

    def pump(self):
        self.buf += b"".join(self.peer.raw_reads)
        self.peer.raw_reads.clear()
        for header, data in driver_packets(self.buf):
            assert header == "TMSVR", f"driver: invalid header {header}"
            self.svr_data(data)

    # tm_packet.cpp TmSvrData::build_TmSvrData: ID to the first ',', mode of one or two digits, then for
    # RESPONSE a two-digit error code and ','
    def svr_data(self, data):
        comma = data.index(b",")
        ident, pos = data[:comma].decode(), comma + 1
        if data[pos + 1:pos + 2] == b",":
            mode, pos = int(data[pos:pos + 1]), pos + 2
        else:
            assert data[pos + 2:pos + 3] == b",", "driver: mode must be one or two digits"
            mode, pos = int(data[pos:pos + 2]), pos + 3
        if mode == 0:
            self.responses.append((ident, int(data[pos:pos + 2]), data[pos + 3:].decode()))
        elif mode == 1:
            self.deserialize(data[pos:])
        elif mode == 12:
            self.read_strings.append((ident, data[pos:].decode()))
        else:
            raise AssertionError(f"driver: invalid mode ({mode})")

    # tm_robot_state.cpp _deserialize_first_time / _deserialize: u16 name length, name, u16 value length,
    # memcpy(value) into the item's field; unknown items are skipped
    def deserialize(self, content):
        pos = 0
        while pos < len(content):
            (n,) = struct.unpack_from("<H", content, pos)
            name = content[pos + 2:pos + 2 + n].decode()
            pos += 2 + n
            (n,) = struct.unpack_from("<H", content, pos)
            value = content[pos + 2:pos + 2 + n]
            pos += 2 + n
            if name in DRIVER_FIELDS:
                assert n <= DRIVER_FIELDS[name][0], f"{name}: {n} bytes overflow the driver's field"
                self.fields[name] = value
                self.checked.add(name)

    def data_table_correct(self):
        return all(name in self.checked for name, (_, required) in DRIVER_FIELDS.items() if required)

    def floats(self, name):
        raw = self.fields[name]
        return list(struct.unpack(f"<{len(raw) // 4}f", raw))

    def integer(self, name):
        return int.from_bytes(self.fields[name], "little", signed=True)

    def joint_states(self):
        """tm_ros2_svr.cpp publish_fbs: joint_states position = rads(Joint_Angle)."""
        return [math.radians(v) for v in self.floats("Joint_Angle")]

    # what the driver sends
    def send_content_str(self, ident, content):           # write_item, send_stick_play
        self.peer.send(codec.encode("TMSVR", f"{ident},2,{content}"))

    def ask_item(self, ident, item):                      # mode READ_STRING
        self.peer.send(codec.encode("TMSVR", f"{ident},12,{item}"))


@pytest.fixture
def h():
    harness = Harness(svr_port=0)              # the simulator's defaults: binary data table every 0.1 s
    yield harness
    harness.close()


def test_official_driver_reads_a_correct_data_table_and_joint_states_follow_the_listen_node(h):
    driver = DriverSvrClient(h.connect_svr())       # the driver connects 5891 first, then 5890
    h.run(0.25)
    driver.pump()
    assert driver.data_table_correct(), f"missing: {set(k for k, v in DRIVER_FIELDS.items() if v[1]) - driver.checked}"
    assert driver.joint_states() == pytest.approx([0, 0, math.pi / 2, 0, math.pi / 2, 0], abs=1e-6)
    assert driver.fields["Robot_Link"] == b"\x01" and driver.fields["Project_Run"] == b"\x01"
    assert driver.integer("MA_Mode") == 2 and driver.integer("Project_Speed") == 100
    node = h.connect()
    h.request(node, sct("0", 'PTP("JPP",30,-10,100,0,90,15,100,200,0,false)\r\nQueueTag(1)'), count=2)
    h.run(0.3)
    driver.pump()
    assert driver.joint_states() == pytest.approx([math.radians(v) for v in (30, -10, 100, 0, 90, 15)], abs=1e-5)
    pose = driver.floats("Coord_Robot_Tool")
    assert pose[:3] == pytest.approx(h.robot.state()["tcp_robot"][:3], abs=0.01)


def test_official_driver_stick_play_write_item_and_ask_item_are_answered(h):
    driver = DriverSvrClient(h.connect_svr())
    h.robot.stop_project()
    driver.send_content_str("Play", "Stick_PlayPause=1")          # send_stick_play()
    driver.send_content_str("w1", "Ctrl_DO3=1")                   # write_item(id, item, value)
    driver.ask_item("a1", "Ctrl_DO3")                             # ask_item(id, item)
    assert h.until(lambda: (driver.pump(), len(driver.read_strings))[1] >= 1, timeout=2)
    assert driver.responses[:2] == [("Play", 0, "OK"), ("w1", 0, "OK")]
    assert driver.read_strings == [("a1", "Ctrl_DO3=1")]
    assert h.robot.session.state == "in_node"
    assert h.until(lambda: (driver.pump(), driver.fields.get("Project_Run"))[1] == b"\x01", timeout=1)


def test_techmanpy_tmsvr_client_reads_writes_and_receives_the_broadcast():
    techmanpy = pytest.importorskip("techmanpy")
    srv = SimServer(port=0, svr_port=0, svr_options={"mode": 2, "period": 0.05})
    srv.start_background()

    class SVR(techmanpy.TMSVR_client):
        PORT = srv.robots[0].svr_port

    async def scenario():
        broadcasts = []
        async with SVR(robot_ip="127.0.0.1") as svr:
            joints = await svr.get_value("Joint_Angle")
            status = await svr.get_values(["Project_Run", "Error_Code", "Robot_Error"])
            await svr.set_value("Ctrl_DO2", 1)
            do2 = await svr.get_value("Ctrl_DO2")
            with pytest.raises(techmanpy.TMSVRError, match="Robot_Link"):
                await svr.set_value("Robot_Link", 1)
            with pytest.raises(techmanpy.TMSVRError, match="Joint_Angel"):
                await svr.get_value("Joint_Angel")
            svr.add_broadcast_callback(broadcasts.append)
            await svr.keep_alive(quit=lambda: len(broadcasts) >= 3)
        return joints, status, do2, broadcasts

    try:
        joints, status, do2, broadcasts = asyncio.run(asyncio.wait_for(scenario(), 20))
    finally:
        srv.close()
    assert joints == pytest.approx([0, 0, 90, 0, 90, 0])
    assert status == {"Project_Run": True, "Error_Code": 0, "Robot_Error": False}
    assert do2 == 1
    assert len(broadcasts) >= 3 and broadcasts[0]["Robot_Link"] == 1
    assert broadcasts[-1]["Joint_Angle"] == pytest.approx([0, 0, 90, 0, 90, 0])


class DriverSctClient:
    """tmr_ros2's Listen-node side (tm_listen_node_connect.cpp, tm_sct_communication.cpp): it reads port 5890
    only while the Ethernet Slave is connected, asks TMSTA 00 with empty data to learn whether the flow is in
    the node, sends scripts as TMSCT id,script and takes replies starting with OK / ERROR."""

    def __init__(self, peer, svr_driver):
        self.peer, self.svr = peer, svr_driver
        self.buf = bytearray()
        self.sct, self.sta = [], []

    def pump(self):
        if self.svr.peer.closed:                # while (sct.is_connected() && iface.svr.is_connected())
            return
        self.buf += b"".join(self.peer.raw_reads)
        self.peer.raw_reads.clear()
        for header, data in driver_packets(self.buf):
            text = data.decode()
            if header == "TMSCT":
                ident, _, script = text.partition(",")
                self.sct.append((ident, script))
            elif header == "TMSTA":
                self.sta.append(tuple(text.split(",", 1)))
            else:
                raise AssertionError(f"driver: {header} on the Listen node")

    def send_sta_request(self, subcmd, subdata=""):
        self.peer.send(codec.encode("TMSTA", f"{subcmd},{subdata}"))

    def send_script_str(self, ident, script):
        self.peer.send(codec.encode("TMSCT", f"{ident},{script}"))


def test_official_driver_sct_and_svr_together_move_the_arm_and_publish_its_joint_states(h):
    svr = DriverSvrClient(h.connect_svr())
    sct = DriverSctClient(h.connect(), svr)

    def pump():
        svr.pump()
        sct.pump()

    sct.send_sta_request("00")                                  # check_is_on_listen_node: ask_sta_struct("00", "")
    assert h.until(lambda: (pump(), sct.sta)[1], timeout=2)
    assert sct.sta[0] == ("00", "true,Listen1")                 # >> std::boolalpha reads "true"
    sct.send_script_str("Move", 'PTP("JPP",-20,15,70,5,90,10,100,200,0,false)\r\nQueueTag(7,1)')
    assert h.until(lambda: (pump(), sct.sct)[1], timeout=10)
    assert sct.sct[0] == ("Move", "OK")
    h.run(0.3)
    pump()
    assert svr.data_table_correct()
    assert svr.joint_states() == pytest.approx([math.radians(v) for v in (-20, 15, 70, 5, 90, 10)], abs=1e-5)
    sct.send_script_str("Exit", "ScriptExit()")                 # send_script_exit() when the driver stops
    assert h.until(lambda: (pump(), len(sct.sct))[1] >= 2, timeout=5)
    assert sct.sct[1] == ("Exit", "OK")
