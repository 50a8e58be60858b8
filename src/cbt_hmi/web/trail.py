"""The TCP trail of the robot view, kept by the server: sampled from the PLC every 50 ms while the position is
valid, so every page (and a page opened later) shows the same path since the HMI server started.

The variable table names what to sample: ``"trail": {"valid": "ReadPos_Valid", "position": "ReadPos_Position.TCP"}``.
A point is kept when the TCP moved more than ``STEP_MM``; the oldest points go beyond ``CAPACITY``.
"""
from __future__ import annotations

import math
import threading
from collections import deque

PERIOD_S = 0.05
STEP_MM = 0.5
CAPACITY = 2000


class Trail:
    def __init__(self, plc, valid: str, position: str) -> None:
        self.plc, self.valid, self.position = plc, valid, position
        self.points: deque[tuple[int, float, float, float]] = deque(maxlen=CAPACITY)   # (number, x, y, z)
        self.count = 0
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def sample(self) -> None:
        """Take one sample (the thread calls this every PERIOD_S; tests call it directly)."""
        with self.plc.lock:
            if not self.plc.read(self.valid):
                return
            p = self.plc.read(self.position)
        x, y, z = float(p["X"]), float(p["Y"]), float(p["Z"])
        if not all(math.isfinite(v) for v in (x, y, z)):
            return
        with self._lock:
            if self.points:
                _, lx, ly, lz = self.points[-1]
                if math.dist((x, y, z), (lx, ly, lz)) <= STEP_MM:
                    return
            self.count += 1
            self.points.append((self.count, x, y, z))

    def since(self, number: int) -> dict:
        """Points after point ``number`` (0: all kept), and the number to ask from next time."""
        with self._lock:
            points = [[round(x, 2), round(y, 2), round(z, 2)] for n, x, y, z in self.points if n > number]
            first = self.points[0][0] if self.points else self.count + 1
            return {"ok": True, "points": points, "next": self.count, "complete": number + 1 >= first or number == 0}

    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="hmi-trail", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(PERIOD_S):
            try:
                self.sample()
            except (KeyError, ValueError, TypeError):
                return                          # the program has no such variables: no trail

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2)
