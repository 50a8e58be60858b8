"""Commissioning scenarios for ``vplc run``: timed writes, reactions, simulator actions and expectations.

    # comment (a `#` at the start of a line or after a blank)
    at 2s set Main.Start TRUE              write a variable when the run reaches 2 s
    expect Main.Placed = 12 within 60s     must hold at some scan before 60 s, else the run fails there
    at 5s expect Main.Busy = FALSE         must hold at the first scan at or after 5 s
    at 5s expect Main.Error = FALSE within 1s
    expect Main.Error = FALSE always       must hold at every scan from its time to the end of the run
    at 90s stop                            end the run (without it: when every line has been decided)
    at 5s robot 1 cut_link                 a request on the simulator's control channel (--sim-control)
    when Main.Moves >= 80 robot 1 estop    ... when a condition becomes true
    when Main.Alarm = TRUE for 1s then set Main.Reset TRUE after 200ms every time
                                           a reaction: the operator or a machine, without PLC code

Times count from the first scan. A condition is one or more `VAR OP VALUE` joined by `and`; `time` is the
controller time (`when time >= 5s and Main.Busy = FALSE ...`). A reaction fires on the scan its condition becomes
true (held for `for T` when given), once, or again each time it becomes true with `every time`; its action runs
`after T` later (before that scan). Operators: = <> < <= > >=. Values are ST literals of the variable's type
(TRUE, 12, -3.5, 16#FF, 'text', T#250ms, an enumeration value's name). ``--set VAR=VALUE@TIME`` on the command
line is the same as ``at TIME set VAR VALUE``.
"""
from __future__ import annotations

import operator
import re
from dataclasses import dataclass, field

from ..frontend import types as T
from ..runtime.values import PathError, parse_duration
from . import simlink


class ScenarioError(ValueError):
    """A scenario line that cannot be understood; str() names the file and line."""


@dataclass
class Write:
    at_ns: int
    path: str
    text: str
    where: str
    done: bool = False
    value: object = None


@dataclass
class Expect:
    from_ns: int
    until_ns: int | None          # None: checked once, at the first scan at or after from_ns
    always: bool
    path: str
    op: str
    text: str
    where: str
    source: str
    value: object = None
    state: str = "open"           # open, held, failed
    last: object = None
    since_ns: int = 0             # when ``last`` became the variable's value
    decided_ns: int | None = None
    sig: object = None            # the watched Signal and the comparator, built by Runner
    test: object = None


@dataclass
class Term:
    """`VAR OP VALUE` of a condition; ``path`` None is the controller time (`time >= 5s`)."""
    path: str | None
    op: str
    text: str
    value: object = None
    sig: object = None            # the watched Signal and the comparator, built by Runner
    test: object = None


@dataclass
class Action:
    path: str | None = None       # `set VAR VALUE`
    text: str = ""
    value: object = None
    robot: int | None = None      # `robot N COMMAND ...`: N counted from 1, the words and the control request
    words: str = ""
    request: dict | None = None


@dataclass
class Reaction:
    """An `at TIME robot ...` line (timed: its condition is `time >= TIME`) or a `when` line."""
    terms: list[Term]
    hold_ns: int                  # `for T`: the condition must stay true this long
    delay_ns: int                 # `after T`: the action runs this long after the reaction fired
    every: bool                   # `every time`: fires again each time the condition becomes true
    action: Action
    where: str
    source: str
    timed: bool = False
    armed: bool = True            # the condition was false since the last firing (edge)
    true_since: int | None = None
    fired: int = 0
    due: list[int] = field(default_factory=list)
    index: int = 0                # file order (actions of one scan run in it)
    clock: bool = False           # judged every scan: a `time` term, a `for` running or an action due
    mark: int = -1


@dataclass
class Scenario:
    writes: list[Write] = field(default_factory=list)
    expects: list[Expect] = field(default_factory=list)
    reactions: list[Reaction] = field(default_factory=list)
    stop_ns: int | None = None

    @property
    def empty(self) -> bool:
        return not self.writes and not self.expects and not self.reactions and self.stop_ns is None

    @property
    def robots(self) -> list[Reaction]:
        """The lines that act on the simulator, in file order."""
        return [r for r in self.reactions if r.action.robot is not None]


_OPS = ("<>", "<=", ">=", "=", "<", ">")
_AT = re.compile(r"^at\s+(\S+)\s+(.*)$", re.IGNORECASE)
_SET = re.compile(r"^set\s+(\S+?)\s*(?::=|=|\s)\s*(.+)$", re.IGNORECASE)
_EXPECT = re.compile(r"^expect\s+(\S+?)\s*(<>|<=|>=|=|<|>)\s*(.+?)(?:\s+within\s+(\S+)|\s+(always))?$",
                     re.IGNORECASE)
_WHEN = re.compile(r"^when\s+(.+?)(?:\s+for\s+(\S+))?\s+(?:then\s+)?((?:set|robot)\s.+)$", re.IGNORECASE)
_TERM = re.compile(r"^(\S+?)\s*(<>|<=|>=|=|<|>)\s*(.+)$")
_ROBOT = re.compile(r"^robot\s+(\S+)\s*(.*)$", re.IGNORECASE)
_EVERY = re.compile(r"^(.*?)\s+every\s+time$", re.IGNORECASE)
_AFTER = re.compile(r"^(.*?)\s+after\s+(\S+)$", re.IGNORECASE)
_AND = re.compile(r"\s+and\s+", re.IGNORECASE)
MAX_REACTIONS = 10_000          # lines that act or react, per scenario (each is evaluated every scan)


def _time(text: str, where: str, what: str) -> int:
    ns = parse_duration(text) if re.search(r"[a-zA-Zµ]", text.removeprefix("T#").removeprefix("t#")) else None
    if ns is None or ns < 0:
        raise ScenarioError(f"{where}: {what} `{text}` is not a time like 2s, 250ms or 1.5s")
    return ns


def _strip_comment(line: str) -> str:
    """A comment starts with `#` at the start of the line or after a blank (16#FF and T#2s are values)."""
    quoted = False
    for i, ch in enumerate(line):
        if ch == "'":
            quoted = not quoted
        elif ch == "#" and not quoted and (i == 0 or line[i - 1].isspace()):
            return line[:i].strip()
    return line.strip()


def parse_line(line: str, where: str, sc: Scenario) -> None:
    text = _strip_comment(line)
    if not text:
        return
    at_ns, rest, timed = 0, text, False
    m = _AT.match(text)
    if m:
        at_ns, rest, timed = _time(m.group(1), where, "time"), m.group(2).strip(), True
    if rest.lower() == "stop":
        if not timed:
            raise ScenarioError(f"{where}: `stop` needs a time: `at 60s stop`")
        sc.stop_ns = at_ns if sc.stop_ns is None else min(sc.stop_ns, at_ns)
        return
    if rest.lower().startswith("when ") and not timed:
        _add_reaction(sc, _when(rest, where))
        return
    m = _SET.match(rest)
    if m:
        if not timed:
            raise ScenarioError(f"{where}: `set` needs a time: `at 0s {rest}`")
        sc.writes.append(Write(at_ns, m.group(1), m.group(2).strip(), where))
        return
    if _ROBOT.match(rest):
        if not timed:
            raise ScenarioError(f"{where}: `robot` needs a time or a condition: `at 5s {rest}` or "
                                f"`when Main.Moves >= 80 {rest}`")
        _add_reaction(sc, Reaction([Term(None, ">=", "", at_ns)], 0, 0, False, _robot(rest, where), where, text,
                                   timed=True))
        return
    m = _EXPECT.match(rest)
    if m:
        until = None if m.group(4) is None else at_ns + _time(m.group(4), where, "window")
        sc.expects.append(Expect(at_ns, until, m.group(5) is not None, m.group(1), m.group(2), m.group(3).strip(),
                                 where, rest))
        return
    raise ScenarioError(f"{where}: cannot read `{text}`; expected `at TIME set VAR VALUE`, "
                        f"`at TIME robot N COMMAND`, `when CONDITION [for TIME] then ACTION [after TIME] "
                        f"[every time]`, `[at TIME] expect VAR = VALUE [within TIME | always]` or `at TIME stop`")


def _add_reaction(sc: Scenario, reaction: Reaction) -> None:
    if len(sc.reactions) >= MAX_REACTIONS:
        raise ScenarioError(f"{reaction.where}: more than {MAX_REACTIONS:,} `when` and `robot` lines")
    sc.reactions.append(reaction)


def _when(text: str, where: str) -> Reaction:
    """# grammar: when COND {and COND} [for TIME] [then] (set VAR VALUE | robot N CMD ...) [after TIME] [every time]"""
    m = _WHEN.match(text)
    if not m:
        raise ScenarioError(f"{where}: cannot read `{text}`; expected `when VAR OP VALUE [for TIME] then "
                            f"set VAR VALUE [after TIME] [every time]` or `when VAR OP VALUE robot N COMMAND`")
    cond, hold, action = m.group(1), m.group(2), m.group(3).strip()
    every, delay = False, None
    for _ in range(2):                       # `after T` and `every time`, in either order
        e = _EVERY.match(action)
        if e and not every:
            every, action = True, e.group(1)
            continue
        a = _AFTER.match(action)
        if a and delay is None:
            delay, action = _time(a.group(2), where, "delay"), a.group(1)
    terms = []
    for part in _AND.split(cond):
        t = _TERM.match(part.strip())
        if not t:
            raise ScenarioError(f"{where}: condition `{part.strip()}` is not `VAR OP VALUE` (OP one of "
                                f"{' '.join(_OPS)}), e.g. `Main.Alarm = TRUE` or `time >= 5s`")
        if t.group(1).lower() == "time":
            terms.append(Term(None, t.group(2), t.group(3).strip(), _time(t.group(3).strip(), where, "time")))
        else:
            terms.append(Term(t.group(1), t.group(2), t.group(3).strip()))
    hold_ns = _time(hold, where, "hold time") if hold else 0
    if action.lower().startswith("robot"):
        act = _robot(action, where)
    else:
        s = _SET.match(action)
        if not s:
            raise ScenarioError(f"{where}: cannot read the action `{action}`; expected `set VAR VALUE` or "
                                f"`robot N COMMAND`")
        act = Action(path=s.group(1), text=s.group(2).strip())
    return Reaction(terms, hold_ns, delay or 0, every, act, where, text)


def _robot(text: str, where: str) -> Action:
    m = _ROBOT.match(text)
    number = m.group(1) if m else ""
    if not number.isdigit() or int(number) < 1:
        raise ScenarioError(f"{where}: `robot {number}`: robots are numbered from 1, as the simulator's "
                            f"start-up lines count them")
    try:
        request = simlink.build_request(m.group(2).split())
    except simlink.CommandError as exc:
        raise ScenarioError(f"{where}: {exc}") from None
    return Action(robot=int(number), words=" ".join(m.group(2).split()), request=request)


def load(filename: str, sc: Scenario | None = None) -> Scenario:
    sc = sc or Scenario()
    try:
        with open(filename, encoding="utf-8") as f:
            lines = f.read().splitlines()
    except OSError as exc:
        raise ScenarioError(f"cannot read scenario {filename}: {exc.strerror}") from None
    except UnicodeDecodeError:
        raise ScenarioError(f"scenario {filename} is not UTF-8 text") from None
    for n, line in enumerate(lines, 1):
        parse_line(line, f"{filename}:{n}", sc)
    return sc


def add_set_option(text: str, sc: Scenario) -> None:
    """``--set VAR=VALUE@TIME`` (``@TIME`` optional, default 0 s)."""
    m = re.fullmatch(r"\s*([^=\s]+)\s*:?=\s*(.+?)\s*(?:@\s*([^@']+))?\s*", text)
    if not m:
        raise ScenarioError(f"--set {text!r} is not of the form VAR=VALUE@TIME (e.g. Main.Start=TRUE@2s)")
    at = _time(m.group(3).strip(), "--set", "time") if m.group(3) else 0
    sc.writes.append(Write(at, m.group(1), m.group(2), f"--set {text}"))


def check_robots(sc: Scenario, count: int, where: str) -> None:
    """Every `robot N` line names one of the ``count`` robots of the simulator at ``where``."""
    for r in sc.robots:
        if r.action.robot > count:
            raise ScenarioError(f"{r.where}: robot {r.action.robot} does not exist: the simulator at {where} "
                                f"has {count} robot{'s' if count != 1 else ''} (robot 1 to {count})")


# ---- values -------------------------------------------------------------------------------------
def parse_value(plc, path: str, text: str):
    """An ST literal for the variable at ``path`` -> the API value (bool/int/float/str); PathError if it
    does not fit the variable's type."""
    t = plc._resolver._locate(path)[2]
    u = T.base_of(t)
    tn = plc.var_type(path)
    s = text.strip()
    bad = PathError(f"`{s}` is not a value for {path} ({tn})")
    if isinstance(u, T.EnumType):
        return s.split("#")[-1]
    if isinstance(u, T.StringType):
        if len(s) >= 2 and s[0] == s[-1] and s[0] in "'\"":
            return s[1:-1]
        raise PathError(f"`{s}`: write a text for {path} ({tn}) in quotes, e.g. '{s}'")
    if not isinstance(u, T.ElementaryType):
        raise PathError(f"{path} is a {tn}; set its elementary members one by one")
    if "#" in s and u.kind not in ("time", "ltime"):
        prefix, _, rest = s.partition("#")
        if prefix.isdigit():
            s = str(_int(rest, int(prefix), bad))
        else:
            s = rest                               # typed literal: INT#5, BOOL#TRUE
    if u.kind == "bool":
        if s.upper() in ("TRUE", "1"):
            return True
        if s.upper() in ("FALSE", "0"):
            return False
        raise bad
    if u.kind == "real":
        try:
            return float(s.replace("_", ""))
        except ValueError:
            raise bad from None
    if u.kind in ("time", "ltime"):
        ns = parse_duration(s)
        if ns is None:
            raise bad
        return ns
    if u.kind in ("int", "uint", "bit"):
        return _int(s, 10, bad)
    raise PathError(f"{path} ({tn}) cannot be set from a scenario")


def _int(s: str, base: int, bad: Exception) -> int:
    try:
        return int(s.replace("_", ""), base)
    except ValueError:
        raise bad from None


def compare(a, op: str, b) -> bool:
    if isinstance(a, str) and isinstance(b, str):
        a, b = a.upper(), b.upper()
    if op == "=":
        return a == b if not isinstance(a, float) else abs(a - b) <= 1e-6 * max(1.0, abs(b))
    if op == "<>":
        return not compare(a, "=", b)
    try:
        return _ORDER[op](a, b)
    except TypeError:
        return False


def resolve(plc, sc: Scenario) -> None:
    """Check every path and value against the loaded program before the first scan."""
    for w in sc.writes:
        try:
            w.value = parse_value(plc, w.path, w.text)
            plc.read(w.path)
        except PathError as exc:
            raise ScenarioError(f"{w.where}: {exc}") from None
    for e in sc.expects:
        _resolve_term(plc, e, e.where)
    for r in sc.reactions:
        for term in r.terms:
            if term.path is not None:
                _resolve_term(plc, term, r.where)
        if r.action.path is not None:
            try:
                r.action.value = parse_value(plc, r.action.path, r.action.text)
                plc.read(r.action.path)
            except PathError as exc:
                raise ScenarioError(f"{r.where}: {exc}") from None


def _resolve_term(plc, term, where: str) -> None:
    try:
        term.value = parse_value(plc, term.path, term.text)
    except PathError as exc:
        raise ScenarioError(f"{where}: {exc}") from None
    if term.op not in ("=", "<>") and isinstance(term.value, (bool, str)):
        raise ScenarioError(f"{where}: `{term.op}` compares numbers; {term.path} is a {plc.var_type(term.path)}")


_UNSEEN = object()
_ORDER = {"<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge}


class Signal:
    """One variable a scenario watches: sampled once after every scan; the reactions and expectations on it are
    judged again only when it changed (what keeps 100 `when` lines cheap). A variable declared directly in a
    program instance or a global list is read straight from its instance, which lives as long as the controller;
    anything deeper (members, array elements, whose containers an assignment may replace) through ``plc.read``."""

    __slots__ = ("container", "conv", "expects", "key", "path", "raw", "reactions", "read", "since_ns", "stamp",
                 "value")

    def __init__(self, plc, path: str) -> None:
        from ..runtime.values import converter
        res = plc._resolver
        container, key, t = res._locate(path)
        root, steps = res._parse(path)
        owner = plc.instances[root] if root is not None else plc.globals
        self.path, self.read = path, None
        if len(steps) == 1 and not steps[0][3] and container is getattr(owner, "__dict__", None):
            self.container, self.key, self.conv = container, key, converter(t)
        else:
            self.container, self.key, self.conv = None, None, _same
            self.read = lambda: plc.read(path)
        self.raw, self.value, self.since_ns, self.stamp = _UNSEEN, None, 0, -1
        self.reactions: list[Reaction] = []
        self.expects: list[Expect] = []


def _same(v):
    return v


def _one(key):
    return lambda container: (container[key],)


def comparator(op: str, b):
    """``v -> v OP b`` for the value ``b`` of a condition or an expectation (what ``compare`` does, built once)."""
    if isinstance(b, str):
        b = b.upper()
        return (lambda a: isinstance(a, str) and a.upper() == b) if op == "=" else \
            (lambda a: not (isinstance(a, str) and a.upper() == b))
    if isinstance(b, float):
        return lambda a: compare(a, op, b)
    if op in _ORDER:
        order = _ORDER[op]
        return lambda a: order(a, b)
    return (lambda a: a == b) if op == "=" else (lambda a: a != b)


class Runner:
    """Applies the writes and reactions due before a scan and judges the expectations after it. ``link`` is the
    simulator's control channel (``simlink.SimControl``) for `robot` lines; ``wait`` sends each request and waits
    for its answer (virtual time), otherwise requests leave from a sender thread and the scan never waits."""

    def __init__(self, plc, sc: Scenario, link=None, wait: bool = False, say=print) -> None:
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
        groups: dict[int, list[Signal]] = {}       # direct signals by the instance they live in
        for sig in self.signals.values():
            if sig.read is None:
                groups.setdefault(id(sig.container), []).append(sig)
        # one C-level read of all of an instance's watched variables a scan: [container, getter, signals, last]
        self.direct = [[sigs[0].container, operator.itemgetter(*[x.key for x in sigs]) if len(sigs) > 1 else
                        _one(sigs[0].key), sigs, None] for sigs in groups.values()]
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
                for s, raw in zip(group[2], values):
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
        for robot in sorted({r.action.robot for r in self.sc.robots}):
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
        request = {**a.request, "robot": a.robot - 1, "plc_time": round(t_ns / 1e9, 6)}
        self.say(f"{t_ns / 1e9:10.3f} s  robot {a.robot}: {a.words} ({r.where})", flush=True)
        if self.wait:
            self.link.send_now(request, r.where)
        else:
            self.link.post(request, r.where)

    def _write(self, path, value, where) -> None:
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
        due = [e for s in self.changed for e in s.expects if e.state == "open" and e.from_ns <= t_ns]
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
        v = e.sig.value
        e.last, e.since_ns = v, e.sig.since_ns
        ok = e.test(v)
        if ok and not e.always:
            e.state, e.decided_ns = "held", t_ns
        elif not ok and (e.always or e.until_ns is None or t_ns >= e.until_ns):
            e.state, e.decided_ns = "failed", t_ns
            if self.failure is None:
                self.first = e
                self.failure = (f"expectation failed at {seconds(t_ns)}: {e.source} ({e.where}); "
                                f"{e.path} is {fmt(v)}")

    def finished(self, t_ns: int) -> bool:
        """The run ends at a failure, at `stop`, or when every write and timed robot action is done and every
        expectation decided."""
        if self.failure is not None:
            return True
        if self.sc.stop_ns is not None:
            return t_ns >= self.sc.stop_ns
        if not self.sc.expects:
            return False
        return all(w.done for w in self.sc.writes) and \
            all(r.fired and not r.due for r in self.sc.reactions if r.timed) and \
            all(e.state != "open" for e in self.sc.expects if not e.always) and \
            any(not e.always for e in self.sc.expects)

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
                head = f"failed at {seconds(e.decided_ns)}{mark}"
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


def seconds(t_ns: int) -> str:
    return f"{t_ns / 1e9:.3f} s"


def fmt(v) -> str:
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, str):
        return v
    return str(v)
