"""Commissioning scenarios for ``vplc run``: timed writes, reactions, simulator actions and expectations.

    # comment (a `#` at the start of a line or after a blank)
    at 2s set Main.Start TRUE              write a variable when the run reaches 2 s
    expect Main.Placed = 12 within 60s     must hold at some scan before 60 s, else the run fails there
    at 5s expect Main.Busy = FALSE         must hold at the first scan at or after 5 s
    at 5s expect Main.Error = FALSE within 1s
    expect Main.Error = FALSE always       must hold at every scan from its time to the end of the run
    at 90s stop                            end the run (without it: when every write, `at` robot line and
                                           `within`/`at` expectation is done; runtime.md section 6)
    at 5s robot 1 cut_link                 a request on the simulator's control channel (--sim-control)
    when Main.Moves >= 80 robot 1 estop    ... when a condition becomes true
    when Main.Alarm = TRUE for 1s then set Main.Reset TRUE after 200ms every time
                                           a reaction: the operator or a machine, without PLC code

Times count from the first scan (written without a blank: 60s). A condition is one or more `VAR OP VALUE` of
an elementary variable joined by `and` (no `or`); `time` is the controller time (`when time >= 5s and Main.Busy
= FALSE ...`). A reaction fires on the scan its condition becomes true (held for `for T` when given), once, or
again each time it becomes true with `every time`; its action runs `after T` later (before that scan).
Operators: = <> < <= > >=. Values are ST literals of the variable's type (TRUE, 12, -3.5, 16#FF, 'text',
T#250ms, an enumeration value's name) that the variable can hold. ``--set VAR=VALUE@TIME`` on the command line
is the same as ``at TIME set VAR VALUE``.
"""
from __future__ import annotations

import operator
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

from ..frontend import types as T
from ..frontend.parser_exprs import parse_duration as parse_time_literal
from ..frontend.source import FileRefused, read_file_bytes
from ..runtime.values import PathError, from_python, parse_duration
from . import simlink

if TYPE_CHECKING:
    from ..api import Plc


class Watched(Protocol):
    """What the runner's watch of one variable offers the lines that read it (scenario_run.Signal): its value after
    the last scan, since when it has it, and the reactions and expectations to judge again when it changes."""
    value: Any
    since_ns: int
    reactions: list[Reaction]
    expects: list[Expect]


class ScenarioError(ValueError):
    """A scenario line that cannot be understood; str() names the file and line."""


def _not_built(_value: object) -> bool:
    """The comparison of a condition or an expectation before a Runner (scenario_run) built it."""
    raise RuntimeError("the scenario runner has not built this comparison yet")


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
    sig: Watched | None = None    # the watched variable and the comparator, built by Runner
    test: Callable[[Any], bool] = _not_built


@dataclass
class Term:
    """`VAR OP VALUE` of a condition; ``path`` None is the controller time (`time >= 5s`)."""
    path: str | None
    op: str
    text: str
    value: object = None
    sig: Watched | None = None    # the watched variable and the comparator, built by Runner
    test: Callable[[Any], bool] = _not_built


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
    files: list[str] = field(default_factory=list)      # the scenario files read (``load``)

    @property
    def empty(self) -> bool:
        return not self.writes and not self.expects and not self.reactions and self.stop_ns is None

    @property
    def ends(self) -> bool:
        """The scenario ends the run by itself: it has an `at ... stop`, a `within` / `at` expectation, an
        `at ... robot` line, or a scenario file with writes (``--set`` lines alone leave the run to Ctrl-C,
        --cycles or --duration). `when` lines and `always` expectations never end a run."""
        return (self.stop_ns is not None or any(not e.always for e in self.expects)
                or any(r.timed for r in self.reactions) or bool(self.files and self.writes))

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
MAX_FILE_BYTES = 4 * 1024 * 1024   # a scenario file: far more lines than MAX_REACTIONS of any length one needs


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


_SPACED_TIME = re.compile(r"\b(at|within|for|after)\s+(\d+(?:\.\d+)?)\s+(ns|us|µs|ms|s|m|h)\b", re.IGNORECASE)
_OR = re.compile(r"\s(or|xor)\s", re.IGNORECASE)
_JUDGED = re.compile(r"^(?:at\s+\S+\s+)?(?:when|expect)\s", re.IGNORECASE)    # lines with conditions


def _unquoted(text: str) -> str:
    """``text`` with its quoted strings emptied: what is left is keywords, names and numbers."""
    return re.sub(r"'[^']*'|\"[^\"]*\"", "''", text)


def _check_words(text: str, where: str) -> None:
    """Mistakes that would otherwise surface as a value that does not fit: a time written with a blank
    (`within 60 s`) and conditions joined by `or`."""
    bare = _unquoted(text)
    m = _SPACED_TIME.search(bare)
    if m:
        raise ScenarioError(f"{where}: `{m.group(0)}`: write the time without a blank between number and unit, "
                            f"like `{m.group(1)} {m.group(2)}{m.group(3)}` (2s, 250ms, 1.5s)")
    m = _OR.search(bare)
    if m and _JUDGED.match(bare):
        raise ScenarioError(f"{where}: `{m.group(1)}` cannot join conditions: only `and` does (`when A = TRUE and "
                            f"B = FALSE ...`); for either of two conditions write one line for each")


def parse_line(line: str, where: str, sc: Scenario) -> None:
    text = _strip_comment(line)
    if not text:
        return
    _check_words(text, where)
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
    if m is None or not number.isdigit() or int(number) < 1:
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
        lines = read_file_bytes(filename, MAX_FILE_BYTES).decode("utf-8").splitlines()
    except OSError as exc:
        raise ScenarioError(f"cannot read scenario {filename}: {exc.strerror or exc}") from None
    except FileRefused as exc:
        raise ScenarioError(f"cannot read scenario {filename}: it {exc}") from None
    except UnicodeDecodeError:
        raise ScenarioError(f"scenario {filename} is not UTF-8 text") from None
    for n, line in enumerate(lines, 1):
        parse_line(line, f"{filename}:{n}", sc)
    sc.files.append(filename)
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
        if r.action.robot is not None and r.action.robot > count:
            raise ScenarioError(f"{r.where}: robot {r.action.robot} does not exist: the simulator at {where} "
                                f"has {count} robot{'s' if count != 1 else ''} (robot 1 to {count})")


# ---- values -------------------------------------------------------------------------------------
def parse_value(plc: Plc, path: str, text: str, compared: bool = False) -> Any:
    """An ST literal for the variable at ``path`` -> the API value (bool/int/float/str); PathError if it
    does not fit the variable's type (its range, its enumeration values, its STRING capacity: what a write
    would refuse). ``compared``: the value of a condition or an expectation, not of a write."""
    t = plc.type_of(path)
    value = _literal(plc, path, t, text, compared)
    from_python(value, t, path)          # the check the write makes, made before the first scan
    return value


def _literal(plc: Plc, path: str, t: T.Type, text: str, compared: bool) -> Any:
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
        if compared:
            members = _members(u)
            example = f", e.g. `{path}.{members[0]}`" if members else ""
            raise PathError(f"{path} is a {tn}: a condition or an expectation compares one elementary "
                            f"variable; name one of its members{example}")
        raise PathError(f"{path} is a {tn}; set its elementary members one by one")
    if "#" in s and u.kind not in ("time", "ltime"):
        prefix, _, rest = s.partition("#")
        # based literal (16#FF) or typed literal (INT#5, BOOL#TRUE)
        s = str(_int(rest, int(prefix), bad)) if prefix.isdigit() else rest
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
        prefix, sep, body = s.partition("#")
        # an ST TIME literal with several units or a sign (T#1s500ms, TIME#-2s) is read as the compiler reads it
        ns = parse_time_literal(body) if sep and prefix.upper() in ("T", "TIME", "LT", "LTIME") \
            else parse_duration(s)
        if ns is None:
            raise bad
        return ns
    if u.kind in ("int", "uint", "bit"):
        return _int(s, 10, bad)
    raise PathError(f"{path} ({tn}) cannot be set from a scenario")


def _members(u: T.Type) -> list[str]:
    """Member names of a structure or a function block instance (its outputs first), for a message."""
    if isinstance(u, T.StructType):
        return [f.name for f in u.fields.values()]
    if isinstance(u, T.PouType):
        return [p.name for p in sorted(u.params, key=lambda p: p.direction != "out")]
    return []


def _int(s: str, base: int, bad: Exception) -> int:
    try:
        return int(s.replace("_", ""), base)
    except ValueError:
        raise bad from None


def compare(a: Any, op: str, b: Any) -> bool:
    if isinstance(a, str) and isinstance(b, str):
        a, b = a.upper(), b.upper()
    if op == "=":
        return a == b if not isinstance(a, float) else abs(a - b) <= 1e-6 * max(1.0, abs(b))
    if op == "<>":
        return not compare(a, "=", b)
    try:
        return ORDERINGS[op](a, b)
    except TypeError:
        return False


def resolve(plc: Plc, sc: Scenario) -> None:
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


def _resolve_term(plc: Plc, term: Term | Expect, where: str) -> None:
    path = term.path
    if path is None:                          # `time`: its value was read with the line
        return
    try:
        t = plc.type_of(path)
        term.value = _literal(plc, path, t, term.text, compared=True)
    except PathError as exc:
        raise ScenarioError(f"{where}: {exc}") from None
    try:
        from_python(term.value, t, path)
    except PathError as exc:                  # issue 27: a condition that can never be evaluated is a mistake
        raise ScenarioError(f"{where}: `{path} {term.op} {term.text}` compares {path} with a value it can never "
                            f"hold: {exc}") from None
    if term.op not in ("=", "<>") and isinstance(term.value, (bool, str)):
        raise ScenarioError(f"{where}: `{term.op}` compares numbers; {path} is a {plc.var_type(path)}")


# the ordering comparisons a condition or an expectation may use, by their ST spelling (= and <> compare any value)
ORDERINGS = {"<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge}


def seconds(t_ns: int) -> str:
    return f"{t_ns / 1e9:.3f} s"


def fmt(v: Any) -> str:
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, str):
        return v
    return str(v)
