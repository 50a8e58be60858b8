"""Work meter of one robot: the scheduler's turns are bounded in work, not in time or items.

One simulator thread serves every robot, so a turn that does unbounded work for one client stalls all
the others. Each turn the server gives a robot (a client's input, advancing its motions and its running
script) starts with ``begin(TURN_WORK)``; the session, the interpreter, the motion planner and the event
log add what they do (``add``) in work units (tmsim/limits.py: WORK_* costs); a piece of work that finds
the turn ``spent`` stops at its next safe point and goes on in a later turn - a script between two
statements or two lines it checks, the motion planner between two motions (its clock keeps the time it
owes). One item (a statement, a line, a motion plan) is never split, so a turn may pass TURN_WORK by the
cost of its last item. Outside the server (``limit`` None) nothing stops: the sans-I/O session runs a
script through at once.

The meter counts for the tests and the docs: turns begun, turns ended by the budget, the most work done
in one turn.
"""
from __future__ import annotations


class WorkMeter:
    __slots__ = ("work", "limit", "turns", "deferred", "max_work", "_counted")

    def __init__(self) -> None:
        self.work = 0               # work units done in the current turn
        self.limit: int | None = None   # TURN_WORK while the server runs a turn; None = no bound
        self.turns = 0              # turns begun
        self.deferred = 0           # turns that stopped a piece of work for a later turn
        self.max_work = 0           # the most work done in one turn so far
        self._counted = False       # this turn is already counted in ``deferred``

    def begin(self, limit: int | None) -> None:
        self.max_work = max(self.max_work, self.work)
        self.work, self.limit, self._counted = 0, limit, False
        self.turns += 1

    def add(self, units: int) -> None:
        self.work += units

    @property
    def spent(self) -> bool:
        """The turn's budget is used up: stop at the next safe point (counted once per turn)."""
        if self.limit is None or self.work < self.limit:
            return False
        if not self._counted:
            self._counted = True
            self.deferred += 1
        return True

    def most(self) -> int:
        """The most work done in one turn, the current one included."""
        return max(self.max_work, self.work)
