"""The HMI's alarm system, kept by the server, the controller side (ISA-18.2), not by each browser tab.

A thread samples the PLC every PERIOD_S (under plc.lock for the few variables it needs, between two scans) and
turns what it reads into alarms:

* one alarm per cause, ranked: PLC fault or stalled, E-stop, robot error, robot project stopped, robot outside
  its Listen node, link to the robot lost, a command that failed. A condition that comes while a higher-ranked
  alarm is active is a consequence: it becomes a detail of that alarm, not an alarm of its own. One that lasts
  after its cause has gone stays a detail if it clears by itself (the link reconnecting after Play: it can raise
  an alarm again only after it has cleared); one that waits for the operator (the robot error an E-stop leaves
  until Play) becomes an alarm of its own once no higher-ranked cause is active. Consequences wait
  ON_DELAY_S before they are raised (ISA-18.2 on-delay), so a cause seen a moment later still takes them; the
  first alarm of an episode (raised while no other alarm is listed) is marked first-out.
* states: active-unacknowledged, active-acknowledged, returned-unacknowledged, normal (acknowledged and gone:
  off the list, in the history). A condition alarm follows the process: it returns when its cause is gone,
  whatever the pages do with a command's Execute. A failed command is an event: it is raised returned (its
  Error stays TRUE only because the page holds Execute), and an ErrorID the table marks "message" (a refused
  start: a parameter out of range, not connected, a stop held) is no alarm at all: the page shows it on its
  message line.
* timestamps from the server's clock (the controller side; date and 24-hour time), never the browser's.
* acknowledge is a request to the server: every panel sees it, a page reload keeps it.
* a history of HISTORY entries, appended to a JSON-lines file by a writer thread of its own (neither a scan nor
  a request ever waits for the disk) and read back at start-up, so it survives a browser and a server restart.

Texts: the ErrorIDs' operator remedies come from cbt_hmi/pages/errors.json (generated from docs/library/errors.tsv); the
causes without an ErrorID (PLC, E-stop) have theirs in CAUSES below.
"""
from __future__ import annotations

import json
import logging
import pathlib
import queue
import re
import threading
import time
from collections import deque
from dataclasses import dataclass, field

from .mapping import HMI_DIR

log = logging.getLogger("cbt_hmi.web")

PERIOD_S = 0.1          # sampling period of the alarm thread
ON_DELAY_S = 0.5        # a consequence waits this long for its cause before it is raised on its own
STALL_S = 1.0           # the PLC's tasks completed no cycle for this long: "PLC not scanning"
LOCK_WAIT_S = 0.5       # plc.lock not free for this long: "PLC not answering"
HISTORY = 1000          # history entries kept (and read back from the file at start-up)
MAX_HISTORY_FILE_BYTES = 16 * 1024 * 1024    # the file holds at most 2 x HISTORY entries of well under 1 KiB each
MAX_DETAILS = 20        # consequences kept per alarm
MAX_LISTED = 200        # alarms listed at most: beyond, the oldest returned ones leave the list unacknowledged

PRIORITIES = {1: "high", 2: "medium", 3: "low"}

# key: (rank, priority, source, text, operator remedy). The rank orders causes before their consequences.
CAUSES = {
    "plc": (0, 1, "PLC", "PLC stopped: {what}",
            "Call the maintenance engineer: the PLC must be restarted. The values shown are not valid."),
    "estop": (1, 1, "Robot", "Emergency stop pressed",
              "Make the cell safe, release the emergency stop, then press Play on the Main screen."),
    "robot": (2, 1, "Robot", "Robot error {code}: {what}", None),                       # remedy: 16#4006
    "project": (3, 2, "Robot", "Robot project stopped", None),                          # remedy: 16#4007
    "listen": (4, 2, "Robot", "The robot left the Listen node: commands from the PLC are refused", None),  # 16#4002
    "link": (5, 2, "Connection", "{lost}{attempt}{reason}", None),                     # remedy: its ErrorID
}
CLEARS_BY_ITSELF = {"link"}          # CBT_Connect reconnects by itself; the other causes wait for the operator
COMMAND_RANK, COMMAND_PRIORITY = 6, 3
REMEDY_IDS = {"robot": 0x4006, "project": 0x4007, "listen": 0x4002}

# [group, source shown]: every command FB the variable table feeds; the link's own errors are the "link" alarm
COMMANDS = [("PnP_Move", "PnP sequence"), ("Project", "Project control"), ("ChangeBase", "Change Base"),
            ("ChangeTCP", "Change TCP"), ("MoveRel", "Move Relative"), ("MoveAbs", "Move Absolute"),
            ("MoveCircle", "Move Circle"), ("ProgramControl", "Pause / Resume"), ("SetOutput", "Digital Output"),
            ("Stop", "Stop Motion")]
STATUS = ["Connect_Execute", "Connect_Connected", "Connect_Reconnecting", "Connect_RetryCount", "Connect_Error",
          "Connect_ErrorID", "Connect_ErrorDescrip", "Robot_InListenNode", "Robot_LastErrorID", "RobotStatus_Valid",
          "RobotStatus"]


def id_text(error_id: int) -> str:
    return f"16#{error_id:04X}"


FB_NAME = re.compile(r"\bCBT_\w")


def operator_text(descrip: str | None) -> str:
    """An FB's ErrorDescrip as the operator reads it: up to the clause that names a function block ("Robot not
    connected: CBT_Connect is retrying ..." -> "Robot not connected"); the operator remedy says what to do. The pages'
    operatorText (alarms.js) is the same rule."""
    text = descrip or ""
    found = FB_NAME.search(text)
    if found is None:
        return text
    cut = text.rfind(": ", 0, found.start())
    return text[:cut] if cut > 0 else ""


def stamp(seconds: float) -> str:
    """Date and 24-hour time of the server's clock (local time), to the millisecond."""
    return time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(seconds)) + f".{int(seconds * 1000) % 1000:03d}"


def plc_fault(plc) -> dict | None:
    """The PLC's major fault, None while it can scan: {"message": the controller's whole text, "what": the
    cause alone (after "major fault in <instance>: ")}. vplc's Plc.fault holds it from the scan that faulted on;
    the PLC no longer scans, its variables keep the values of that moment and its sockets are closed. A PLC
    stand-in without a fault property never faults."""
    fault = getattr(plc, "fault", None)
    if fault is None:
        return None
    message = str(fault)
    what = message.partition(": major fault in ")[2].partition(": ")[2]
    return {"message": message, "what": what or message}


@dataclass
class Alarm:
    number: int
    key: str
    rank: int
    priority: int
    source: str
    text: str
    remedy: str
    raised: float
    error_id: int = 0
    active: bool = True
    acked: bool = False
    returned: float | None = None
    first_out: bool = False
    details: list = field(default_factory=list)

    @property
    def state(self) -> str:
        if self.active:
            return "active-acknowledged" if self.acked else "active-unacknowledged"
        return "normal" if self.acked else "returned-unacknowledged"

    def as_json(self) -> dict:
        return {"number": self.number, "key": self.key, "priority": PRIORITIES[self.priority],
                "rank": self.rank, "source": self.source, "text": self.text, "remedy": self.remedy,
                "id": id_text(self.error_id) if self.error_id else "", "time": stamp(self.raised),
                "returned": stamp(self.returned) if self.returned is not None else "", "state": self.state,
                "first_out": self.first_out, "details": list(self.details)}


class History:
    """The newest HISTORY entries in memory and in a JSON-lines file written by a thread of its own."""

    def __init__(self, path: pathlib.Path | str | None):
        self.path = pathlib.Path(path) if path else None
        self.entries: deque[dict] = deque(maxlen=HISTORY)
        self._queue: queue.SimpleQueue = queue.SimpleQueue()
        self._lines = 0
        self._thread: threading.Thread | None = None
        if self.path is not None and self.path.is_file():       # a pipe or a device is not read (the demo refuses it)
            self._load(self.path)

    def _load(self, path: pathlib.Path) -> None:
        try:
            with path.open("rb") as fh:
                data = fh.read(MAX_HISTORY_FILE_BYTES + 1)
            if len(data) > MAX_HISTORY_FILE_BYTES:      # not a file this history wrote (it keeps 2 x HISTORY lines)
                raise ValueError(f"larger than {MAX_HISTORY_FILE_BYTES // 1048576} MiB")
            lines = data.decode("utf-8").splitlines()
        except (OSError, UnicodeDecodeError, ValueError) as exc:
            log.warning("HMI alarm history %s not read (%s): starting a new one", path, exc)
            return
        for number, line in enumerate(lines, start=1):
            try:
                entry = json.loads(line)
            except json.JSONDecodeError:
                log.warning("%s:%d: not a history entry (skipped)", path, number)
                continue
            # entries numbered in order only: a rewrite of the file may have left an entry twice at its end
            if isinstance(entry, dict) and isinstance(entry.get("n"), int) and \
                    (not self.entries or entry["n"] > self.entries[-1]["n"]):
                self.entries.append(entry)
        self._lines = len(lines)

    @property
    def last_numbers(self) -> tuple[int, int]:
        """(the last entry number, the last alarm number) in the history read back."""
        return (max((e["n"] for e in self.entries), default=0),
                max((e.get("alarm", 0) for e in self.entries if isinstance(e.get("alarm"), int)), default=0))

    def add(self, entry: dict) -> None:
        self.entries.append(entry)
        if self.path is not None:
            self._queue.put(entry)

    def start(self) -> None:
        if self.path is not None:
            self._thread = threading.Thread(target=self._write, args=(self.path,), name="hmi-alarm-history",
                                            daemon=True)
            self._thread.start()

    def stop(self) -> None:
        if self._thread is not None:
            self._queue.put(None)
            self._thread.join(timeout=5)
            self._thread = None

    def _write(self, path: pathlib.Path) -> None:
        """Appends the entries as they come; past twice HISTORY lines the file is rewritten with the kept ones."""
        path.parent.mkdir(parents=True, exist_ok=True)
        while True:
            batch = [self._queue.get()]
            while not self._queue.empty():
                batch.append(self._queue.get())
            done = None in batch
            batch = [e for e in batch if e is not None]
            try:
                if self._lines + len(batch) > 2 * HISTORY:
                    kept = list(self.entries)
                    temporary = path.with_suffix(".tmp")
                    temporary.write_text("".join(json.dumps(e) + "\n" for e in kept), encoding="utf-8")
                    temporary.replace(path)
                    self._lines = len(kept)
                elif batch:
                    with path.open("a", encoding="utf-8") as out:
                        out.write("".join(json.dumps(e) + "\n" for e in batch))
                    self._lines += len(batch)
            except OSError as exc:
                log.warning("HMI alarm history not written to %s: %s", path, exc)
            if done:
                return


class AlarmSystem:
    """Alarms of one PLC. start() samples in a thread; sample() takes one sample (tests call it directly)."""

    def __init__(self, plc, mapping, history_path: pathlib.Path | str | None = None, clock=time.time,
                 monotonic=time.monotonic, errors: dict | None = None):
        self.plc, self.clock, self.monotonic = plc, clock, monotonic
        self.errors = errors if errors is not None else _load_errors()
        self.history = History(history_path)
        self.entry_number, self.alarm_number = self.history.last_numbers
        self.status = [name for name in STATUS if mapping.is_readable(name)]
        self.commands = [(g, s) for g, s in COMMANDS
                         if all(mapping.is_readable(f"{g}_{x}") for x in ("Error", "ErrorID", "ErrorDescrip"))]
        self.names = self.status + [f"{g}_{x}" for g, _ in self.commands for x in ("Error", "ErrorID", "ErrorDescrip")]
        self.alarms: dict[int, Alarm] = {}          # not normal yet: active or unacknowledged
        self.seq = 0                               # changes with every change of the alarm list
        self.robot_state = "unknown"
        self._lock = threading.Lock()
        self._pending: dict[str, float] = {}        # consequence key -> when its condition was first seen
        self._absorbed: set[str] = set()            # consequences shown as a cause's details, until they clear
        self._events: list[tuple[float, dict]] = []  # failed commands waiting for their cause
        self._errors_seen: dict[str, tuple[bool, int]] = {}
        self._was_connected = False                # a retry before the first connect is no "lost" link
        self._cycles: tuple | None = None
        self._cycles_since = monotonic()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def forget_connection(self) -> None:
        """From now on, until the robot is connected again, a connect that fails is "Not connected to the robot"
        (retrying), not "Connection to the robot lost": for a PLC whose program was restarted (a new first
        connect) while the HMI kept running."""
        self._was_connected = False

    # --- sampling ------------------------------------------------------------------------------
    def start(self) -> None:
        self.history.start()
        self._thread = threading.Thread(target=self._run, name="hmi-alarms", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2)
        self.history.stop()

    def _run(self) -> None:
        while not self._stop.wait(PERIOD_S):
            try:
                self.sample()
            except Exception:
                log.exception("HMI alarm sample failed")

    def _read(self) -> tuple[dict | None, dict | None, tuple | None]:
        if not self.plc.lock.acquire(timeout=LOCK_WAIT_S):
            return None, None, None
        try:
            values = {}
            for name in self.names:
                try:
                    values[name] = self.plc.read(name)
                except (KeyError, ValueError, TypeError):
                    values[name] = None
            return values, plc_fault(self.plc), tuple(getattr(self.plc, "task_cycles", ()))
        finally:
            self.plc.lock.release()

    def sample(self) -> None:
        values, fault, cycles = self._read()
        now, mono = self.clock(), self.monotonic()
        conditions = {}
        if values is None:
            conditions["plc"] = self._cause("plc", what="not answering (its program holds the CPU)")
        elif fault is not None:
            conditions["plc"] = self._cause("plc", what=fault["what"])
        else:
            if cycles != self._cycles:
                self._cycles, self._cycles_since = cycles, mono
            elif cycles and mono - self._cycles_since > STALL_S:
                conditions["plc"] = self._cause("plc", what=f"its tasks completed no cycle for {STALL_S:g} s")
            conditions.update(self._robot_conditions(values))
        with self._lock:
            self._update(conditions, values if values is not None and fault is None else None, now, mono)

    def _cause(self, key: str, error_id: int = 0, **words) -> dict:
        rank, priority, source, text, remedy = CAUSES[key]
        if remedy is None:
            remedy = self.operator_remedy(error_id or REMEDY_IDS.get(key, 0))
        return {"rank": rank, "priority": priority, "source": source, "text": text.format(**words),
                "remedy": remedy, "error_id": error_id}

    def operator_remedy(self, error_id: int) -> str:
        row = self.errors.get(id_text(error_id)) if error_id else None
        return row.get("operator", "") if row else ""

    def _robot_conditions(self, v: dict) -> dict:
        out = {}
        rs = v.get("RobotStatus") if v.get("RobotStatus_Valid") else None
        executing, connected = v.get("Connect_Execute") is True, v.get("Connect_Connected") is True
        self._was_connected = self._was_connected or connected
        if rs:
            if rs.get("EStop"):
                out["estop"] = self._cause("estop")
            if rs.get("RobotError"):
                code = int(rs.get("ErrorCode") or 0) & 0xFFFFFFFF
                out["robot"] = self._cause("robot", code=f"16#{code:08X}", what=rs.get("ErrorText") or "")
            elif executing and rs.get("ProjectStopped") and not rs.get("ProjectRunning"):
                out["project"] = self._cause("project")
        if executing and connected and v.get("Robot_InListenNode") is False:
            out["listen"] = self._cause("listen")
        if executing and not connected and (v.get("Connect_Reconnecting") or v.get("Connect_Error")):
            error_id = int(v.get("Connect_ErrorID") or 0) or int(v.get("Robot_LastErrorID") or 0)
            row = self.errors.get(id_text(error_id), {}) if error_id else {}
            reason = operator_text(v.get("Connect_ErrorDescrip") if v.get("Connect_Error") else row.get("text", ""))
            attempt = f" (attempt {v['Connect_RetryCount']})" if v.get("Connect_RetryCount") else ""
            out["link"] = self._cause("link", error_id, reason=f" — {reason}" if reason else "", attempt=attempt,
                                      lost="Connection to the robot lost, reconnecting" if self._was_connected
                                      else "Not connected to the robot, retrying" if v.get("Connect_Reconnecting")
                                      else "Not connected to the robot")
        self.robot_state = ("E-stop" if "estop" in out else "robot error" if "robot" in out
                            else "not connected" if not connected else "project stopped" if "project" in out
                            else "left the Listen node" if "listen" in out
                            else "ready" if rs and rs.get("ProjectRunning") else "connected")
        return out

    # --- the alarm list -------------------------------------------------------------------------
    def _top(self, below_rank: int) -> Alarm | None:
        """The active alarm of the highest-ranked cause above ``below_rank`` (the first raised of equal rank)."""
        higher = [a for a in self.alarms.values() if a.active and a.rank < below_rank]
        return min(higher, key=lambda a: (a.rank, a.number)) if higher else None

    def _record(self, now: float, event: str, alarm: Alarm, **more) -> None:
        self.entry_number += 1
        self.history.add({"n": self.entry_number, "time": stamp(now), "event": event, "alarm": alarm.number,
                          "priority": PRIORITIES[alarm.priority], "source": alarm.source, "text": alarm.text,
                          "id": id_text(alarm.error_id) if alarm.error_id else "", **more})
        self.seq += 1

    def _raise(self, key: str, c: dict, now: float, active: bool = True) -> Alarm:
        self.alarm_number += 1
        alarm = Alarm(self.alarm_number, key, c["rank"], c["priority"], c["source"], c["text"], c["remedy"], now,
                      c["error_id"], active=active, returned=None if active else now,
                      first_out=not self.alarms)     # the first of an episode: nothing else listed
        self.alarms[alarm.number] = alarm
        self._record(now, "raised" if active else "event", alarm, first_out=alarm.first_out)
        if len(self.alarms) > MAX_LISTED:                 # bounded: nobody acknowledges a flood of events
            for old in [a for a in self.alarms.values() if not a.active][:len(self.alarms) - MAX_LISTED]:
                del self.alarms[old.number]
                self._record(now, "left the full list unacknowledged", old)
        return alarm

    def _detail(self, alarm: Alarm, now: float, text: str) -> None:
        if len(alarm.details) < MAX_DETAILS and text not in [d["text"] for d in alarm.details]:
            alarm.details.append({"time": stamp(now), "text": text})
            self._record(now, "consequence", alarm, detail=text)

    def _update(self, conditions: dict, values: dict | None, now: float, mono: float) -> None:
        active = {a.key: a for a in self.alarms.values() if a.active}
        returned = {a.key: a for a in self.alarms.values() if not a.active}
        for key, c in sorted(conditions.items(), key=lambda kc: kc[1]["rank"]):
            held = active.get(key)
            if held is not None:                          # still active: its reason may change in place
                if (held.text, held.error_id) != (c["text"], c["error_id"]):
                    held.text, held.error_id, held.remedy = c["text"], c["error_id"], c["remedy"]
                    self.seq += 1
                continue
            if key in self._absorbed:
                # a consequence lasting beyond its cause: the link reconnecting after Play clears by itself and
                # gets no alarm of its own; a robot error, a stopped project or the robot outside its node stays
                # until the operator acts (Play once the E-stop is released), so when no higher-ranked cause is
                # active any more it is an alarm of its own, not a condition left without one
                if key in CLEARS_BY_ITSELF or self._top(c["rank"]) is not None:
                    continue
                self._absorbed.discard(key)
            top = self._top(c["rank"])
            if top is not None:                           # a consequence of an active cause
                shown = f"{c['source']} {id_text(c['error_id'])}" if c["error_id"] else c["source"]
                self._detail(top, now, f"{shown}: {c['text']}")
                self._pending.pop(key, None)
                self._absorbed.add(key)
                continue
            if c["rank"] >= CAUSES["project"][0]:         # a consequence-type alarm waits for its cause
                since = self._pending.setdefault(key, mono)
                if mono - since < ON_DELAY_S:
                    continue
            self._pending.pop(key, None)
            again = returned.get(key)
            if again is not None:                         # back before it was acknowledged: the same alarm
                again.active, again.returned = True, None
                again.text, again.error_id, again.remedy = c["text"], c["error_id"], c["remedy"]
                self._record(now, "raised again", again)
                active[key] = again
            else:
                active[key] = self._raise(key, c, now)
        for key in [k for k in self._pending if k not in conditions]:
            del self._pending[key]
        self._absorbed &= conditions.keys()
        for alarm in list(self.alarms.values()):          # alarms follow the process condition
            if alarm.active and alarm.key not in conditions:
                alarm.active, alarm.returned = False, now
                self._record(now, "returned", alarm)
                if alarm.acked:
                    self._normal(alarm, now)
        if values is not None:
            self._commands(values, now, mono)

    def _commands(self, v: dict, now: float, mono: float) -> None:
        """A command's Error going TRUE is one event; it waits ON_DELAY_S for its cause like a consequence."""
        for group, source in self.commands:
            error, error_id = v.get(f"{group}_Error") is True, int(v.get(f"{group}_ErrorID") or 0)
            before = self._errors_seen.get(group, (False, 0))
            self._errors_seen[group] = (error, error_id)
            if not error or not error_id or before == (True, error_id):
                continue
            row = self.errors.get(id_text(error_id), {})
            if row.get("hmi", "alarm") != "alarm":
                continue                                  # a refused start: the page's message line says it
            text = operator_text(v.get(f"{group}_ErrorDescrip") or row.get("text", ""))
            self._events.append((mono, {"rank": COMMAND_RANK, "priority": COMMAND_PRIORITY, "source": source,
                                        "text": text, "remedy": row.get("operator", ""), "error_id": error_id}))
        waiting = []
        for seen, c in self._events:
            top = self._top(COMMAND_RANK)
            if top is not None:
                self._detail(top, now, f"{c['source']} {id_text(c['error_id'])}: {c['text']}")
            elif mono - seen < ON_DELAY_S:
                waiting.append((seen, c))
            else:
                self._raise(f"command:{c['source']}", c, now, active=False)
        self._events = waiting

    def _normal(self, alarm: Alarm, now: float) -> None:
        del self.alarms[alarm.number]
        self._record(now, "normal", alarm)

    # --- requests -------------------------------------------------------------------------------
    def acknowledge(self, numbers: list[int] | None, role: str) -> int:
        """Acknowledge the alarms ``numbers`` (None: every alarm); returns how many were acknowledged."""
        now, count = self.clock(), 0
        with self._lock:
            for alarm in list(self.alarms.values()):
                if alarm.acked or (numbers is not None and alarm.number not in numbers):
                    continue
                alarm.acked = True
                count += 1
                self._record(now, "acknowledged", alarm, by=role)
                if not alarm.active:
                    self._normal(alarm, now)
        return count

    def summary(self, history: int = 0) -> dict:
        """The alarm list, highest priority first (then newest first), and the newest ``history`` entries."""
        with self._lock:
            listed = sorted(self.alarms.values(), key=lambda a: (a.priority, -a.number))
            answer = {"ok": True, "seq": self.seq, "now": stamp(self.clock()), "robot": self.robot_state,
                      "alarms": [a.as_json() for a in listed]}
            if history:
                answer["history"] = list(self.history.entries)[-history:][::-1]
        return answer


def _load_errors() -> dict:
    try:
        return json.loads((HMI_DIR / "errors.json").read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        log.warning("cbt_hmi/pages/errors.json not read (%s): alarms without operator remedies", exc)
        return {}
