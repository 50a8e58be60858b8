"""A small stand-in for the Contract A PLC object: read/write/var_type/lock/now_ns over the mapped variables.

Used by the HTTP API tests so they do not depend on the ST toolchain. Values live in nested dicts/lists
built from hmi/mapping.json; scan() advances the clock and runs an optional program callback.
"""
from __future__ import annotations

import contextlib
import re
import threading
import time

from cbt_hmi.web.mapping import INT_RANGES, Mapping

_STEP = re.compile(r"\.?([A-Za-z_]\w*)|\[(\d+)\]")


def _default(type_name: str, types: dict):
    definition = types.get(type_name)
    if definition and "fields" in definition:
        return {name: _default(spec["type"], types) for name, spec in definition["fields"].items()}
    if definition and "enum" in definition:
        return min(definition["enum"].values())
    if type_name == "BOOL":
        return False
    if type_name in ("REAL", "LREAL"):
        return 0.0
    if type_name.startswith("STRING"):
        return ""
    if type_name in ("DATE_AND_TIME", "DT"):
        return 0
    return 0


class FakePlc:
    def __init__(self, mapping: Mapping, program=None):
        self.lock = threading.RLock()
        self.now_ns = 0
        self.period_ns = 1_000_000
        self.task_cycles = (0,)
        self.scans = 0
        self.task_every = 1               # the task runs in every n-th scan only
        self.program = program
        self.writes: list[tuple[str, object]] = []
        # command_program's memory: the Execute each group's fake FB saw in the last scan (a group set TRUE here
        # with its Execute TRUE is "held": no rising edge, the fake FB does nothing)
        self.executes_seen: dict[str, bool] = {}
        types = mapping.document["types"]
        self.vars = {}
        self.types = {}
        for name, spec in mapping.document["variables"].items():
            if "array" in spec:
                low, high = spec["array"]
                self.vars[name] = [_default(spec["type"], types) for _ in range(low, high + 1)]
            else:
                self.vars[name] = _default(spec["type"], types)
        for path, leaf in mapping.leaves.items():
            self.types[path] = leaf.type
        # the Execute variables command_program answers (looked for once: a scan every millisecond searching the
        # whole table cost the stand-in PLC ~7 % of a core)
        self.execute_names = [n for n in self.vars if n.endswith("_Execute") and n != "PnP_Example_Execute"]

    @property
    def fault(self):
        """Like vplc's Plc.fault: the major fault, None while it scans (a test faults it with plc.engine)."""
        return getattr(getattr(self, "engine", None), "fault", None)

    def _walk(self, path: str):
        steps = [m.group(1) if m.group(1) else int(m.group(2)) for m in _STEP.finditer(path)]
        container, key = self.vars, steps[0]
        if key not in container:
            raise KeyError(f"unknown variable '{path}'")
        for step in steps[1:]:
            container, key = container[key], step
        return container, key

    def read(self, path: str):
        with self.lock:
            container, key = self._walk(path)
            return container[key]

    def write(self, path: str, value) -> None:
        with self.lock:
            kind = self.types.get(path)
            if kind is None:
                raise ValueError(f"'{path}' is not a writable scalar")
            if kind in INT_RANGES and not isinstance(value, int):
                raise ValueError(f"'{path}' expects an integer")
            container, key = self._walk(path)
            container[key] = value
            self.writes.append((path, value))

    def var_type(self, path: str) -> str:
        if path not in self.types:
            raise KeyError(f"unknown variable '{path}'")
        return self.types[path]

    def scan(self, now_ns: int | None = None) -> None:
        with self.lock:
            self.now_ns = self.now_ns + self.period_ns if now_ns is None else now_ns
            self.scans += 1
            if self.scans % self.task_every:
                return                      # like the engine: the clock moved but the task was not due
            if self.program:
                self.program(self)
            self.task_cycles = (self.task_cycles[0] + 1,)


def command_program(plc: FakePlc) -> None:
    """Every <Group>_Execute rising edge turns into Done on the next scan, like a quick FB."""
    state = plc.executes_seen
    for name in plc.execute_names:
        group = name[: -len("_Execute")]
        execute = plc.vars[name]
        if execute and not state.get(group):
            plc.vars[f"{group}_Busy"] = True
            if f"{group}_CmdID_Ack" in plc.vars:
                plc.vars[f"{group}_CmdID_Ack"] += 1
        elif execute and plc.vars.get(f"{group}_Busy"):
            plc.vars[f"{group}_Busy"] = False
            if f"{group}_Done" in plc.vars:
                plc.vars[f"{group}_Done"] = True
            if group == "Connect":
                plc.vars["Connect_Connected"] = True
        elif not execute:
            if f"{group}_Done" in plc.vars:
                plc.vars[f"{group}_Done"] = False
            if group == "Connect":
                plc.vars["Connect_Connected"] = False
        state[group] = execute


def scan_every(plc: FakePlc, stop: threading.Event, period_s: float = 0.001) -> None:
    """Scan ``plc`` every ``period_s`` (wall clock) until ``stop`` is set. A plain sleep between the scans: waiting on
    the Event with a timeout, and looking for the Execute variables in every scan, made the stand-in PLC cost 6.7 %
    of a core, 2.9 % now."""
    while not stop.is_set():
        time.sleep(period_s)
        plc.scan()


@contextlib.contextmanager
def scanning(plc: FakePlc, period_s: float = 0.001):
    """The fake PLC scanning in a thread (wall clock) while the block runs."""
    stop = threading.Event()

    thread = threading.Thread(target=scan_every, args=(plc, stop, period_s), daemon=True)
    thread.start()
    try:
        yield plc
    finally:
        stop.set()
        thread.join(timeout=5)


@contextlib.contextmanager
def serving(plc, mapping):
    """An HMI server for ``plc`` on an ephemeral loopback port while the block runs."""
    from cbt_hmi.web.server import HmiServer
    server = HmiServer(plc, mapping, port=0)
    server.start()
    try:
        yield server
    finally:
        server.stop()


class ConnectedStack:
    """The stand-in PLC scanning every millisecond with a robot connected in its Listen node (project running, auto
    mode, speed 100 %), and an HMI server on it; ``server_options()`` gives the server's keyword arguments at each
    start (a test that restarts the server on the same port calls ``start_server(port)``)."""

    def __init__(self, port: int = 0):
        self.mapping = Mapping.load()
        self.plc = FakePlc(self.mapping, command_program)
        self.plc.vars.update(Connect_Execute=True, Connect_Connected=True, Robot_InListenNode=True,
                             RobotStatus_Valid=True)
        self.plc.vars["RobotStatus"].update(ProjectRunning=True, AutoMode=True, ProjectSpeed=100)
        self.plc.executes_seen = {"Connect": True}
        self.stop_scanning = threading.Event()
        self.thread = threading.Thread(target=self._scan, daemon=True)
        self.thread.start()
        self.start_server(port)

    def _scan(self) -> None:
        scan_every(self.plc, self.stop_scanning)

    def server_options(self) -> dict:
        return {}

    def start_server(self, port: int = 0) -> None:
        from cbt_hmi.web.server import HmiServer
        self.server = HmiServer(self.plc, self.mapping, port=port, **self.server_options())
        self.server.start()

    def set(self, **values) -> None:
        """Write variables of the stand-in PLC; ``RS_<member>`` is a member of RobotStatus."""
        with self.plc.lock:
            for name, value in values.items():
                if name.startswith("RS_"):
                    self.plc.vars["RobotStatus"][name[3:]] = value
                else:
                    self.plc.vars[name] = value

    def close(self) -> None:
        self.server.stop()
        self.stop_scanning.set()
        self.thread.join(timeout=5)
