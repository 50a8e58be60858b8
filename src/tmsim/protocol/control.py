"""The control channel's protocol, sans-I/O: one JSON request object per line in, one JSON answer per line out
(docs/simulator.md, "Control channel"). ``next_line(buf)`` frames the byte stream (``(line, consumed)``, 0 = need
more, as the frame codecs do); ``decode_request(line)`` checks a line (JSON, nesting, fields) and the field
checkers check each value, all raising RequestError with the answer's text; ``encode_answer`` writes an answer.
The TCP adapter and the table of commands are tmsim/net/control.py."""
from __future__ import annotations

import json
import math
import re

from tmsim.limits import CONTROL_DEPTH_MAX


class RequestError(ValueError):
    """A request that is not valid; its text is the answer's ``error``."""


def next_line(buf: bytes | bytearray) -> tuple[bytes | None, int]:
    """The first complete request line at the front of ``buf`` without its newline, and the bytes it takes;
    ``(None, 0)`` while no newline has arrived (the caller bounds what it keeps: CONTROL_LINE_MAX)."""
    end = buf.find(b"\n")
    if end < 0:
        return None, 0
    return bytes(buf[:end]), end + 1


FIELDS = {"cmd", "robot", "since", "fault", "params", "pressed", "mode", "period", "items", "write_permission",
           "plc_time", "name", "value"}
VISION_FIELDS = {"job", "objects", "pass", "seconds", "capture", "variable"}
FIELDS |= VISION_FIELDS
_BRACKETS = re.compile(rb'"(?:[^"\\]|\\.)*"|[\[\]{}]')


def decode_request(line: bytes) -> dict:
    if line.count(b"[") + line.count(b"{") > CONTROL_DEPTH_MAX:
        depth = deepest = 0
        for match in _BRACKETS.finditer(line):
            token = match.group()
            if token in (b"[", b"{"):
                depth += 1
                deepest = max(deepest, depth)
            elif token in (b"]", b"}"):
                depth -= 1
        if deepest > CONTROL_DEPTH_MAX:
            raise RequestError(f"request nested deeper than {CONTROL_DEPTH_MAX} levels")
    try:
        request = json.loads(line, parse_constant=_no_constant, parse_int=_small_int)
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise RequestError(f"a request must be one JSON object on one line ({exc})") from None
    except RecursionError:
        raise RequestError(f"request nested deeper than {CONTROL_DEPTH_MAX} levels") from None
    if not isinstance(request, dict):
        raise RequestError("a request must be a JSON object")
    unknown = sorted(set(request) - FIELDS)
    if unknown:
        raise RequestError(f"unknown field {unknown[0]!r}; known: {', '.join(sorted(FIELDS))}")
    return request


def plc_time(request: dict) -> float:
    """The controller's time (s) a client such as ``vplc run --scenario`` sends with its request, logged next to
    the robot clock's ``t`` so that both logs line up."""
    value = request["plc_time"]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 <= value < 1e9:
        raise RequestError(f"'plc_time' must be the controller time in seconds (0 .. 1e9), got {show(value)}")
    return value


def _small_int(text):
    if len(text.lstrip("-")) > 18:
        raise RequestError(f"number {text[:20]}... has more than 18 digits")
    return int(text)


def _no_constant(name):
    raise RequestError(f"{name} is not a number a request may carry")


def text_field(request: dict, name: str) -> str:
    value = request.get(name)
    if not isinstance(value, str):
        raise RequestError(f"'{name}' must be a text, got {show(value)}")
    return value


def bool_field(request: dict, name: str, default: bool) -> bool:
    value = request.get(name, default)
    if not isinstance(value, bool):
        raise RequestError(f"'{name}' must be true or false, got {show(value)}")
    return value


def int_field(request: dict, name: str, default: int, low: int, high: int | None, message: str) -> int:
    value = request.get(name, default)
    if type(value) is not int:
        raise RequestError(f"'{name}' must be an integer, got {show(value)}")
    if value < low or (high is not None and value > high):
        raise RequestError(message.format(show(value)))
    return value


def fault_params(request: dict) -> dict:
    params = request.get("params", {})
    if params is None:
        return {}
    if not isinstance(params, dict):
        raise RequestError(f"'params' must be an object, got {show(params)}")
    for key, value in params.items():
        if isinstance(value, float) and not math.isfinite(value):
            raise RequestError(f"parameter '{key}' must be a finite number")
        if not isinstance(value, (bool, int, float, str)) or (isinstance(value, str) and len(value) > 64):
            raise RequestError(f"parameter '{key}' must be a number, true/false or a short text, got "
                               f"{show(value)}")
    return params


def operation_mode(text: object) -> bool:
    if text not in ("auto", "manual"):
        raise RequestError(f"operation mode must be \"auto\" or \"manual\", got {show(text)}")
    return text == "auto"


def show(value: object) -> str:
    text = json.dumps(value) if isinstance(value, (dict, list, str)) else repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def error_answer(text: str) -> dict:
    return {"ok": False, "error": text}


def encode_answer(answer: dict) -> bytes:
    return (json.dumps(answer, allow_nan=False, ensure_ascii=False) + "\n").encode("utf-8")
