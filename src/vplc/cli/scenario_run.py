"""Running a scenario (``scenario.Scenario``) beside the scan loop: the writes and reactions due before a scan,
the requests to the simulator, the expectations after it.

Every variable the scenario watches is a ``Signal`` sampled once after each scan; a reaction or an expectation is
judged again only when one of its variables changed, when it runs on the clock (a `time` term, a `for` running,
an `after` pending) or at its deadline. That keeps a scenario's cost in a scan independent of how many `when`
lines wait for something that does not change (docs/toolchain/runtime.md section 7).
"""
from __future__ import annotations

import operator
from collections.abc import Callable, MutableMapping
from typing import TYPE_CHECKING, Any

from ..runtime.values import PathError
from .scenario import ORDERINGS, Expect, Reaction, Scenario, compare, fmt, seconds

if TYPE_CHECKING:
    from ..api import Plc
    from .simlink import SimControl

_UNSEEN = object()


class Signal:
    """One variable a scenario watches: sampled once after every scan; the reactions and expectations on it are
    judged again only when it changed (what keeps 100 `when` lines cheap). A variable declared directly in a
    program instance or a global list (a program's VAR_EXTERNAL too: it is the global) is read straight from its
    instance, which lives as long as the controller; anything deeper (members, array elements, whose containers
    an assignment may replace) through ``plc.read``."""

    __slots__ = ("container", "conv", "expects", "key", "path", "raw", "reactions", "read", "since_ns", "stamp",
                 "value")

    def __init__(self, plc: Plc, path: str) -> None:
        from ..runtime.values import converter
        slot = plc.lasting_slot(path)                                         # PathError for a bad path
        self.path = path
        self.read: Callable[[], Any] | None = None
        self.container: MutableMapping[Any, Any] | None
        self.key: Any
        self.conv: Callable[[Any], Any]
        if slot is not None:
            self.container, self.key, self.conv = slot.container, slot.key, converter(slot.type)
        else:
            self.container, self.key, self.conv = None, None, _same
            self.read = lambda: plc.read(path)
        self.raw, self.value, self.since_ns, self.stamp = _UNSEEN, None, 0, -1
        self.reactions: list[Reaction] = []
        self.expects: list[Expect] = []


def _same(v: Any) -> Any:
    return v


def _one(key: Any) -> Callable[[Any], tuple]:
    return lambda container: (container[key],)


def comparator(op: str, b: Any) -> Callable[[Any], bool]:
    """``v -> v OP b`` for the value ``b`` of a condition or an expectation (what ``compare`` does, built once)."""
    if isinstance(b, str):
        b = b.upper()
        return (lambda a: isinstance(a, str) and a.upper() == b) if op == "=" else \
            (lambda a: not (isinstance(a, str) and a.upper() == b))
    if isinstance(b, float):
        return lambda a: compare(a, op, b)
    if op in ORDERINGS:
        order = ORDERINGS[op]
        return lambda a: order(a, b)
    return (lambda a: a == b) if op == "=" else (lambda a: a != b)


class Runner:
    """Applies the writes and reactions due before a scan and judges the expectations after it. ``link`` is the
    simulator's control channel (``simlink.SimControl``) for `robot` lines; ``wait`` sends each request and waits
    for its answer (virtual time), otherwise requests leave from a sender thread and the scan never waits."""

    def __init__(self, plc: Plc, sc: Scenario, link: SimControl | None = None, wait: bool = False,
                 say: Callable[..., None] = print) -> None:
        self.plc, self.sc, self.link, self.wait, self.say = plc, sc, link, wait, say
        self.failure: str | None = None
        self.first: Expect | None = None
        self.started = False
        self.signals: dict[str, Signal] = {}
        for i, r in enumerate(sc.reactions):
            r.index = i
            for term in r.terms:
                term.test = comparator(term.op, term.value)
                if term.path is None:
                    r.clock = True
                else:
                    term.sig = self._signal(term.path)
                    if r not in term.sig.reactions:
                        term.sig.reactions.append(r)
        for e in sc.expects:
            e.sig, e.test = self._signal(e.path), comparator(e.op, e.value)
            e.sig.expects.append(e)
        self.clocked = {r.index: r for r in sc.reactions if r.clock}
        self.dirty: list[Reaction] = []
        self.changed: list[Signal] = []
        self.unchecked = sorted(sc.expects, key=lambda e: e.from_ns)     # not judged yet: due at from_ns
        self.deadline = min((e.until_ns for e in sc.expects if e.until_ns is not None), default=None)
        self.writes = sorted(sc.writes, key=lambda w: w.at_ns)
        self.timed = [r for r in sc.reactions if r.timed]                # `at TIME robot ...` lines
        self.decisive = sum(1 for e in sc.expects if not e.always)        # `within` / `at` expectations
        self.undecided = self.decisive
        self.ends = sc.ends                                              # see Scenario.ends
        groups: dict[int, list[Signal]] = {}       # direct signals by the instance they live in
        for sig in self.signals.values():
            if sig.read is None:
                groups.setdefault(id(sig.container), []).append(sig)
        # one C-level read of all of an instance's watched variables a scan: [container, getter, signals, last]
        self.direct: list[list[Any]] = []
        for sigs in groups.values():
            getter: Callable[[Any], tuple] = operator.itemgetter(*[x.key for x in sigs]) if len(sigs) > 1 \
                else _one(sigs[0].key)
            self.direct.append([sigs[0].container, getter, sigs, None])
        self.indirect = [sig for sig in self.signals.values() if sig.read is not None]
        self.stamp = -1

    def _signal(self, path: str) -> Signal:
        sig = self.signals.get(path)
        if sig is None:
            sig = self.signals[path] = Signal(self.plc, path)
        return sig

    def _sample(self, t_ns: int) -> None:
        """Read every watched variable once; those that changed mark their reactions to be judged."""
        self.stamp = stamp = self.stamp + 1
        changed = self.changed = []
        for group in self.direct:
            values = group[1](group[0])
            if values != group[3]:             # nothing watched in this instance changed: the usual scan
                group[3] = values
                for s, raw in zip(group[2], values, strict=False):
                    if raw != s.raw:           # the first time too: s.raw is _UNSEEN
                        s.raw = raw
                        changed.append(s)
        for s in self.indirect:
            raw = s.read()
            if raw != s.raw:
                s.raw = raw
                changed.append(s)
        dirty = self.dirty
        for s in changed:
            s.value, s.since_ns, s.stamp = s.conv(s.raw), t_ns, stamp
            for r in s.reactions:
                if r.mark != stamp:
                    r.mark = stamp
                    dirty.append(r)

    def before_scan(self, t_ns: int) -> None:
        if not self.started:
            self.started = True
            self._mark_start(t_ns)
            self._sample(t_ns)                 # the initial values
        while self.writes and self.writes[0].at_ns <= t_ns:
            w = self.writes.pop(0)
            self._write(w.path, w.value, w.where)
            w.done = True
        if self.dirty or self.clocked:
            self._react(t_ns)
        self.collect_refusals()

    def _react(self, t_ns: int) -> None:
        """Judge the reactions whose variables changed in the last scan (and those on the clock) on the values
        that scan left, all on the same values; then run the actions, in file order."""
        todo = []
        stamp = self.stamp
        candidates, self.dirty = self.dirty, []
        for r in self.clocked.values():
            if r.mark != stamp:
                r.mark = stamp
                candidates.append(r)
        if len(candidates) > 1:
            candidates.sort(key=_index)
        for r in candidates:
            while r.due and r.due[0] <= t_ns:
                r.due.pop(0)
                todo.append(r)
            if not (r.fired and not r.every):
                self._judge(r, t_ns, todo)
            needs_clock = (r.due or r.true_since is not None or any(t.path is None for t in r.terms)) and \
                not (r.fired and not r.every and not r.due)
            if needs_clock:
                self.clocked[r.index] = r
            else:
                self.clocked.pop(r.index, None)
        if len(todo) > 1:
            todo.sort(key=_index)
        for r in todo:
            self._act(r, t_ns)

    @staticmethod
    def _judge(r: Reaction, t_ns: int, todo: list) -> None:
        for term in r.terms:
            if not term.test(t_ns if term.sig is None else term.sig.value):
                r.armed, r.true_since = True, None
                return
        if not r.armed:
            return
        if r.true_since is None:
            r.true_since = t_ns
        if t_ns - r.true_since < r.hold_ns:
            return
        r.armed, r.true_since = False, None
        r.fired += 1
        if r.delay_ns:
            r.due.append(t_ns + r.delay_ns)
        else:
            todo.append(r)

    def _mark_start(self, t_ns: int) -> None:
        """A `ping` carrying the controller time of the first scan to every robot the scenario drives: the
        simulator's log then lines up both clocks from the start, before the first action."""
        if self.link is None:
            return
        for robot in sorted({r.action.robot for r in self.sc.robots if r.action.robot is not None}):
            request = {"cmd": "ping", "robot": robot - 1, "plc_time": round(t_ns / 1e9, 6)}
            if self.wait:
                self.link.send_now(request, "start of the run")
            else:
                self.link.post(request, "start of the run")

    def _act(self, r: Reaction, t_ns: int) -> None:
        a = r.action
        if a.path is not None:
            self._write(a.path, a.value, r.where)
            return
        if a.robot is None or a.request is None:      # an action is a `set` line or a `robot` line
            raise RuntimeError(f"{r.where}: an action neither writes a variable nor commands a robot")
        if self.link is None:                         # run.py connects the control channel for `robot` lines
            raise RuntimeError(f"{r.where}: a `robot` line without the simulator's control channel")
        request = {**a.request, "robot": a.robot - 1, "plc_time": round(t_ns / 1e9, 6)}
        self.say(f"{t_ns / 1e9:10.3f} s  robot {a.robot}: {a.words} ({r.where})", flush=True)
        if self.wait:
            self.link.send_now(request, r.where)
        else:
            self.link.post(request, r.where)

    def _write(self, path: str, value: Any, where: str) -> None:
        try:
            self.plc.write(path, value)
        except PathError as exc:
            if self.failure is None:
                self.failure = f"{where}: {exc}"

    def collect_refusals(self) -> None:
        if self.link is None:
            return
        for text in self.link.refusals():
            if self.failure is None:
                self.failure = text

    def after_scan(self, t_ns: int) -> None:
        """Judge the expectations whose variable changed, that are due for their first look, or whose window
        ends now; an expectation whose variable kept its value keeps its verdict."""
        self._sample(t_ns)
        due = [e for s in self.changed for e in s.expects if e.state == "open" and e.from_ns <= t_ns] \
            if self.changed else []
        while self.unchecked and self.unchecked[0].from_ns <= t_ns:
            e = self.unchecked.pop(0)
            if e.last is None and e not in due:
                due.append(e)
        if self.deadline is not None and t_ns >= self.deadline:
            due += [e for e in self.sc.expects if e.state == "open" and e.until_ns is not None
                    and e.until_ns <= t_ns and e not in due]
            self.deadline = min((e.until_ns for e in self.sc.expects if e.state == "open" and e.until_ns is not None
                                 and e.until_ns > t_ns), default=None)
        for e in due:
            if e.state == "open":
                self._check(e, t_ns)

    def _check(self, e: Expect, t_ns: int) -> None:
        sig = e.sig
        if sig is None:
            raise RuntimeError(f"{e.where}: expectation judged before the runner watched {e.path}")
        v = sig.value
        e.last, e.since_ns = v, sig.since_ns
        ok = e.test(v)
        if ok and not e.always:
            e.state, e.decided_ns = "held", t_ns
            self.undecided -= 1
        elif not ok and (e.always or e.until_ns is None or t_ns >= e.until_ns):
            e.state, e.decided_ns = "failed", t_ns
            self.undecided -= not e.always
            if self.failure is None:
                self.first = e
                self.failure = (f"expectation failed at {seconds(t_ns)}: {e.source} ({e.where}); "
                                f"{e.path} is {fmt(v)}")

    def finished(self, t_ns: int) -> bool:
        """The run ends at a failure, at `stop`, or, when the scenario ends by itself (``Scenario.ends``), as soon
        as every write and timed robot action is done and every `within` / `at` expectation decided."""
        if self.failure is not None:
            return True
        if self.sc.stop_ns is not None:
            return t_ns >= self.sc.stop_ns
        if self.undecided or not self.ends or self.writes:
            return False                       # (kept as counts and lists: this is asked before every scan)
        return all(r.fired and not r.due for r in self.timed)

    def end_check(self, t_ns: int) -> str | None:
        """After the last scan: the reason the run did not do what the scenario asked, or None."""
        self.collect_refusals()
        if self.failure is not None:
            return self.failure
        for e in self.sc.expects:
            if e.always and e.state == "open" and e.from_ns <= t_ns:
                e.state = "held"                   # held at every scan to the end
            if e.state == "open":
                return (f"expectation not decided: the run ended at {seconds(t_ns)} before `{e.source}` "
                        f"({e.where}) was reached; {e.path} is {fmt(self.plc.read(e.path))}")
        return None

    def unmet(self, t_ns: int) -> list[str]:
        """Every expectation that failed or was left open, with the value it last had and since when; the first
        failure marked. Empty when fewer than two (the last line then says all there is)."""
        lines = []
        for e in self.sc.expects:
            if e.state == "failed":
                mark = " (first)" if e is self.first else ""
                head = f"failed at {seconds(e.decided_ns or 0)}{mark}"
            elif e.state == "open" and not (e.always and e.from_ns <= t_ns):
                head = "not decided"
            else:
                continue
            last = (f"{e.path} was {fmt(e.last)} since {seconds(e.since_ns)}" if e.last is not None
                    else f"{e.path} was never checked (from {seconds(e.from_ns)})")
            lines.append(f"  {head}: {e.source} ({e.where}); {last}")
        return lines if len(lines) > 1 else []


def _index(r: Reaction) -> int:
    return r.index
