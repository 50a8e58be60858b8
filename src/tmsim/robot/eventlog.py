"""Event log of one robot: every event as a dict, bounded in memory by count and by bytes.

Mixed into ``server.Robot``, which provides ``_server`` (``event_limit``, ``event_bytes_limit``,
``log_file``), ``index`` and ``session`` (its clock). The JSONL file (``LogFile``, rotated at
LOG_FILE_BYTES_MAX) gets every event whole; memory keeps
the newest ones: when the count or the bytes exceed the robot's share, the oldest are dropped until half
of both is left (``events_dropped`` counts them, so an index that counts every event ever logged stays
valid: the control channel's ``since``).
"""
from __future__ import annotations

import json
import os
import threading

from tmsim.limits import LOG_FILE_BYTES_MAX, WORK_LOG_BYTES

EVENT_OVERHEAD = 200        # bytes an event counts, plus the length of its texts


class EventLog:
    def _init_event_log(self):
        self.events: list[dict] = []
        self.events_dropped = 0                  # events removed from the front of ``events`` so far
        self._event_sizes: list[int] = []
        self.event_bytes = 0
        self._waiters: list[tuple] = []          # (predicate, threading.Event, [match]) of wait_event

    def _log(self, kind, **fields):
        session = self.__dict__.get("session")
        event = {"t": round(session.now, 6) if session is not None else 0.0, "robot": self.index, "kind": kind,
                 **fields}
        size = EVENT_OVERHEAD
        for value in fields.values():
            if type(value) is str:
                size += len(value)
        handled = size                           # bytes kept, and as many written to the file
        if self._server.log_file is not None:
            self._server.log_file.write(json.dumps(event, ensure_ascii=False) + "\n")
            handled += size
        if session is not None:                  # keeping and writing the event is work of the robot's turn
            session.meter.work += handled // WORK_LOG_BYTES
        budget = self._server.event_bytes_limit
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
        if len(self.events) > self._server.event_limit or self.event_bytes > budget:
            self._drop_old_events()

    def _drop_old_events(self):
        """Drop the oldest events until at most half the count and half the bytes are kept."""
        keep_bytes, count = self._server.event_bytes_limit // 2, len(self.events)
        cut, excess = max(0, count - self._server.event_limit // 2), self.event_bytes - keep_bytes
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

    def wait_event(self, kind: str, timeout: float = 5.0, since: int = 0, **fields) -> dict | None:
        """First event of ``kind`` whose fields equal ``fields``, among events[since:] or logged later
        (from another thread, e.g. start_background()); None after ``timeout`` wall-clock seconds."""
        def predicate(event):
            return event["kind"] == kind and all(event.get(k) == v for k, v in fields.items())
        flag, found = threading.Event(), []
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

    def __init__(self, path):
        self.path = str(path)
        self._file = open(self.path, "ab", buffering=0)
        self.size = self._file.tell()
        self.rotations = 0

    def write(self, text: str):
        if self.size >= LOG_FILE_BYTES_MAX:
            self._file.close()
            os.replace(self.path, self.path + ".1")
            self._file = open(self.path, "ab", buffering=0)
            self.size = 0
            self.rotations += 1
        data = text.encode("utf-8", "backslashreplace")
        self._file.write(data)
        self.size += len(data)

    def close(self):
        self._file.close()


def _shortened(event, size):
    """A copy of ``event`` whose long texts are cut so that it counts about ``size`` bytes."""
    room = max(64, (size - EVENT_OVERHEAD) // max(1, sum(type(v) is str for v in event.values())))
    return {key: (value[:room] + f"...[{len(value)} characters]" if type(value) is str and len(value) > room
                  else value) for key, value in event.items()}


def text(raw: bytes) -> str:
    """Bytes of the wire as event text (non-UTF-8 bytes as \\xNN)."""
    return raw.decode("utf-8", "backslashreplace")
