"""32 robots from one program, each with its own stCBT_Connection, independent of each other."""
from rig import LIB, SEC, ST

from tmsim.net.server import SimServer
from vplc.api import load_plc


def test_thirty_two_robots_move_independently():
    srv = SimServer(host="127.0.0.1", port=0, robots=32, auto_enter=True)
    srv.start()
    # 32 connections need a controller with at least 32 TCP sockets (the virtual PLC emulates 30 by default)
    plc = load_plc([str(LIB), str(ST / "Main_Multi.st")], task="Main@1ms", socket_limit=32)
    try:
        pump = lambda now: srv.poll(now / 1e9)  # noqa: E731
        for i, port in enumerate(srv.ports, start=1):
            plc.write(f"Main.Ports[{i}]", port)
        plc.write("Main.ConnExec", True)
        assert plc.run_until(lambda: plc.read("Main.AllConnected"), 5 * SEC, on_scan=pump)
        srv.robots[7].inject("disconnect")
        for i in range(1, 33):
            plc.write(f"Main.MoveExec[{i}]", True)
        assert plc.run_until(lambda: all(plc.read(f"Main.movers[{i}].Done") or plc.read(f"Main.movers[{i}].Error")
                                         for i in range(1, 33)), 5 * SEC, on_scan=pump)
        assert plc.read("Main.movers[8].Error")
        # robot 8 alone lost its link, and got it back by itself (Execute held)
        assert plc.read("Main.conns[8].Reconnecting") or plc.read("Main.conns[8].RetryCount") >= 1
        assert all(not plc.read(f"Main.conns[{i}].Reconnecting") for i in range(1, 33) if i != 8)
        for i in range(1, 33):
            if i != 8:
                assert plc.read(f"Main.movers[{i}].Done")
                end = [e for e in srv.robots[i - 1].events if e["kind"] == "motion_end"]
                assert len(end) == 1 and end[0]["joints"][5] == float(i)
    finally:
        plc.close()
        srv.close()
