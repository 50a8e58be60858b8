"""Sysmac system-defined variables (prelude/sysmac_sysvars.st), kept up to date by a hook of the scan loop.

The generic engine knows nothing of them: :func:`task_hook` gives the callable the engine runs before every
task execution (``Engine.before_task``), or None when the program sees none of these variables. It sets

* ``P_First_Run``, ``P_First_RunMode``: TRUE during the first execution of the task;
* the clock pulses ``P_0_02s``, ``P_0_1s``, ``P_0_2s``, ``P_1s``, ``P_1min``: on for the first half of their
  period, off for the second, on the scan time;
* ``_CurrentTime``: the controller clock (DT), read before every task execution (W501, system-defined
  variables).

The pulses change only every half period: the hook does that work only when the next change is due, and in a
task's first two cycles (when the first-run flags change).
"""
from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from . import abi

if TYPE_CHECKING:
    from .engine import Engine, Task

FIRST_RUN = ("P_FIRST_RUN", "P_FIRST_RUNMODE")
CLOCK_PULSES = (("P_0_02S", 20_000_000), ("P_0_1S", 100_000_000), ("P_0_2S", 200_000_000),
                ("P_1S", 1_000_000_000), ("P_1MIN", 60_000_000_000))
CURRENT_TIME = "_CURRENTTIME"


class SystemVariables:
    """The system-defined variables one PLC's globals object holds, and the scan time of their next change."""

    def __init__(self, values: dict, first: list, clocks: list) -> None:
        self.values = values              # the globals object's __dict__
        self.first = first                # attributes of the first-run flags
        self.clocks = clocks              # (attribute, period ns) of the clock pulses
        self.next_ns: float = 0           # scan time at which a clock pulse changes next

    def update(self, task: Task, now_ns: int) -> None:
        """First-run flags for the task's first cycle; clock pulses (half period on, half off). The next call is
        due when the next pulse changes (the scan skips the work until then)."""
        values = self.values
        for attr in self.first:
            values[attr] = task.cycles == 0
        nxt = math.inf
        for attr, period in self.clocks:
            half = period // 2
            values[attr] = now_ns % period < half
            nxt = min(nxt, now_ns - now_ns % half + half)
        self.next_ns = nxt


def task_hook(engine: Engine, globals_obj: Any) -> Callable[[Task, int], None] | None:
    """The hook updating the system-defined variables of ``globals_obj`` before every task execution of
    ``engine``, or None when the program's globals have none of them. It runs in every scan, so it is a
    closure over what it needs (no attribute look-ups on the way to the common case)."""
    info = getattr(type(globals_obj), abi.VARS, {})
    first = [info[n][0] for n in FIRST_RUN if n in info]
    clocks = [(info[n][0], period) for n, period in CLOCK_PULSES if n in info]
    current = info[CURRENT_TIME][0] if CURRENT_TIME in info else None
    values = globals_obj.__dict__
    state = SystemVariables(values, first, clocks) if first or clocks else None
    time_ns = time.time_ns
    if state is None and current is None:
        return None
    if state is None:
        def before_task(task: Task, now_ns: int) -> None:
            base = engine.clock_base_ns                     # as Engine.clock_dt_ns()
            values[current] = time_ns() if base is None else base + now_ns
    elif current is None:
        def before_task(task: Task, now_ns: int) -> None:
            if task.cycles < 2 or now_ns >= state.next_ns:
                state.update(task, now_ns)
    else:
        def before_task(task: Task, now_ns: int) -> None:
            if task.cycles < 2 or now_ns >= state.next_ns:
                state.update(task, now_ns)
            base = engine.clock_base_ns                     # as Engine.clock_dt_ns()
            values[current] = time_ns() if base is None else base + now_ns
    return before_task
