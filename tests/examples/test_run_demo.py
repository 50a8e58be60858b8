"""`make demo` launcher: clear messages instead of tracebacks when it cannot start."""
from __future__ import annotations

import os
import pathlib
import socket
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
DEMO = ROOT / "examples" / "run_demo.py"


def run_demo(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(DEMO), *args], capture_output=True, text=True, timeout=60,
                          cwd=ROOT)


@pytest.fixture
def busy_port():
    holder = socket.socket()
    holder.bind(("127.0.0.1", 0))
    holder.listen(1)
    yield holder.getsockname()[1]
    holder.close()


def test_taken_robot_port_is_named_with_the_option_to_change_it(busy_port, free_port):
    result = run_demo("--robot-port", str(busy_port), "--hmi-port", str(free_port()))
    assert result.returncode == 2
    assert f"port {busy_port} on 127.0.0.1 (robot simulator) is already in use" in result.stderr
    assert "--robot-port PORT" in result.stderr and "Traceback" not in result.stderr


def test_taken_hmi_port_is_named_with_the_option_to_change_it(busy_port, free_port):
    result = run_demo("--robot-port", str(free_port()), "--hmi-port", str(busy_port))
    assert result.returncode == 2
    assert f"port {busy_port} on 127.0.0.1 (web HMI) is already in use" in result.stderr
    assert "--hmi-port PORT" in result.stderr and "Traceback" not in result.stderr


def test_bad_option_value_is_reported_by_the_argument_parser():
    result = run_demo("--hmi-port", "eighty")
    assert result.returncode == 2 and "invalid int value: 'eighty'" in result.stderr


def test_port_outside_the_tcp_range_is_refused():
    result = run_demo("--robot-port", "70000")
    assert result.returncode == 2 and "70000 is not a TCP port (1..65535)" in result.stderr


def start_demo(robot_port: int, hmi_port: int, svr_port: int, control_port: int, *extra: str):
    """The demo as `make demo` starts it (``extra``: further options); returns (process, banner text, queue of
    further stdout lines)."""
    import queue
    import threading
    demo = subprocess.Popen([sys.executable, str(DEMO), "--robot-port", str(robot_port), "--hmi-port",
                             str(hmi_port), "--svr-port", str(svr_port), "--control-port", str(control_port),
                             *extra],
                            stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=ROOT)
    lines: queue.Queue = queue.Queue()
    errors: list[str] = []                  # drained all the time: a full stderr pipe would block the demo
    threading.Thread(target=lambda: [lines.put(line) for line in demo.stdout], daemon=True).start()
    threading.Thread(target=lambda: errors.extend(demo.stderr), daemon=True).start()
    demo.errors = errors
    banner, waited = [], 0
    while not banner or not banner[-1].startswith("Press Ctrl-C"):
        try:
            banner.append(lines.get(timeout=1).strip())
        except queue.Empty:
            waited += 1
            if demo.poll() is not None or waited >= 60:
                demo.kill()
                raise AssertionError(f"no complete banner from the demo: {banner} {''.join(errors)}") from None
    return demo, "\n".join(banner), lines


def stop_demo(demo, lines) -> tuple[str, str]:
    import signal
    demo.send_signal(signal.SIGINT)
    try:
        demo.wait(timeout=60)
    except subprocess.TimeoutExpired:
        demo.kill()
        demo.wait(timeout=10)
        raise AssertionError("the demo did not stop within 60 s of Ctrl-C; it printed: "
                             f"{''.join(lines.queue)} {''.join(demo.errors)}") from None
    return "".join(lines.queue), "".join(demo.errors)


def control_request(port: int, request: dict) -> dict:
    import json
    with socket.create_connection(("127.0.0.1", port), timeout=5) as conn:
        conn.sendall(json.dumps(request).encode() + b"\n")
        return json.loads(conn.makefile().readline())


def wait_for_line(lines, text: str, timeout_s: float = 30.0) -> None:
    """Wait until the demo prints a line containing ``text`` (other lines may come first, in any order)."""
    import queue
    import time
    deadline, seen = time.monotonic() + timeout_s, []
    while not any(text in line for line in seen):
        try:
            seen.append(lines.get(timeout=max(0.0, deadline - time.monotonic())))
        except queue.Empty:
            raise AssertionError(f"the demo did not print {text!r} within {timeout_s} s; it printed {seen}") from None
    for line in seen:                 # stop_demo() reports everything the demo printed
        lines.put(line)


def test_demo_runs_everything_stops_cleanly_on_ctrl_c_and_starts_again_at_once(free_port):
    import json
    import urllib.request
    ports = [free_port() for _ in range(4)]        # reserved: four different ports
    robot_port, hmi_port, svr_port, control_port = ports
    for attempt in range(2):          # the second start follows at once: the first one's connections in TIME_WAIT
        demo, text, lines = start_demo(robot_port, hmi_port, svr_port, control_port)
        try:
            assert f"1 robot on 127.0.0.1:{robot_port}" in text and "1 ms task" in text
            assert f"http://127.0.0.1:{hmi_port}/" in text
            assert f"control channel   127.0.0.1:{control_port}, the simulator's JSON-line requests" in text
            url = f"http://127.0.0.1:{hmi_port}/api/read?names=PnP_Segment"
            with urllib.request.urlopen(url, timeout=5) as r:
                assert json.loads(r.read())["ok"] is True
            with socket.create_connection(("127.0.0.1", robot_port), timeout=5):
                pass
            answer = control_request(control_port, {"cmd": "state", "robot": 0})
            assert answer["ok"] is True and answer["result"]["port"] == robot_port, answer
            if attempt == 0:
                # the command printed for the user, pasted into a shell as it is, stops the robot's project
                pasted = [line for line in text.splitlines() if line.startswith("python3 -c ")]
                assert len(pasted) == 1, text
                shell = subprocess.run(["sh", "-c", pasted[0]], capture_output=True, text=True, timeout=30)
                assert json.loads(shell.stdout) == {"ok": True, "result": None}, (shell.stdout, shell.stderr)
                wait_for_line(lines, "robot 1: project stopped")
                assert control_request(control_port, {"cmd": "state"})["result"]["project_running"] is False
        finally:
            out, err = stop_demo(demo, lines)
        assert demo.returncode == 0, (attempt, demo.returncode, out, err)
        assert "Demo stopped" in out and "Traceback" not in err


def test_taken_control_port_is_named_and_two_servers_on_one_port_are_refused(busy_port, free_port):
    result = run_demo("--robot-port", str(free_port()), "--svr-port", str(free_port()), "--hmi-port",
                      str(free_port()), "--control-port", str(busy_port))
    assert result.returncode == 2
    assert f"port {busy_port} on 127.0.0.1 (simulator control channel) is already in use" in result.stderr
    assert "--control-port PORT" in result.stderr and "Traceback" not in result.stderr
    port = free_port()
    result = run_demo("--robot-port", str(free_port()), "--svr-port", str(free_port()), "--hmi-port", str(port),
                      "--control-port", str(port))
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert f"--hmi-port and --control-port are both {port}; give each server its own port." in result.stderr


def test_control_port_defaults_to_the_port_before_the_robots_or_any_free_one(busy_port, free_port):
    """As the simulator's command line derives it: 5889 for 5890; 0 (any free port, printed) when that one is taken or
    is one of the demo's own ports."""
    from cbt_hmi.demo import default_control_port
    port = free_port()
    assert default_control_port(port + 1, ()) == port              # reserved for this test: nobody took it
    assert default_control_port(busy_port + 1, ()) == 0
    assert default_control_port(port + 1, (port,)) == 0
    assert default_control_port(1, ()) == 0


def test_taken_port_names_the_process_that_holds_it(busy_port, free_port):
    import os
    result = run_demo("--robot-port", str(free_port()), "--hmi-port", str(busy_port), "--svr-port", str(free_port()))
    assert result.returncode == 2
    assert f"is already in use by process {os.getpid()} (" in result.stderr


def test_robot_side_events_print_one_console_line_each():
    """The demo prints one line per robot-side event: a robot error, the project stopped and started, the flow
    leaving and entering the Listen node, a stick button pressed through the Ethernet Slave."""
    from cbt_hmi.demo import robot_event_line
    from tmsim.net.server import SimServer

    sim = SimServer(port=0, robots=1, svr_port=0)
    sim.start()
    try:
        robot = sim.robots[0]
        start = len(robot.events)
        robot.leave_listen_node()
        robot.enter_listen_node()
        robot.session.fire("robot_fault", reason="Line: target pose is out of reach")
        robot.start_project()
        robot.svr_source.write({"Stick_Stop": 1})
        lines = [line for line in map(robot_event_line, robot.events[start:]) if line]
    finally:
        sim.close()
    texts = [line.split(": ", 1)[1] for line in lines]
    assert texts == ["flow left the Listen node (Pass exit)", "flow entered the Listen node",
                     "robot error: Line: target pose is out of reach - project stopped", "project started",
                     "flow entered the Listen node", "stick button Stop pressed through the Ethernet Slave",
                     "project stopped"]
    assert all(line.startswith("[") and "] robot 1: " in line for line in lines)


CELL_PAGE = """{
  "title": "Gripper Cell",
  "status": [
    {"variable": "PnP_GripperClosed", "label": "Gripper closed"},
    {"variable": "PnP_CycleCount", "label": "Cycles done"}
  ]
}
"""


def test_demo_serves_the_users_page_descriptions_next_to_the_shipped_pages(tmp_path, free_port):
    """--pages DIR: the good page is served (Main lists it, its address answers, its values are read); a page with
    an unknown variable and one writing a variable of the shipped pages are named with file and line, and left
    out; the demo runs on."""
    import json
    import urllib.request
    (tmp_path / "gripper.json").write_text(CELL_PAGE)
    (tmp_path / "typo.json").write_text('{"title": "Typo",\n "status": [{"variable": "PnP_CycleCont", '
                                        '"label": "Cycles"}]}\n')
    (tmp_path / "taken.json").write_text('{"title": "Taken", "command": {"variable": "Connect_Execute", '
                                         '"label": "Connect"}}\n')
    ports = [free_port() for _ in range(4)]        # reserved: four different ports
    demo, text, lines = start_demo(*ports, "--pages", str(tmp_path))
    hmi = f"http://127.0.0.1:{ports[1]}"
    try:
        assert f"Your pages from {tmp_path}: gripper" in text, text
        with urllib.request.urlopen(hmi + "/api/mapping", timeout=5) as r:
            table = json.loads(r.read())
        assert list(table["custom_pages"]) == ["gripper"]
        assert {"gripper", "pnp", "stop"} <= set(table["pages"])
        with urllib.request.urlopen(hmi + "/gripper.html", timeout=5) as r:
            assert r.status == 200
        with urllib.request.urlopen(hmi + "/api/read?names=PnP_CycleCount,PnP_GripperClosed", timeout=5) as r:
            assert json.loads(r.read())["ok"] is True
    finally:
        out, err = stop_demo(demo, lines)
    assert demo.returncode == 0, (out, err)
    assert f"error: {tmp_path / 'typo.json'}:2: unknown variable 'PnP_CycleCont'" in err, err
    assert f"error: {tmp_path / 'taken.json'}: 'Connect_Execute' belongs to the shipped pages" in err, err
    assert "Traceback" not in err


def test_demo_pages_option_names_a_missing_folder():
    result = run_demo("--pages", "no/such/folder")
    assert result.returncode == 2
    assert "error: --pages no/such/folder: not a folder of page description files" in result.stderr
    assert "Traceback" not in result.stderr


@pytest.mark.parametrize("command", ["demo", "cell"])
def test_an_empty_host_is_a_usage_error_not_every_interface(command, capsys):
    """--host "$HOST" with HOST unset bound 0.0.0.0 while the start-up line said 127.0.0.1."""
    from cbt_hmi import demo
    from cbt_hmi.web import cell
    parse = demo.parse_args if command == "demo" else lambda argv: cell.parse_args([*argv, "--pages", ".", "x.st"])
    with pytest.raises(SystemExit) as stopped:
        parse(["--host", ""])
    assert stopped.value.code == 2
    assert "argument --host: an address is needed: 127.0.0.1 for this computer only, 0.0.0.0 for every " \
           "interface" in capsys.readouterr().err
    assert parse(["--host", "0.0.0.0"]).host == "0.0.0.0"


def test_an_alarm_log_that_is_a_pipe_a_device_or_a_folder_is_a_usage_error(tmp_path, capsys):
    """A pipe held the start-up for ever (the history is read first), /dev/zero filled the memory."""
    from cbt_hmi import demo
    os.mkfifo(tmp_path / "pipe.jsonl")
    for given in (tmp_path / "pipe.jsonl", "/dev/zero", tmp_path, ""):
        with pytest.raises(SystemExit) as stopped:
            demo.parse_args(["--alarm-log", str(given)])
        assert stopped.value.code == 2 and "is not a regular file; name a file" in capsys.readouterr().err
    assert demo.parse_args(["--alarm-log", str(tmp_path / "new.jsonl")]).alarm_log == str(tmp_path / "new.jsonl")
