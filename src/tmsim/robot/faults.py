"""Fault injection on the outgoing side of one robot (what the server writes, and when).

fault                parameters (range)
    effect
reply_delay          seconds=0.5 (0..3600), count=None (1..10^6)
    every frame (or the next ``count``) leaves ``seconds`` later (virtual time)
split_replies        size=1 (1..65536)
    frames are written in ``size``-byte pieces, one piece per poll
glue_replies         count=2 (2..1000), max_wait=0.05 (0..60)
    frames are held until ``count`` are waiting (or ``max_wait`` s passed), then sent in one send
corrupt_checksum     count=1, match="" (text)
    the next ``count`` frames (containing ``match``) carry a wrong checksum
close_after          frames=1
    the connection is closed after ``frames`` more received frames (replies to them are sent first)
close_mid_frame      -
    the next frame is cut in half and the connection closed
black_hole           enabled=True
    received bytes are discarded, nothing is answered
refuse_connections   enabled=True
    the listening socket is closed (connects are refused); existing clients stay

Session-level faults: reply_error, leave_node, stop_project (the Listen node's own:
protocol.listen_session.ListenSession.inject) and disconnect (net.robot_ports.Robot.inject).
Parameters are checked by ``check_params`` (PARAMS below); a value outside its range is a ValueError.
Clearing the faults (``adopt``) keeps what is held back: it still leaves, whole and in order.
"""
from __future__ import annotations

import math
from collections import deque
from collections.abc import Iterable
from typing import Any

# fault -> parameter -> (kind, default, low, high); kind "choice": high holds the allowed values
PARAMS: dict[str, dict[str, tuple[str, Any, Any, Any]]] = {
    "reply_delay": {"seconds": ("number", 0.5, 0.0, 3600.0), "count": ("int", None, 1, 10 ** 6)},
    "split_replies": {"size": ("int", 1, 1, 65536)},
    "glue_replies": {"count": ("int", 2, 2, 1000), "max_wait": ("number", 0.05, 0.0, 60.0)},
    "corrupt_checksum": {"count": ("int", 1, 1, 10 ** 6), "match": ("text", "", 0, 200)},
    "close_after": {"frames": ("int", 1, 0, 10 ** 6)},
    "close_mid_frame": {},
    "black_hole": {"enabled": ("bool", True, None, None)},
    "refuse_connections": {"enabled": ("bool", True, None, None)},
    "reply_error": {"count": ("int", 1, 1, 10 ** 6)},
    "leave_node": {"path": ("choice", "Pass", None, ("Pass", "Fail"))},
    "stop_project": {},
    "disconnect": {},
}


def check_params(fault: str, params: dict) -> dict:
    """The parameters of ``fault`` with defaults filled in; ValueError naming the first bad one."""
    spec = PARAMS.get(fault)
    if spec is None:
        raise ValueError(f"unknown fault '{fault}'; known faults: {', '.join(KNOWN)}")
    unknown = sorted(set(params) - set(spec))
    if unknown:
        raise ValueError(f"bad parameter for fault '{fault}': unknown parameter '{unknown[0]}' "
                         f"(known: {', '.join(spec) or 'none'})")
    checked: dict[str, Any] = {}
    for name, (kind, default, low, high) in spec.items():
        value = params.get(name, default)
        if value is None:
            checked[name] = None
            continue
        if kind == "bool":
            if not isinstance(value, bool):
                raise ValueError(f"bad parameter for fault '{fault}': {name} must be true or false, got {value!r}")
        elif kind == "text":
            if not isinstance(value, str) or len(value) > high:
                raise ValueError(f"bad parameter for fault '{fault}': {name} must be text of at most {high} "
                                 f"characters, got {value!r}")
        elif kind == "choice":
            if value not in high:
                raise ValueError(f"bad parameter for fault '{fault}': {name} must be one of "
                                 f"{', '.join(high)}, got {value!r}")
        else:
            integer = kind == "int"
            if isinstance(value, bool) or not isinstance(value, (int, float)) or (
                    integer and isinstance(value, float) and not value.is_integer()):
                raise ValueError(f"bad parameter for fault '{fault}': {name} must be "
                                 f"{'an integer' if integer else 'a number'}, got {value!r}")
            if not math.isfinite(value) or not low <= value <= high:
                raise ValueError(f"bad parameter for fault '{fault}': {name} must be {low}..{high}, got {value!r}")
            value = int(value) if integer else float(value)
        checked[name] = value
    return checked


class FaultState:
    def __init__(self) -> None:
        self.delay = 0.0
        self.delay_count: int | None = None
        self.split = 0
        self.glue = 0
        self.glue_wait = 0.05
        self.corrupt = 0
        self.corrupt_match = b""
        self.close_after: int | None = None
        self.close_mid = False
        self.black_hole = False
        self.refuse = False
        self._queues: dict[int, deque] = {}
        self._partial: dict[int, bytes] = {}

    def arm(self, fault: str, **params: Any) -> None:
        params = check_params(fault, params)
        if fault == "reply_delay":
            self.delay = params["seconds"]
            self.delay_count = params["count"]
        elif fault == "split_replies":
            self.split = params["size"]
        elif fault == "glue_replies":
            self.glue = params["count"]
            self.glue_wait = params["max_wait"]
        elif fault == "corrupt_checksum":
            self.corrupt = min(self.corrupt + params["count"], 10 ** 6)
            self.corrupt_match = params["match"].encode()
        elif fault == "close_after":
            self.close_after = params["frames"]
        elif fault == "close_mid_frame":
            self.close_mid = True
        elif fault == "black_hole":
            self.black_hole = params["enabled"]
        elif fault == "refuse_connections":
            self.refuse = params["enabled"]
        else:
            raise ValueError(f"fault '{fault}' is not an output fault")

    @property
    def active(self) -> bool:
        """True while any output fault is armed or output is still held back."""
        return bool(self.delay or self.split or self.glue or self.corrupt or self.close_mid or self.black_hole
                    or (self._queues and any(self._queues.values()))
                    or (self._partial and any(self._partial.values())))

    def describe(self) -> dict:
        return {"reply_delay": self.delay, "split_replies": self.split, "glue_replies": self.glue,
                "corrupt_checksum": self.corrupt, "close_after": self.close_after,
                "close_mid_frame": self.close_mid, "black_hole": self.black_hole,
                "refuse_connections": self.refuse}

    def queue(self, conn: int, frames: Iterable[bytes], now: float) -> None:
        out = self._queues.setdefault(conn, deque())
        for frame in frames:
            if self.corrupt > 0 and self.corrupt_match in frame:
                self.corrupt -= 1
                bad = (int(frame[-4:-2], 16) ^ 0x5A)
                frame = frame[:-4] + b"%02X" % bad + b"\r\n"
            release = now
            if self.delay > 0 and (self.delay_count is None or self.delay_count > 0):
                release = now + self.delay
                if self.delay_count is not None:
                    self.delay_count -= 1
            out.append((release, now, frame))
        if self.black_hole:
            out.clear()

    def close_after_reached(self) -> None:
        """A connection received the ``close_after`` count of frames and is closed: the fault is spent."""
        self.close_after = None

    def adopt(self, other: FaultState) -> None:
        """Take over the frames another (cleared) fault state still holds back."""
        self._queues, self._partial = other._queues, other._partial

    def holding(self, conn: int) -> bool:
        return bool(self._queues.get(conn)) or bool(self._partial.get(conn))

    def forget(self, conn: int) -> None:
        self._queues.pop(conn, None)
        self._partial.pop(conn, None)

    def next_due(self, now: float) -> float | None:
        """The earliest robot-clock time at which ``take`` releases something held back: ``now`` while pieces of a
        split frame wait (one piece a poll) or released frames are ready to leave; the release time of the first
        held frame of a connection (reply_delay); for glue_replies, the time its oldest released frame has
        waited ``max_wait`` (unless ``count`` frames wait before). None when nothing is held."""
        if not (self._queues or self._partial):
            return None
        if any(self._partial.values()):
            return now
        due: float | None = None
        for out in self._queues.values():
            if not out:
                continue
            released = 0
            for release, _queued, _frame in out:
                if release > now:
                    break
                released += 1
            if not released:
                at = out[0][0]
            elif self.glue and released < self.glue and released == len(out):
                at = max(now, min(item[1] for item in out) + self.glue_wait)
            else:
                at = now
            due = at if due is None else min(due, at)
        return due

    def take(self, conn: int, now: float) -> tuple[list[bytes], bool]:
        """(list of byte chunks to write now, close-after-writing flag)."""
        pending = self._queues.get(conn)
        ready = []
        while pending and pending[0][0] <= now:
            ready.append(pending.popleft())
        if self.close_mid and ready:
            self.close_mid = False
            frame = ready[0][2]
            return [frame[: max(1, len(frame) // 2)]], True
        if self.glue and ready:
            oldest = min(item[1] for item in ready)
            if len(ready) < self.glue and now - oldest < self.glue_wait and not pending:
                for item in reversed(ready):
                    self._queues[conn].appendleft(item)
                return [], False
            ready_bytes = [b"".join(item[2] for item in ready)]
        else:
            ready_bytes = [item[2] for item in ready]
        held = self._partial.pop(conn, b"")
        if held and not self.split:          # pieces of a split that was cleared: they go first, whole
            return [held, *ready_bytes], False
        if held:
            self._partial[conn] = held
        if self.split:
            partial = self._partial.get(conn, b"") + b"".join(ready_bytes)
            piece, rest = partial[: self.split], partial[self.split:]
            self._partial[conn] = rest
            return ([piece] if piece else []), False
        return ready_bytes, False


KNOWN = tuple(PARAMS)
