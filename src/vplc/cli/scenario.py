"""Commissioning scenarios for ``vplc run``: timed writes and expectations, one per line.

    # comment (a `#` at the start of a line or after a blank)
    at 2s set Main.Start TRUE              write a variable when the run reaches 2 s
    expect Main.Placed = 12 within 60s     must hold at some scan before 60 s, else the run fails there
    at 5s expect Main.Busy = FALSE         must hold at the first scan at or after 5 s
    at 5s expect Main.Error = FALSE within 1s
    expect Main.Error = FALSE always       must hold at every scan from its time to the end of the run
    at 90s stop                            end the run (without it: when every line has been decided)

Times count from the first scan. Operators: = <> < <= > >=. Values are ST literals of the variable's type
(TRUE, 12, -3.5, 16#FF, 'text', T#250ms, an enumeration value's name). ``--set VAR=VALUE@TIME`` on the command
line is the same as ``at TIME set VAR VALUE``.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

from ..frontend import types as T
from ..runtime.values import PathError, parse_duration


class ScenarioError(ValueError):
    """A scenario line that cannot be understood; str() names the file and line."""


@dataclass
class Write:
    at_ns: int
    path: str
    text: str
    where: str
    done: bool = False


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


@dataclass
class Scenario:
    writes: list[Write] = field(default_factory=list)
    expects: list[Expect] = field(default_factory=list)
    stop_ns: int | None = None

    @property
    def empty(self) -> bool:
        return not self.writes and not self.expects and self.stop_ns is None


_OPS = ("<>", "<=", ">=", "=", "<", ">")
_AT = re.compile(r"^at\s+(\S+)\s+(.*)$", re.IGNORECASE)
_SET = re.compile(r"^set\s+(\S+?)\s*(?::=|=|\s)\s*(.+)$", re.IGNORECASE)
_EXPECT = re.compile(r"^expect\s+(\S+?)\s*(<>|<=|>=|=|<|>)\s*(.+?)(?:\s+within\s+(\S+)|\s+(always))?$",
                     re.IGNORECASE)


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
    m = _SET.match(rest)
    if m:
        if not timed:
            raise ScenarioError(f"{where}: `set` needs a time: `at 0s {rest}`")
        sc.writes.append(Write(at_ns, m.group(1), m.group(2).strip(), where))
        return
    m = _EXPECT.match(rest)
    if m:
        until = None if m.group(4) is None else at_ns + _time(m.group(4), where, "window")
        sc.expects.append(Expect(at_ns, until, m.group(5) is not None, m.group(1), m.group(2), m.group(3).strip(),
                                 where, rest))
        return
    raise ScenarioError(f"{where}: cannot read `{text}`; expected `at TIME set VAR VALUE`, "
                        f"`[at TIME] expect VAR = VALUE [within TIME | always]` or `at TIME stop`")


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
        return {"<": a < b, "<=": a <= b, ">": a > b, ">=": a >= b}[op]
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
        try:
            e.value = parse_value(plc, e.path, e.text)
        except PathError as exc:
            raise ScenarioError(f"{e.where}: {exc}") from None
        if e.op not in ("=", "<>") and isinstance(e.value, (bool, str)):
            raise ScenarioError(f"{e.where}: `{e.op}` compares numbers; {e.path} is a {plc.var_type(e.path)}")


class Runner:
    """Applies the writes due before a scan and judges the expectations after it."""

    def __init__(self, plc, sc: Scenario) -> None:
        self.plc, self.sc = plc, sc
        self.failure: str | None = None

    def before_scan(self, t_ns: int) -> None:
        for w in self.sc.writes:
            if not w.done and w.at_ns <= t_ns:
                try:
                    self.plc.write(w.path, w.value)
                except PathError as exc:
                    self.failure = f"{w.where}: {exc}"
                w.done = True

    def after_scan(self, t_ns: int) -> None:
        for e in self.sc.expects:
            if e.state != "open" or t_ns < e.from_ns:
                continue
            e.last = self.plc.read(e.path)
            ok = compare(e.last, e.op, e.value)
            if ok and not e.always:
                e.state = "held"
            elif not ok and (e.always or e.until_ns is None or t_ns >= e.until_ns):
                e.state = "failed"
                if self.failure is None:
                    self.failure = (f"expectation failed at {seconds(t_ns)}: {e.source} ({e.where}); "
                                    f"{e.path} is {fmt(e.last)}")

    def finished(self, t_ns: int) -> bool:
        """The run ends at a failure, at `stop`, or when every write is done and every expectation decided."""
        if self.failure is not None:
            return True
        if self.sc.stop_ns is not None:
            return t_ns >= self.sc.stop_ns
        if not self.sc.expects:
            return False
        return all(w.done for w in self.sc.writes) and \
            all(e.state != "open" for e in self.sc.expects if not e.always) and \
            any(not e.always for e in self.sc.expects)

    def end_check(self, t_ns: int) -> str | None:
        """After the last scan: the reason the run did not do what the scenario asked, or None."""
        if self.failure is not None:
            return self.failure
        for e in self.sc.expects:
            if e.always and e.state == "open" and e.from_ns <= t_ns:
                e.state = "held"                   # held at every scan to the end
            if e.state == "open":
                return (f"expectation not decided: the run ended at {seconds(t_ns)} before `{e.source}` "
                        f"({e.where}) was reached; {e.path} is {fmt(self.plc.read(e.path))}")
        return None


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
