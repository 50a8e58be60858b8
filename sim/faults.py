"""Fault injection on the outgoing side of one robot (what the server writes, and when).

| fault                | parameters                        | effect                                               |
|----------------------|-----------------------------------|------------------------------------------------------|
| reply_delay          | seconds=0.5, count=None           | every frame (or the next ``count``) leaves ``seconds`` later (virtual time) |
| split_replies        | size=1                            | frames are written in ``size``-byte pieces, one piece per poll |
| glue_replies         | count=2, max_wait=0.05            | frames are held until ``count`` are waiting (or ``max_wait`` s passed), then sent in one send |
| corrupt_checksum     | count=1                           | the next ``count`` frames carry a wrong checksum     |
| close_after          | frames=1                          | the connection is closed after ``frames`` more received frames (replies to them are sent first) |
| close_mid_frame      | -                                 | the next frame is cut in half and the connection closed |
| black_hole           | enabled=True                      | received bytes are discarded, nothing is answered    |
| refuse_connections   | enabled=True                      | the listening socket is closed (connects are refused); existing clients stay |
Session-level faults handled in server.Robot.inject: reply_error, leave_node, stop_project, disconnect.
"""
from __future__ import annotations

from collections import deque


class FaultState:
    def __init__(self):
        self.delay = 0.0
        self.delay_count = None
        self.split = 0
        self.glue = 0
        self.glue_wait = 0.05
        self.corrupt = 0
        self.close_after = None
        self.close_mid = False
        self.black_hole = False
        self.refuse = False
        self._queues: dict[int, deque] = {}
        self._partial: dict[int, bytes] = {}

    def arm(self, fault, **params):
        try:
            if fault == "reply_delay":
                self.delay = float(params.get("seconds", 0.5))
                self.delay_count = params.get("count")
            elif fault == "split_replies":
                self.split = max(1, int(params.get("size", 1)))
            elif fault == "glue_replies":
                self.glue = max(2, int(params.get("count", 2)))
                self.glue_wait = float(params.get("max_wait", 0.05))
            elif fault == "corrupt_checksum":
                self.corrupt += int(params.get("count", 1))
            elif fault == "close_after":
                self.close_after = max(0, int(params.get("frames", 1)))
            elif fault == "close_mid_frame":
                self.close_mid = True
            elif fault == "black_hole":
                self.black_hole = bool(params.get("enabled", True))
            elif fault == "refuse_connections":
                self.refuse = bool(params.get("enabled", True))
            else:
                raise ValueError(f"unknown fault '{fault}'; known faults: {', '.join(KNOWN)}")
        except (TypeError, ValueError) as exc:
            if "unknown fault" in str(exc):
                raise
            raise ValueError(f"bad parameter for fault '{fault}': {exc}") from None

    @property
    def active(self) -> bool:
        """True while any output fault is armed or output is still held back."""
        return bool(self.delay or self.split or self.glue or self.corrupt or self.close_mid or self.black_hole
                    or any(self._queues.values()) or any(self._partial.values()))

    def describe(self) -> dict:
        return {"reply_delay": self.delay, "split_replies": self.split, "glue_replies": self.glue,
                "corrupt_checksum": self.corrupt, "close_after": self.close_after,
                "close_mid_frame": self.close_mid, "black_hole": self.black_hole,
                "refuse_connections": self.refuse}

    def queue(self, conn, frames, now):
        out = self._queues.setdefault(conn, deque())
        for frame in frames:
            if self.corrupt > 0:
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

    def adopt(self, other: "FaultState"):
        """Take over the frames another (cleared) fault state still holds back."""
        self._queues, self._partial = other._queues, other._partial

    def holding(self, conn) -> bool:
        return bool(self._queues.get(conn)) or bool(self._partial.get(conn))

    def forget(self, conn):
        self._queues.pop(conn, None)
        self._partial.pop(conn, None)

    def take(self, conn, now):
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
        if self.split:
            partial = self._partial.get(conn, b"") + b"".join(ready_bytes)
            piece, rest = partial[: self.split], partial[self.split:]
            self._partial[conn] = rest
            return ([piece] if piece else []), False
        return ready_bytes, False


KNOWN = ("reply_delay", "split_replies", "glue_replies", "corrupt_checksum", "close_after",
         "close_mid_frame", "black_hole", "refuse_connections", "reply_error", "leave_node",
         "stop_project", "disconnect")
