"""Ethernet Slave data table: the items, their types and permissions, and their three encodings (pure).

Item names, types, sizes, read/write access and writable mode follow the TMflow 2.24 software manual,
Appendix D "Ethernet Slave Data Table"; ``Robot_Link`` is the predefined item of TMscript 2.24 §17.2.
Three items come from older TMflow tables that the official Techman ROS driver (TechmanRobotInc/tmr_ros2,
``tm_robot_state.cpp``) still asks for: ``Safeguard_A``, ``MA_Mode`` and ``Error_Content``.

Encodings (TMscript 2.24 §17.4.2-17.4.4):

* binary (mode 1/11): per item ``len(name) u16 LE | name UTF-8 | len(value) u16 LE | value``; bool and byte
  one byte, int int32 LE, float float32 LE, string UTF-8 (string arrays joined by 00 00).
* string (mode 2/12): ``Item=Value`` lines joined by CR LF; arrays ``{a,b,c}``, strings in double quotes.
  The manual shows no bool value in this mode; the simulator writes ``true``/``false`` (TMscript's bool
  text, and what techmanpy's parser expects) and accepts 1/0/true/false.
* JSON (mode 3/13): ``[{"Item": name, "Value": value}, ...]``.

Values that do not fit the item raise ``SvrValueError`` (status 07); malformed content raises
``SvrContentError`` (status 03).
"""
from __future__ import annotations

import json
import math
import struct
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from tmsim.limits import SVR_ARRAY_MAX, SVR_STRING_MAX

_WIDTH = {"bool": 1, "byte": 1, "int": 4, "float": 4}
_PACK = {"bool": "B", "byte": "B", "int": "i", "float": "f"}


class SvrContentError(ValueError):
    """The content does not match its mode (status 03 InvalidData)."""


class SvrValueError(ValueError):
    """A value does not match the item's type or size (status 07 ValueError)."""


@dataclass(frozen=True)
class Item:
    name: str
    type: str              # bool | byte | int | float | string
    size: int = 1          # elements; > 1 is an array
    writable: str = ""     # "" read only, "MA" writable in manual and auto mode, "A" in auto mode only
    low: float | None = None       # value range of a writable number (None: the type's range)
    high: float | None = None
    step: int | None = None        # written values must be multiples of this (Project_Speed)
    # A global variable declared without a size (`string[]`, as the TMscript 2.24 manual names g_ss, §17.4.2-17.4.4)
    # is a TMscript array: a write may give it another number of elements (the manual's T2 writes
    # g_ss={"Hello","World"} over {"Hi","TM","Robot"}: 00 OK). ``size`` is then its initial length.
    resizable: bool = False

    @property
    def array(self) -> bool:
        return self.size > 1 or self.resizable


def _items():
    f6: dict[str, Any] = {"type": "float", "size": 6}
    table = [
        Item("Robot_Link", "byte"),                                   # §17.2: always sent, read only
        # Appendix D, system items
        Item("Get_UI_Control", "bool"), Item("Robot_Error", "bool"), Item("Error_Code", "int"),
        Item("Error_Time", "string"), Item("Warning_Code", "int"), Item("Warning_Time", "string"),
        Item("Camera_Light", "byte", writable="MA", low=0, high=1),
        Item("Project_Speed", "byte", writable="MA", low=5, high=100, step=5),   # "multiples of five, 5..100"
        Item("Project_Name", "string", writable="A"), Item("Project_Run_Time", "string"),
        Item("Project_Run", "bool"), Item("Project_Edit", "bool"), Item("Project_Pause", "bool"),
        Item("Coord_Base_Flange", **f6), Item("Joint_Angle", **f6), Item("Coord_Base_Tool", **f6),
        Item("Coord_Robot_Flange", **f6), Item("Coord_Robot_Tool", **f6),
        Item("TCP_Force", "float", 3), Item("TCP_Force3D", "float"), Item("TCP_Speed", **f6),
        Item("TCP_Speed3D", "float"), Item("Joint_Speed", **f6), Item("Joint_Torque", **f6),
        Item("TCP_Name", "string"), Item("TCP_Value", **f6), Item("TCP_Mass", "float"),
        Item("Base_Name", "string"), Item("Base_Value", **f6),
        Item("Stick_MA", "bool"),
        *(Item(f"Stick_{b}", "bool", writable="MA", low=0, high=1)      # "W: Triggered as 1 received"
          for b in ("Play", "Stop", "Plus", "Minus", "Pause", "PlayPause")),
        Item("Stick_ESTOP", "bool"), Item("Robot_Model", "string"), Item("ControlBox_SN", "string"),
        Item("TMflow_Version", "string"), Item("Robot_Light", "byte"), Item("ESTOP", "bool"),
        Item("Ext_Safeguard", "bool"), Item("Robot_State", "byte"), Item("Operation_Mode", "int"),
        # Appendix D, IO items (Ctrl_/End_ DO, DI, AO, AI); AO/AI carry volts as float
        *(Item(f"Ctrl_DO{i}", "byte", writable="MA", low=0, high=1) for i in range(16)),
        *(Item(f"Ctrl_DI{i}", "byte") for i in range(16)),
        *(Item(f"Ctrl_AO{i}", "float", writable="MA", low=-10, high=10) for i in range(2)),
        *(Item(f"Ctrl_AI{i}", "float") for i in range(2)),
        *(Item(f"End_DO{i}", "byte", writable="MA", low=0, high=1) for i in range(4)),
        *(Item(f"End_DI{i}", "byte") for i in range(4)),
        *(Item(f"End_AO{i}", "float", writable="MA", low=-10, high=10) for i in range(2)),
        *(Item(f"End_AI{i}", "float") for i in range(2)),
        # older tables, read by tmr_ros2
        Item("Safeguard_A", "bool"), Item("MA_Mode", "int"), Item("Error_Content", "string"),
    ]
    return {item.name: item for item in table}


ITEMS: dict[str, Item] = _items()

_U16 = struct.Struct("<H")
# item name -> (length-prefixed name, packer of its value) for the binary format
_PACKERS = {item.name: (_U16.pack(len(item.name.encode())) + item.name.encode(),
                        None if item.type == "string" else struct.Struct(f"<{item.size}{_PACK[item.type]}"))
            for item in ITEMS.values()}


# ---- checking a value against its item ------------------------------------------------------------
def check_value(item: Item, value: Any) -> Any:
    """The value coerced to the item's type (lists for arrays); raises SvrValueError when it does not fit."""
    if item.resizable:
        if not isinstance(value, (list, tuple)) or not 1 <= len(value) <= SVR_ARRAY_MAX:
            raise SvrValueError(f"{item.name} needs an array of 1..{SVR_ARRAY_MAX} values")
        return [_scalar(item, v) for v in value]
    if item.size > 1:
        if not isinstance(value, (list, tuple)) or len(value) != item.size:
            raise SvrValueError(f"{item.name} needs {item.size} values")
        return [_scalar(item, v) for v in value]
    if isinstance(value, (list, tuple)):
        raise SvrValueError(f"{item.name} takes one value, not an array")
    return _scalar(item, value)


def _scalar(item, value):
    kind = item.type
    if kind == "string":
        if not isinstance(value, str) or len(value.encode("utf-8")) > SVR_STRING_MAX:
            raise SvrValueError(f"{item.name} needs a text of at most {SVR_STRING_MAX} bytes")
        return value
    if isinstance(value, bool):
        value = int(value)
    if kind == "float":
        if not isinstance(value, (int, float)) or not math.isfinite(value) or abs(value) > 3.4e38:
            raise SvrValueError(f"{item.name} needs a finite number")
        value = float(value)
    else:
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        if not isinstance(value, int):
            raise SvrValueError(f"{item.name} needs a whole number")
        low, high = {"bool": (0, 1), "byte": (0, 255), "int": (-2 ** 31, 2 ** 31 - 1)}[kind]
        if not low <= value <= high:
            raise SvrValueError(f"{item.name} value {value} is outside {low}..{high}")
    if item.low is not None and not item.low <= value <= item.high:
        raise SvrValueError(f"{item.name} value {value:g} is outside {item.low:g}..{item.high:g}")
    if item.step and value % item.step:
        raise SvrValueError(f"{item.name} value {value:g} is not a multiple of {item.step}")
    return value


# ---- binary (mode 1 / 11) --------------------------------------------------------------------------
def _packer(item: Item):
    """(length-prefixed name, value packer) of an item: precomputed for the table, built for a declared variable."""
    known = _PACKERS.get(item.name)
    if known is not None and ITEMS.get(item.name) is item:
        return known
    name = item.name.encode("utf-8")
    return (_U16.pack(len(name)) + name,
            None if item.type == "string" else struct.Struct(f"<{item.size}{_PACK[item.type]}"))


def binary_value(item: Item, value: Any) -> bytes:
    if item.type == "string":
        if item.array:                         # §17.4.2: "two bytes, 0x00 0x00, are inserted between the elements"
            return b"\x00\x00".join(v.encode("utf-8") for v in value)
        return value.encode("utf-8")
    if item.resizable:
        return struct.pack(f"<{len(value)}{_PACK[item.type]}", *value)
    packer = _packer(item)[1]
    if item.size > 1:
        return packer.pack(*value)
    return packer.pack(value)


def encode_binary(pairs: Iterable[tuple[Item, Any]]) -> bytes:
    """``pairs``: (Item, value) -> mode 1 content: u16 name length, name, u16 value length, value."""
    out = []
    for item, value in pairs:
        data = binary_value(item, value)
        out.append(_packer(item)[0])
        out.append(_U16.pack(len(data)))
        out.append(data)
    return b"".join(out)


def split_binary(content: bytes, with_values: bool) -> list[tuple[str, bytes | None]]:
    """Mode 1 content -> [(name, value bytes)]; mode 11 (``with_values`` False) -> [(name, None)]."""
    out, pos = [], 0
    while pos < len(content):
        name, pos = _chunk(content, pos)
        try:
            text = name.decode("utf-8")
        except UnicodeDecodeError:
            raise SvrContentError("an item name is not UTF-8") from None
        value = None
        if with_values:
            value, pos = _chunk(content, pos)
        out.append((text, value))
    if not out:
        raise SvrContentError("no item in the content")
    return out


def _chunk(content, pos):
    if pos + 2 > len(content):
        raise SvrContentError("a length field is cut off")
    (length,) = struct.unpack_from("<H", content, pos)
    end = pos + 2 + length
    if end > len(content):
        raise SvrContentError("a length field points past the end of the content")
    return content[pos + 2:end], end


def decode_binary_value(item: Item, data: bytes) -> Any:
    if item.type == "string":
        try:
            if item.array:
                return [part.decode("utf-8") for part in data.split(b"\x00\x00")]
            return data.decode("utf-8")
        except UnicodeDecodeError:
            raise SvrValueError(f"{item.name} is not UTF-8 text") from None
    width = _WIDTH[item.type]
    count = len(data) // width if item.resizable else item.size     # (resizable: as many as the bytes hold)
    if item.resizable:
        if not data or len(data) % width or count > SVR_ARRAY_MAX:
            raise SvrValueError(f"{item.name} needs 1..{SVR_ARRAY_MAX} values of {width} bytes, got {len(data)} bytes")
    elif len(data) != width * count:
        raise SvrValueError(f"{item.name} needs {width * count} bytes, got {len(data)}")
    values = list(struct.unpack(f"<{count}{_PACK[item.type]}", data))
    if item.type == "float":
        values = [float(v) for v in values]
    return values if item.array else values[0]


# ---- string (mode 2 / 12) --------------------------------------------------------------------------
def string_value(item: Item, value: Any) -> str:
    if item.array:
        return "{" + ",".join(_string_scalar(item, v) for v in value) + "}"
    return _string_scalar(item, value)


def _string_scalar(item, value):
    if item.type == "string":
        return '"' + value.replace('"', "'") + '"'
    if item.type == "bool":
        return "true" if value else "false"
    if item.type == "float":
        return _float_text(value)
    return str(int(value))


def _float_text(value) -> str:
    """The float32 value with the digits it carries (7 significant), no exponent for usual values."""
    (single,) = struct.unpack("<f", struct.pack("<f", float(value)))
    text = f"{single:.7g}"
    return "0" if text in ("-0", "0") else text


def encode_string(pairs: Iterable[tuple[Item, Any]]) -> str:
    return "\r\n".join(f"{item.name}={string_value(item, value)}" for item, value in pairs)


def split_string(content: str, with_values: bool) -> list[tuple[str, str | None]]:
    """Mode 2 content -> [(name, value text)]; mode 12 -> [(name, None)]."""
    out: list[tuple[str, str | None]] = []
    for line in content.split("\r\n"):
        if with_values:
            name, eq, value = line.partition("=")
            if not eq or not name.strip():
                raise SvrContentError(f"line {line[:40]!r} is not Item=Value")
            out.append((name.strip(), value.strip()))
        else:
            if not line.strip() or "=" in line:
                raise SvrContentError(f"line {line[:40]!r} is not an item name")
            out.append((line.strip(), None))
    return out


def parse_string_value(item: Item, text: str) -> Any:
    """``Value`` text of mode 2 -> Python value (not yet range-checked); SvrValueError when unreadable."""
    if item.array:
        if not (text.startswith("{") and text.endswith("}")):
            raise SvrValueError(f"{item.name} needs {{...}}" if item.resizable
                                else f"{item.name} needs {{...}} with {item.size} values")
        inner = text[1:-1].strip()
        return [_parse_scalar(item, part.strip()) for part in _split_elements(inner)] if inner else []
    return _parse_scalar(item, text)


def _split_elements(inner: str) -> list[str]:
    parts: list[str] = []
    current: list[str] = []
    quoted = False
    for ch in inner:
        if ch == '"':
            quoted = not quoted
        if ch == "," and not quoted:
            parts.append("".join(current))
            current = []
        else:
            current.append(ch)
    parts.append("".join(current))
    return parts


def _parse_scalar(item, text):
    if item.type == "string":
        if len(text) < 2 or text[0] != '"' or text[-1] != '"':
            raise SvrValueError(f"{item.name} needs a text in double quotes")
        return text[1:-1]
    lowered = text.lower()
    if lowered in ("true", "false"):
        return lowered == "true"
    try:
        if item.type == "float":
            return float(text)
        if lowered.startswith("0x"):
            return int(text, 16)
        return int(text)
    except ValueError:
        raise SvrValueError(f"{item.name} value {text[:40]!r} is not a {item.type}") from None


# ---- JSON (mode 3 / 13) ----------------------------------------------------------------------------
def json_value(item: Item, value: Any) -> Any:
    if item.type == "bool":
        return [bool(v) for v in value] if item.array else bool(value)
    if item.type == "float":
        return [float(_float_text(v)) for v in value] if item.array else float(_float_text(value))
    return value


def encode_json(pairs: Iterable[tuple[Item, Any]]) -> str:
    return json.dumps([{"Item": item.name, "Value": json_value(item, value)} for item, value in pairs],
                      separators=(",", ":"), ensure_ascii=False)


def split_json(content: str, with_values: bool) -> list[tuple[str, object]]:
    """Mode 3 content -> [(name, value)]; mode 13 -> [(name, None)] (a single object is one item)."""
    try:
        data = json.loads(content)
    except (ValueError, RecursionError):         # RecursionError: nested deeper than the parser goes
        raise SvrContentError("the content is not JSON") from None
    if isinstance(data, dict):
        data = [data]
    if not isinstance(data, list) or not data:
        raise SvrContentError("the content is not a JSON array of items")
    out = []
    for entry in data:
        if not isinstance(entry, dict) or not isinstance(entry.get("Item"), str):
            raise SvrContentError('each entry needs an "Item" name')
        if with_values and "Value" not in entry:
            raise SvrContentError(f'item {entry["Item"]!r} has no "Value"')
        out.append((entry["Item"], entry.get("Value") if with_values else None))
    return out


# ---- global variables of the robot's project (TMscript 2.24 §17.2 "Global Variable") ---------------------
# "the external communication devices can read / write global variables with the communication protocol"; like
# user-defined items they must be in the communication file to be read or written (§17.4), so the simulator
# knows only the variables declared to it (start-up option --svr-var, SvrSession.declare). TMflow names them
# g_<name> (the manual's example item g_ss, string[]); the simulator does not insist on the prefix.
VARIABLE_TYPES = ("bool", "byte", "int", "float", "string")
VARIABLE_ACCESS = {"rw": "MA", "auto": "A", "ro": ""}   # write in manual and auto mode / auto only / read only


def variable_item(name: str, kind: str, size: int = 1, access: str = "rw", resizable: bool = False) -> Item:
    """The Item of a global variable (``resizable``: an array declared without a size, ``size`` its initial
    length); SvrValueError names what is wrong."""
    if not (isinstance(name, str) and 0 < len(name) <= 64 and name.isascii()
            and (name[0].isalpha() or name[0] == "_") and all(c.isalnum() or c == "_" for c in name)):
        raise SvrValueError(f"variable name {str(name)[:70]!r}: 1..64 letters, digits or '_', "
                            f"not starting with a digit")
    if name in ITEMS:
        raise SvrValueError(f"variable name {name!r} is a predefined item of the data table")
    if kind not in VARIABLE_TYPES:
        raise SvrValueError(f"variable {name}: type {str(kind)[:20]!r} is not one of {', '.join(VARIABLE_TYPES)}")
    if isinstance(size, bool) or not isinstance(size, int) or not 1 <= size <= SVR_ARRAY_MAX:
        raise SvrValueError(f"variable {name}: array size must be 1..{SVR_ARRAY_MAX}, got {size!r}")
    if access not in VARIABLE_ACCESS:
        raise SvrValueError(f"variable {name}: access {str(access)[:20]!r} is not one of {', '.join(VARIABLE_ACCESS)}")
    return Item(name, kind, size, VARIABLE_ACCESS[access], resizable=bool(resizable))


def default_value(item: Item) -> Any:
    zero = "" if item.type == "string" else 0.0 if item.type == "float" else 0
    return [zero] * item.size if item.array else zero


def parse_variable(spec: str) -> tuple[Item, object]:
    """``NAME:TYPE[:ACCESS][=VALUE]`` (TYPE ``int``, ``float[6]`` (fixed size), ``string[]`` (any number of
    elements, initially VALUE's) ...; ACCESS rw, auto or ro; VALUE as in a mode 2 write: ``5``, ``{1,2,3}``,
    ``"text"``) -> (Item, value); SvrValueError names what is wrong."""
    head, eq, text = spec.partition("=")
    parts = head.split(":")
    if len(parts) not in (2, 3):
        raise SvrValueError(f"variable {spec[:60]!r}: expected NAME:TYPE[:ACCESS][=VALUE]")
    name, kind = parts[0].strip(), parts[1].strip()
    size = 1
    if kind.endswith("[]"):
        kind = kind[:-2].strip()
        access = parts[2].strip() if len(parts) == 3 else "rw"
        item = variable_item(name, kind, 1, access, resizable=True)
        value = check_value(item, parse_string_value(item, text.strip())) if eq else default_value(item)
        return variable_item(name, kind, len(value), access, resizable=True), value
    if kind.endswith("]") and "[" in kind:
        kind, _, count = kind[:-1].partition("[")
        if not count.isdigit():
            raise SvrValueError(f"variable {name}: array size {count[:10]!r} is not a number")
        size = int(count)
    item = variable_item(name, kind, size, parts[2].strip() if len(parts) == 3 else "rw")
    value = check_value(item, parse_string_value(item, text.strip())) if eq else default_value(item)
    return item, value

