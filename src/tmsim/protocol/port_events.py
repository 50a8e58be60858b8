"""The events of one port protocol, for a caller that reads them with ``events()`` (sans-I/O, after h11's model).

Every port of the simulator (the Listen node, the Ethernet Slave, the control channel) reports what happens
as events ``(kind, **fields)``: the kinds and fields of docs/simulator.md ("Event log"). A protocol built with a
log callback hands each event to it as it happens: that is how the server's event log (tmsim/robot/eventlog.py)
receives them, stamped with the robot clock, with no copy in between. A protocol built without one keeps them
here, in order, until ``events()`` takes them: a test or a program that drives a protocol directly reads what it
did without writing a callback.

The events kept are bounded: beyond PORT_EVENTS_MAX (tmsim/limits.py) the oldest are dropped and counted
(``dropped``), so a protocol that nobody drains holds a fixed amount of memory (a kept ``frame_in`` holds its
frame's text, up to 64 KiB).
"""
from __future__ import annotations

from collections import deque
from collections.abc import Callable
from typing import Any

from tmsim.limits import PORT_EVENTS_MAX


class PortEvents:
    """The events a protocol produced and nobody took yet: each a dict ``{"kind": kind, **fields}``, oldest
    first, at most ``limit`` of them (PORT_EVENTS_MAX when not given; the oldest dropped beyond, counted in
    ``dropped``)."""

    __slots__ = ("_kept", "dropped", "limit")

    def __init__(self, limit: int | None = None):
        limit = PORT_EVENTS_MAX if limit is None else limit
        if type(limit) is not int or limit < 1:
            raise ValueError(f"the events kept by a port must be at least 1, got {limit!r}")
        self.limit = limit
        self._kept: deque[dict[str, Any]] = deque()
        self.dropped = 0                # events dropped from the front so far (never taken by ``take``)

    def record(self, kind: str, **fields: Any) -> None:
        """Keep one event (the signature of a log callback, so a protocol calls it as it would call one)."""
        kept = self._kept
        if len(kept) >= self.limit:
            kept.popleft()
            self.dropped += 1
        kept.append({"kind": kind, **fields})

    def take(self) -> list[dict[str, Any]]:
        """The events kept, oldest first; they are forgotten (the next call returns only newer ones)."""
        taken = list(self._kept)
        self._kept.clear()
        return taken

    def __len__(self) -> int:
        return len(self._kept)


class EventPort:
    """What every port protocol offers for its events (the Listen node's protocol, the Ethernet Slave's session,
    the control channel): ``log(kind, **fields)``, the callback the protocol reports through (the one it was built
    with, else this port's own PortEvents), and ``events()`` / ``events_dropped`` for a caller that reads them."""

    def __init__(self, log: Callable[..., None] | None = None):
        self._events = PortEvents()
        self.log: Callable[..., None] = self._events.record if log is None else log

    def events(self) -> list[dict[str, Any]]:
        """The events produced since the last call, oldest first, each ``{"kind": ..., **fields}`` (the kinds of
        docs/simulator.md "Event log"); they are forgotten. Empty when the port was built with a ``log`` callback
        (it got them as they happened)."""
        return self._events.take()

    @property
    def events_dropped(self) -> int:
        """Events not taken by ``events()`` and dropped (PORT_EVENTS_MAX, tmsim/limits.py)."""
        return self._events.dropped
