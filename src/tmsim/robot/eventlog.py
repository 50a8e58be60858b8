"""Event log of one robot: every event as a dict, bounded in memory by count and by bytes.

``net.robot_ports.Robot`` holds one (``robot.log``) and hands ``robot.log.event`` to its sessions as their log. The
log follows the clock of the robot's Listen-node session (``follow``): each event carries that clock's
``t``, and keeping or writing it is billed to the session's work meter. The JSONL file (``LogFile``, rotated
at LOG_FILE_BYTES_MAX, shared by every robot of a server) gets every event whole; memory keeps the newest
ones: when the count or the bytes exceed the robot's share, the oldest are dropped until half of both is
left (``events_dropped`` counts them, so an index that counts every event ever logged stays valid: the
control channel's ``since``).
"""
from __future__ import annotations

import json
import os
import threading
from collections.abc import Callable
from typing import Any, Protocol

from tmsim.limits import LOG_FILE_BYTES_MAX, WORK_LOG_BYTES
from tmsim.tmscript.work import WorkMeter

EVENT_OVERHEAD = 200        # bytes an event counts, plus the length of its texts


class Clock(Protocol):
    """What the log reads of the session it follows: the robot clock and the turn's work meter."""
    now: float
    meter: WorkMeter


class EventLog:
    """The events of robot ``index``; at most ``count_limit`` events and ``bytes_limit`` bytes kept in
    memory (its share of EVENTS_KEPT_MAX and EVENT_BYTES_MAX), every event also written to ``file``."""

    def __init__(self, index: int, count_limit: int, bytes_limit: int, file: LogFile | None = None):
        self.index = index
        self.count_limit = count_limit
        self.bytes_limit = bytes_limit
        self._file = file
        self._clock: Clock | None = None           # the session whose clock stamps the events (``follow``)
        self.events: list[dict] = []
        self.events_dropped = 0                  # events removed from the front of ``events`` so far
        self._event_sizes: list[int] = []
        self.event_bytes = 0
        self._waiters: list[tuple[Callable[[dict], bool], threading.Event, list[dict]]] = []   # of wait_event

    def follow(self, clock: Clock) -> None:
        """Stamp the events with ``clock.now`` from now on and bill their cost to ``clock.meter``."""
        self._clock = clock

    def stop_writing(self) -> None:
        """The file was closed (the server closed): events are kept in memory only."""
        self._file = None

    def event(self, kind: str, **fields: Any) -> None:
        """Log one event of ``kind`` with ``fields`` (JSON values)."""
        clock = self._clock
        event = {"t": round(clock.now, 6) if clock is not None else 0.0, "robot": self.index, "kind": kind,
                 **fields}
        size = EVENT_OVERHEAD
        for value in fields.values():
            if type(value) is str:
                size += len(value)
        handled = size                           # bytes kept, and as many written to the file
        if self._file is not None:
            self._file.write(json.dumps(event, ensure_ascii=False) + "\n")
            handled += size
        if clock is not None:                    # keeping and writing the event is work of the robot's turn
            clock.meter.work += handled // WORK_LOG_BYTES
        budget = self.bytes_limit
        if size > budget // 4:                   # one huge event must not push out all others
            event, size = _shortened(event, budget // 4), budget // 4
        self.events.append(event)
        self._event_sizes.append(size)
        self.event_bytes += size
        if self._waiters:
            for predicate, flag, found in list(self._waiters):
                if not flag.is_set() and predicate(event):
                    found.append(event)
                    flag.set()
        if len(self.events) > self.count_limit or self.event_bytes > budget:
            self._drop_old_events()

    def _drop_old_events(self) -> None:
        """Drop the oldest events until at most half the count and half the bytes are kept."""
        keep_bytes, count = self.bytes_limit // 2, len(self.events)
        cut, excess = max(0, count - self.count_limit // 2), self.event_bytes - keep_bytes
        dropped_bytes = sum(self._event_sizes[:cut])
        while cut < count and dropped_bytes < excess:
            dropped_bytes += self._event_sizes[cut]
            cut += 1
        del self.events[:cut]
        del self._event_sizes[:cut]
        self.event_bytes -= dropped_bytes
        self.events_dropped += cut

    def event_sizes(self, start: int, count: int) -> list[int]:
        """Bytes the event log counts for events[start:start + count]."""
        return self._event_sizes[start:start + count]

    def wait_event(self, kind: str, timeout: float = 5.0, since: int = 0, **fields: Any) -> dict | None:
        """First event of ``kind`` whose fields equal ``fields``, among events[since:] or logged later
        (from another thread, e.g. start_background()); None after ``timeout`` wall-clock seconds."""
        def predicate(event: dict) -> bool:
            return event["kind"] == kind and all(event.get(k) == v for k, v in fields.items())
        flag, found = threading.Event(), list[dict]()
        entry = (predicate, flag, found)
        self._waiters.append(entry)
        try:
            for event in list(self.events[since:]):
                if predicate(event):
                    return event
            return found[0] if flag.wait(timeout) else None
        finally:
            self._waiters.remove(entry)


class LogFile:
    """The JSONL event log file (``--log``), bounded: once it holds LOG_FILE_BYTES_MAX bytes it is renamed to
    ``<name>.1`` (replacing an older one) and a new file is begun, so both together stay below twice the
    bound (plus one event)."""

    def __init__(self, path: str | os.PathLike[str]):
        self.path = str(path)
        self._file = open(self.path, "ab", buffering=0)  # noqa: SIM115 - open for the server's life, closed by close()
        self.size = self._file.tell()
        self.rotations = 0

    def write(self, text: str) -> None:
        if self.size >= LOG_FILE_BYTES_MAX:
            self._file.close()
            os.replace(self.path, self.path + ".1")
            self._file = open(self.path, "ab", buffering=0)  # noqa: SIM115 - as in __init__
            self.size = 0
            self.rotations += 1
        data = text.encode("utf-8", "backslashreplace")
        self._file.write(data)
        self.size += len(data)

    def close(self) -> None:
        self._file.close()


def _shortened(event: dict, size: int) -> dict:
    """A copy of ``event`` whose long texts are cut so that it counts about ``size`` bytes."""
    room = max(64, (size - EVENT_OVERHEAD) // max(1, sum(type(v) is str for v in event.values())))
    return {key: (value[:room] + f"...[{len(value)} characters]" if type(value) is str and len(value) > room
                  else value) for key, value in event.items()}


def text(raw: bytes) -> str:
    """Bytes of the wire as event text (non-UTF-8 bytes as \\xNN)."""
    return raw.decode("utf-8", "backslashreplace")
