"""The PLC-HMI variable table (pages/mapping.json, limits from pages/ranges.json) and the checks every value from the
browser passes before it reaches the PLC: type, range, enumeration, text length, IPv4 pattern."""
from __future__ import annotations

import datetime
import ipaddress
import json
import math
import pathlib
from http import HTTPStatus

from vplc.api import integer_ranges

from .. import PAGES
from .ranges import RangeTableError, apply_ranges, load_ranges, read_json

HMI_DIR = PAGES
DEFAULT_MAPPING = HMI_DIR / "mapping.json"
DEFAULT_RANGES = HMI_DIR / "ranges.json"

INT_RANGES = integer_ranges()    # IEC integer and bit-string types: (lowest, highest), the toolchain's own table
REAL_TYPES = {"REAL", "LREAL"}


class MappingError(Exception):
    """The mapping file is unreadable, inconsistent, or does not match the PLC program."""


class RequestError(Exception):
    """A request the HMI server refuses; str() is the message shown to the operator."""

    def __init__(self, message: str, status: HTTPStatus = HTTPStatus.BAD_REQUEST):
        super().__init__(message)
        self.status = status


class Leaf:
    """One scalar PLC variable reachable from the HMI (a mapped variable or a field inside one)."""

    __slots__ = ("path", "type", "access", "role", "min", "max", "enum", "maxlen", "pattern", "execute", "unit")

    def __init__(self, path: str, spec: dict, access: str, role: str, enum: dict | None = None):
        self.path = path
        self.type = spec["type"]
        self.access = access
        self.role = role                  # the least role that may write it: "operator" or "engineer"
        self.enum = enum
        self.min = spec.get("min")
        self.max = spec.get("max")
        self.maxlen = spec.get("maxlen")
        self.pattern = spec.get("pattern")
        self.execute = bool(spec.get("execute"))
        self.unit = spec.get("unit", "")

    def describe_range(self) -> str:
        if self.enum:
            return "one of " + ", ".join(f"{k} ({v})" for k, v in self.enum.items())
        return f"{self.min} .. {self.max}"


def string_length(type_text: str) -> int | None:
    """The length of a STRING type text (``STRING[20]`` -> 20; a bare ``STRING`` counts as 80), None for any
    other type: the mapping's checks and the page descriptions judge text inputs by it."""
    if type_text.startswith("STRING[") and type_text.endswith("]"):
        return int(type_text[7:-1])
    return 80 if type_text == "STRING" else None


class Mapping:
    """The PLC-HMI variable table flattened to leaf paths such as 'PnP_MoveParameters[2].TargetPosition.X'."""

    def __init__(self, document: dict, source: str = "mapping"):
        self.document = document
        self.source = source
        self.leaves: dict[str, Leaf] = {}
        self.roots: dict[str, dict] = {}
        try:
            self.pages = frozenset(document.get("pages", ["index"]))
            # members that only the engineer may change in every structure that has them (ExitNode: one
            # command with it leaves the robot outside the Listen node, every later command fails 16#4002)
            self.engineering_members = frozenset(document.get("engineering_members", []))
            types = document["types"]
            for name, spec in document["variables"].items():
                self.roots[name] = spec
                access = spec.get("access", "r")
                if access not in ("r", "rw"):
                    raise MappingError(f"{source}: variable '{name}': access must be 'r' or 'rw', not {access!r}")
                role = spec.get("role", "operator")
                if role not in ("operator", "engineer"):
                    raise MappingError(f"{source}: variable '{name}': role must be 'operator' or 'engineer', "
                                       f"not {role!r}")
                self._expand(name, spec, access, role, types)
            self.execute_settings = self._execute_settings(document)
        except (KeyError, TypeError, ValueError) as exc:
            raise MappingError(f"{source}: malformed variable table ({type(exc).__name__}: {exc})") from None

    def _execute_settings(self, document: dict) -> dict[str, list[str]]:
        """The engineering members each described command carries, by its Execute variable ('MoveRel_Execute' ->
        ['MoveRel_Param.ExitNode']): the value the engineer left in the PLC goes with the operator's next Execute."""
        settings: dict[str, list[str]] = {}
        for page in document.get("page_descriptions", {}).values():
            command, parameters = page.get("command") or {}, page.get("parameters") or {}
            if command.get("variable") and parameters.get("variable"):
                prefix = parameters["variable"] + "."
                settings[command["variable"]] = sorted(
                    path for path in self.leaves
                    if path.startswith(prefix) and path.rpartition(".")[2] in self.engineering_members)
        return settings

    @classmethod
    def load(cls, path: pathlib.Path | str = DEFAULT_MAPPING) -> Mapping:
        path = pathlib.Path(path)
        document = read_json(path, "HMI variable table", MappingError)
        ranges_file = path.with_name(DEFAULT_RANGES.name)
        if ranges_file.exists():                # the limits come from the library's range table
            try:
                apply_ranges(document, load_ranges(ranges_file), str(ranges_file))
            except RangeTableError as exc:
                raise MappingError(str(exc)) from None
        return cls(document, str(path))

    def _expand(self, path: str, spec: dict, access: str, role: str, types: dict) -> None:
        if "array" in spec:
            low, high = spec["array"]
            for index in range(low, high + 1):
                self._expand_element(f"{path}[{index}]", spec, access, role, types)
        else:
            self._expand_element(path, spec, access, role, types)

    def _expand_element(self, path: str, spec: dict, access: str, role: str, types: dict) -> None:
        type_name = spec["type"]
        definition = types.get(type_name)
        if definition is None:
            if type_name not in INT_RANGES and type_name not in REAL_TYPES and type_name != "BOOL" \
                    and string_length(type_name) is None and type_name not in ("DATE_AND_TIME", "DT", "TIME"):
                raise MappingError(f"{self.source}: '{path}' has unknown type '{type_name}'")
            self.leaves[path] = Leaf(path, spec, access, role)
        elif "enum" in definition:
            self.leaves[path] = Leaf(path, spec, access, role, enum=dict(definition["enum"]))
        else:
            for field, field_spec in definition["fields"].items():
                if "min" in spec and "min" not in field_spec:      # e.g. TargetPosition's range on X..RZ
                    field_spec = {**field_spec, "min": spec["min"], "max": spec["max"]}
                member_role = "engineer" if field in self.engineering_members else role
                self._expand(f"{path}.{field}", field_spec, access, member_role, types)

    def why_not_a_leaf(self, path) -> str:
        """Why ``path`` cannot be written as one value: a whole structure/array, an index out of its range,
        or a name that is not in the table."""
        if not isinstance(path, str):
            return f"{json.dumps(path)} is not a variable name"
        if path in self.roots or self.is_readable(path):
            example = next(leaf for leaf in self.leaves if leaf.startswith(path))
            return f"'{path}' is a structure or array: write its elements one by one, e.g. '{example}'"
        root = path.split(".")[0].split("[")[0]
        spec = self.roots.get(root)
        if spec is not None and "array" in spec and path[len(root):].startswith("["):
            low, high = spec["array"]
            return f"'{path}': the index is outside {root}[{low}..{high}]"
        return f"'{path}' is not in the HMI variable table"

    def is_readable(self, name: str) -> bool:
        """A mapped variable, a leaf inside one, or an inner struct/array element of one."""
        if name in self.roots or name in self.leaves:
            return True
        return any(leaf.startswith(name + ".") or leaf.startswith(name + "[") for leaf in self.leaves)

    def check_against_plc(self, plc) -> None:
        """Raise MappingError listing every mapped leaf the PLC does not have with the same type."""
        problems = []
        for path, leaf in self.leaves.items():
            try:
                with plc.lock:
                    actual = plc.var_type(path)
            except (KeyError, ValueError) as exc:
                problems.append(f"  {path}: not found in the PLC program ({exc})")
                continue
            bare = actual.rsplit("\\", 1)[-1]
            expected = leaf.type
            same = bare == expected or (expected in ("DATE_AND_TIME", "DT") and bare in ("DATE_AND_TIME", "DT"))
            declared_length, expected_length = string_length(bare), string_length(expected)
            if not same and declared_length is not None and expected_length is not None:
                same = declared_length >= expected_length or leaf.access == "r"
            if not same:
                problems.append(f"  {path}: the table says {expected}, the PLC program declares {actual}")
        if problems:
            raise MappingError(f"{self.source} does not match the PLC program:\n" + "\n".join(problems))


def validate(leaf: Leaf, value: object) -> object:
    """Return the value to hand to plc.write, or raise RequestError saying what is wrong."""
    where = f"'{leaf.path}'"
    if leaf.enum is not None:
        if isinstance(value, str) and value in leaf.enum:
            return leaf.enum[value]
        if isinstance(value, int) and not isinstance(value, bool) and value in leaf.enum.values():
            return value
        raise RequestError(f"{where}: {value!r} is not valid, expected {leaf.describe_range()}")
    if leaf.type == "BOOL":
        if not isinstance(value, bool):
            raise RequestError(f"{where} is BOOL: expected true or false, got {json.dumps(value)}")
        return value
    if leaf.type in INT_RANGES:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or \
                (isinstance(value, float) and not value.is_integer()):
            raise RequestError(f"{where} is {leaf.type}: expected a whole number, got {json.dumps(value)}")
        low, high = INT_RANGES[leaf.type]
        low = low if leaf.min is None else max(low, leaf.min)
        high = high if leaf.max is None else min(high, leaf.max)
        if not low <= value <= high:     # compared before any conversion: 1e308 is not made a 309-digit integer
            shown = str(int(value)) if abs(value) < 1e21 else f"{value:.6g}"
            raise RequestError(f"{where}: {shown} is out of range {low} .. {high}")
        return int(value)
    if leaf.type in REAL_TYPES:
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            raise RequestError(f"{where} is {leaf.type}: expected a number, got {json.dumps(value)}")
        value = float(value)
        if not math.isfinite(value):
            raise RequestError(f"{where}: the value must be a finite number")
        if (leaf.min is not None and value < leaf.min) or (leaf.max is not None and value > leaf.max):
            raise RequestError(f"{where}: {value:g} is out of range {leaf.min} .. {leaf.max}")
        return value
    size = string_length(leaf.type)
    if size is not None:
        if not isinstance(value, str):
            raise RequestError(f"{where} is {leaf.type}: expected text, got {json.dumps(value)}")
        limit = min(size - 1, leaf.maxlen or size)   # Sysmac STRING[n] holds n-1 characters (NUL)
        if len(value) > limit or not value.isascii():
            raise RequestError(f"{where}: text must be at most {limit} ASCII characters")
        if leaf.pattern == "ipv4":
            try:
                ipaddress.IPv4Address(value)
            except ValueError:
                raise RequestError(f"{where}: '{value}' is not an IPv4 address such as 192.168.1.10") from None
        return value
    raise RequestError(f"{where} ({leaf.type}) cannot be written from the HMI")


def format_dt(value) -> str:
    """DATE_AND_TIME as the runtime holds it (ns since 1970-01-01) -> 'DT#2026-11-22-21:42:38'; 0 -> '—'."""
    if not isinstance(value, int) or isinstance(value, bool):
        return str(value)
    if value == 0:
        return "—"
    moment = datetime.datetime(1970, 1, 1) + datetime.timedelta(microseconds=value // 1000)
    return moment.strftime("DT#%Y-%m-%d-%H:%M:%S")


def jsonable(value: object) -> object:
    if isinstance(value, dict):
        return {k: jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if hasattr(value, "value") and isinstance(value.value, int):
        return value.value
    return str(value)
