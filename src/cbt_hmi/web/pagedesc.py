"""Page description files: one JSON file per HMI page says which PLC variables the page shows, with their labels,
units and limits, and the HMI builds the page from it (hmi.js) without page-specific JavaScript. The variable table
the pages use is generated from the program's global variables and the descriptions (``table_document``), never
written by hand. The user's own pages and the shipped command pages (``cbt_hmi/pages/desc/``) are such files.

A page of the user's cell (``<page>.json``; the page is then ``<page>.html``)::

    {"title": "Conveyor",
     "inputs":  [{"variable": "Belt_Speed", "label": "Belt speed", "unit": "mm/s", "min": 0, "max": 500}],
     "command": {"variable": "Belt_Start", "label": "Start belt"},
     "status":  [{"variable": "Belt_Running", "label": "Running"},
                 {"variable": "Belt_Jam", "label": "Jam", "abnormal": true}]}

A page that drives one function block instance (the shipped command pages) names the instance, whose global
variables follow the pattern ``<instance>_Execute``, ``<instance>_Busy`` ... (the command status block), and its
parameter structure, whose members become the fields (enumerations as drop-down lists with the library's names,
ranges per data format from ``ranges.json``)::

    {"title": "Move Absolute", "fb": "CBT_MoveAbsolute", "instance": "MoveAbs",
     "parameters": {"variable": "MoveAbs_Param", "legend": "Motion Settings", "engineer": ["ExitNode"]},
     "labels": {"TargetPosition": "Target Position (mm, °)"},
     "presets": {"Preset Values": {"MovementCommand": "PTP", "Speed": 50}},
     "done": [{"when": {"BlendingEnable": true}, "text": "the robot accepted the motion."},
              {"text": "the robot arrived at the target."}]}

The keys are listed in docs/hmi.md ("Pages for your own program"). Every mistake is reported with the file and the
line of the item; a page with a mistake is left out and the others are served."""
from __future__ import annotations

import json
import os
import pathlib
import stat
from collections.abc import Callable
from typing import Any, NamedTuple, NoReturn

from .. import PAGES
from .mapping import DEFAULT_MAPPING, INT_RANGES, REAL_TYPES, string_length

DESC_DIR = PAGES / "desc"          # the shipped pages' descriptions (package data)
PAGE_KEYS = {"title", "inputs", "status", "command"}
# a page that drives one FB instance: these need "instance" (labels, legend and role do not)
INSTANCE_KEYS = {"fb", "parameters", "presets", "done", "release", "act", "view", "lamps", "reset", "robot_status"}
OTHER_KEYS = {"instance", "labels", "legend", "role"}
# the shipped special pages (Main, PnP, Jog / Teach, Program) are hand-written JavaScript: their descriptions name
# the script and the variables it reads and writes, so that the variable table is still generated
SHIPPED_KEYS = {"script", "reads", "writes", "trail"}
SCRIPTS = {"main", "pnp", "jog", "program"}
ITEM_KEYS = {"inputs": {"variable", "label", "unit", "min", "max", "role", "pattern", "range_of"},
             "status": {"variable", "label", "unit", "abnormal"},
             "command": {"variable", "label"},
             "writes": {"variable", "role", "execute", "min", "max", "range_of", "pattern", "engineer"}}
NUMERIC = set(INT_RANGES) | REAL_TYPES
TIME_TYPES = {"DATE_AND_TIME", "DT", "TIME"}         # shown under 'status' as the server formats them
COMMAND_STATUS = ("Busy", "Done", "CommandAborted", "Error", "ErrorID", "ErrorDescrip", "CmdID_Ack")
# pages of the HMI itself: a description of the user's may not take their names (read from the generated table,
# which an installed package always carries; the descriptions themselves are only the generator's input)
BUILT_IN_PAGES = frozenset(json.loads(DEFAULT_MAPPING.read_text(encoding="utf-8"))["pages"])
MAX_FILE_BYTES = 64 * 1024


class PageError(Exception):
    """A page description file that cannot be used; str() names the file and line."""


class _Located(dict):
    """A JSON object that knows the line it starts on."""
    line = 0


def _object_lines(text: str) -> list[int]:
    """The line of each JSON object's opening brace, in the order the objects close: the order in which the decoder
    calls ``object_pairs_hook`` (an object is complete only at its closing brace)."""
    opened: list[int] = []
    closed: list[int] = []
    in_string = escaped = False
    line = 1
    for char in text:
        if char == "\n":
            line += 1
        if in_string:
            if escaped:
                escaped = False
            elif char == "\\":
                escaped = True
            elif char == '"':
                in_string = False
        elif char == '"':
            in_string = True
        elif char == "{":
            opened.append(line)
        elif char == "}" and opened:
            closed.append(opened.pop())
    return closed


def _decode_located(text: str) -> Any:
    """The JSON document with every object a _Located that knows its line."""
    lines = iter(_object_lines(text))

    def located(pairs: list[tuple[str, Any]]) -> _Located:
        found = _Located(pairs)
        found.line = next(lines, 0)
        return found

    return json.loads(text, object_pairs_hook=located)


def read_description(path: pathlib.Path) -> _Located:
    """The page description's JSON, each object with its line; PageError (file:line: reason) when unreadable."""
    try:
        # opened without waiting and read no further than the limit: a pipe nobody writes to, or a link to a
        # device such as /dev/zero, is refused instead of holding the start-up for ever or filling the memory
        with open(path, "rb", opener=lambda name, flags: os.open(name, flags | getattr(os, "O_NONBLOCK", 0))) as fh:
            if not stat.S_ISREG(os.fstat(fh.fileno()).st_mode):
                raise PageError(f"{path}: not a regular file (a device, pipe, socket or folder): not a page "
                                "description")
            raw = fh.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise PageError(f"{path}: cannot be read ({exc.strerror or exc})") from None
    if len(raw) > MAX_FILE_BYTES:
        raise PageError(f"{path}: larger than {MAX_FILE_BYTES // 1024} KiB: not a page description")
    try:
        document = _decode_located(raw.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise PageError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    except json.JSONDecodeError as exc:
        raise PageError(f"{path}:{exc.lineno}: not valid JSON: {exc.msg} (column {exc.colno})") from None
    if not isinstance(document, _Located):
        raise PageError(f"{path}:1: a page description is a JSON object {{\"title\": ..., \"inputs\": [...]}}")
    return document


class Global(NamedTuple):
    """One global variable of the program as a page description may use it."""
    name: str          # as declared
    type: str          # declared type without namespace (``stCBT_MovAbsParam``, ``ARRAY[0..5] OF ...``, ``REAL``)
    compiled: Any      # the compiled type (``kind``: struct, enum, array, string, or an elementary kind)


Fail = Callable[[int, str], NoReturn]


def user_globals(plc) -> dict[str, Global]:
    """The program's own global variables (Sysmac system and motion variables and constants left out), by
    upper-case name."""
    found = {}
    for name, symbol in plc.project.globals.items():
        if str(getattr(symbol, "global_list", "") or "").startswith("sysmac_") or getattr(symbol, "constant", False):
            continue                     # Sysmac system variables (P_On, _CurrentTime, ...), motion axes, constants
        found[name.upper()] = Global(symbol.name, plc.var_type(symbol.name).rsplit("\\", 1)[-1], symbol.type)
    return found


def type_name(compiled) -> str:
    """The name the variable table gives a compiled type: a structure's or enumeration's own name, an array's
    element type (its bounds go to ``array``), else the type as written (``REAL``, ``STRING[50]``)."""
    if compiled.kind == "array":
        return type_name(compiled.element)
    return str(compiled.name) if compiled.kind in ("struct", "enum") else str(compiled)


def _is_scalar(declared: str) -> bool:
    return declared in NUMERIC or declared == "BOOL" or string_length(declared) is not None


def collect_types(compiled, types: dict[str, dict]) -> None:
    """Add the structure and enumeration types ``compiled`` uses to ``types`` (the variable table's ``types``)."""
    kind = compiled.kind
    if kind == "array":
        collect_types(compiled.element, types)
    elif kind == "enum" and compiled.name not in types:
        types[compiled.name] = {"enum": dict(compiled.values)}
    elif kind == "struct" and compiled.name not in types:
        fields: dict[str, dict] = {}
        types[compiled.name] = {"fields": fields}
        for field in compiled.fields.values():
            spec: dict[str, Any] = {"type": type_name(field.type)}
            if field.type.kind == "array":
                spec["array"] = list(field.type.dims[0])
            fields[field.name] = spec
            collect_types(field.type, types)


def _members(compiled) -> dict[str, Any]:
    """A structure's members by declared name (an array of structures: its element's)."""
    while compiled.kind == "array":
        compiled = compiled.element
    return {field.name: field.type for field in compiled.fields.values()} if compiled.kind == "struct" else {}


def _check_value(compiled, value, where: str, line: int, fail: Fail) -> None:
    """A preset's value fits the member's type: a number in range, true/false, an enumeration's name, text, or an
    object of the structure's members."""
    kind = compiled.kind
    if kind == "struct":
        if not isinstance(value, dict):
            fail(line, f"{where} is a {compiled.name}: give an object of its members")
        members = _members(compiled)
        for key, inner in value.items():
            if key not in members:
                fail(line, f"{where}: {compiled.name} has no member '{key}' (it has {', '.join(members)})")
            _check_value(members[key], inner, f"{where}.{key}", line, fail)
    elif kind == "enum":
        names = dict(compiled.values)
        if not (isinstance(value, str) and value in names) and not (
                isinstance(value, int) and not isinstance(value, bool) and value in names.values()):
            fail(line, f"{where}: {json.dumps(value)} is not one of {', '.join(names)}")
    elif kind == "array":
        if not isinstance(value, list):
            fail(line, f"{where} is an array: give a list")
        for index, inner in enumerate(value):
            _check_value(compiled.element, inner, f"{where}[{index}]", line, fail)
    else:
        declared = str(compiled)
        if declared == "BOOL" and not isinstance(value, bool):
            fail(line, f"{where} is BOOL: give true or false, not {json.dumps(value)}")
        if declared in NUMERIC:
            if not isinstance(value, (int, float)) or isinstance(value, bool):
                fail(line, f"{where} is {declared}: give a number, not {json.dumps(value)}")
            if declared in INT_RANGES:
                low, high = INT_RANGES[declared]
                if not isinstance(value, int) or not low <= value <= high:
                    fail(line, f"{where} is {declared}: {json.dumps(value)} is not a whole number in {low}..{high}")
        if string_length(declared) is not None and not isinstance(value, str):
            fail(line, f"{where} is {declared}: give text, not {json.dumps(value)}")


def check_description(path: pathlib.Path, document: _Located, types: dict[str, Global],
                      shipped: bool = False) -> dict:
    """The page as hmi.js builds it: {"title", "inputs", "status", "command"} with each variable's type, and the
    keys of an FB-instance page when given; raises PageError naming the file and line of the first mistake.
    ``shipped``: a description of the HMI's own pages, which may also name a hand-written script."""
    def fail(line: int, text: str) -> NoReturn:
        raise PageError(f"{path}:{line}: {text}")

    allowed = PAGE_KEYS | INSTANCE_KEYS | OTHER_KEYS | (SHIPPED_KEYS if shipped else set())
    unknown = sorted(set(document) - allowed)
    if unknown:
        fail(document.line, f"unknown key '{unknown[0]}' (a page has {', '.join(sorted(allowed))})")
    title = document.get("title")
    if not isinstance(title, str) or not title.strip():
        fail(document.line, "missing field 'title': the page's name in its header, as text")
    if "script" not in document and not any(key in document for key in ("inputs", "status", "command", "instance")):
        fail(document.line, "the page shows nothing: give 'inputs', 'status', 'command' or 'instance'")
    needs_instance = sorted(set(document) & INSTANCE_KEYS)
    if needs_instance and "instance" not in document:
        fail(document.line, f"'{needs_instance[0]}' is for a page that drives a function block instance: "
                            "give 'instance' (the prefix of its variables, e.g. \"MoveAbs\")")
    role = document.get("role", "operator")
    if role not in ("operator", "engineer"):
        fail(document.line, f"'role' must be \"operator\" or \"engineer\", not {json.dumps(role)}")
    page: dict[str, Any] = {"title": title.strip(), "inputs": [], "status": [], "command": None}
    for section in ("inputs", "status"):
        items = document.get(section, [])
        if not isinstance(items, list):
            fail(document.line, f"'{section}' must be a list of items {{\"variable\": ..., \"label\": ...}}")
        for item in items:
            page[section].append(_check_item(section, item, document.line, types, fail, role))
    if "command" in document:
        page["command"] = _check_item("command", document["command"], document.line, types, fail, role)
    for key in ("legend", "release", "robot_status", "fb"):
        if key in document:
            if not isinstance(document[key], str) or not document[key].strip():
                fail(document.line, f"'{key}' must be text")
            page[key] = document[key].strip()
    for key in ("act", "view", "lamps"):
        if key in document:
            if not isinstance(document[key], bool):
                fail(document.line, f"'{key}' must be true or false")
            page[key] = document[key]
    if role == "engineer":
        page["role"] = role
    labels = document.get("labels", {})
    if not isinstance(labels, dict) or not all(isinstance(v, str) and v.strip() for v in labels.values()):
        fail(document.line, "'labels' must be an object of member names and their labels (text)")
    if labels:
        page["labels"] = {key: value.strip() for key, value in labels.items()}
    if "instance" in document:
        _check_instance(document, page, types, fail)
    if shipped:
        _check_shipped(document, page, types, fail)
    return page


def _check_instance(document: _Located, page: dict, types: dict[str, Global], fail: Fail) -> None:
    """An FB-instance page: its Execute, parameter structure, command status block, presets and Done texts."""
    line = document.line
    instance = document["instance"]
    if not isinstance(instance, str) or not instance.replace("_", "").isalnum():
        fail(line, "'instance' must be the prefix of the instance's variables, e.g. \"MoveAbs\"")
    page["instance"] = instance
    if page["command"] is None:
        execute = types.get(f"{instance}_EXECUTE".upper())
        if execute is None or execute.type != "BOOL":
            fail(line, f"instance '{instance}': the program has no BOOL '{instance}_Execute' (give 'command')")
        page["command"] = {"variable": execute.name, "label": "Execute", "type": "BOOL"}
    members: dict[str, Any] = {}
    parameters = document.get("parameters")
    if parameters is not None:
        if not isinstance(parameters, _Located) or not isinstance(parameters.get("variable"), str):
            fail(line, "'parameters' must be an object {\"variable\": <the FB's parameter structure>, ...}")
        unknown = sorted(set(parameters) - {"variable", "legend", "engineer", "limits"})
        if unknown:
            fail(parameters.line, f"unknown key '{unknown[0]}' in 'parameters' "
                                  "(allowed: engineer, legend, limits, variable)")
        found = types.get(parameters["variable"].strip().upper())
        if found is None:
            fail(parameters.line, f"unknown variable '{parameters['variable']}': the program has no global "
                                  "variable of that name")
        if found.compiled.kind != "struct":
            fail(parameters.line, f"'{found.name}' is {found.type}: 'parameters' names a structure")
        members = _members(found.compiled)
        engineer = parameters.get("engineer", [])
        if not isinstance(engineer, list) or any(name not in members for name in engineer):
            fail(parameters.line, f"'engineer' lists members of {found.type} ({', '.join(members)})")
        legend = parameters.get("legend", "Settings")
        if not isinstance(legend, str):
            fail(parameters.line, "'legend' of 'parameters' must be text")
        page["parameters"] = {"variable": found.name, "type": found.type, "legend": legend, "engineer": engineer}
        limits = parameters.get("limits", {})
        if not isinstance(limits, dict):
            fail(parameters.line, "'limits' is {<member>: {\"min\": ..., \"max\": ..., \"unit\": ...}}")
        for member, limit in limits.items():
            where = getattr(limit, "line", parameters.line)
            kind = str(members[member]) if member in members else ""
            if kind not in NUMERIC:
                fail(where, f"'limits': '{member}' is not a numeric member of {found.type}")
            if not isinstance(limit, dict) or set(limit) - {"min", "max", "unit"} or \
                    not all(isinstance(limit.get(k), (int, float)) and not isinstance(limit.get(k), bool)
                            for k in ("min", "max")) or limit["min"] > limit["max"] or \
                    not isinstance(limit.get("unit", ""), str):
                fail(where, f"'limits' of '{member}' is {{\"min\": <number>, \"max\": <number not below min>, "
                            "\"unit\": <text>}")
        if limits:
            page["parameters"]["limits"] = {member: dict(limit) for member, limit in limits.items()}
    if "status" not in document:                 # the FB's command status block
        page["status"] = [{"variable": found_pin.name, "label": pin, "type": found_pin.type}
                          for pin in COMMAND_STATUS
                          if (found_pin := types.get(f"{instance}_{pin}".upper())) is not None]
    if page.get("lamps", True):                  # the Active lamp (Busy for an FB without Active)
        lamp = types.get(f"{instance}_ACTIVE".upper()) or types.get(f"{instance}_BUSY".upper())
        if lamp is not None:
            page["lamp"] = lamp.name
    presets = document.get("presets", {})
    if not isinstance(presets, dict):
        fail(line, "'presets' must be an object: {\"<button text>\": {<member>: <value>, ...}}")
    fields = {item["variable"]: types[item["variable"].upper()].compiled for item in page["inputs"]}
    for name, values in presets.items():
        where_line = values.line if isinstance(values, _Located) else line
        if not isinstance(values, dict) or not values:
            fail(where_line, f"preset '{name}' must be an object of values")
        for key, value in values.items():
            compiled = members.get(key) if parameters is not None else fields.get(key)
            if compiled is None:
                fail(where_line, f"preset '{name}': '{key}' is not a field of this page")
            _check_value(compiled, value, key, where_line, fail)
    if presets:
        page["presets"] = dict(presets)
    done = document.get("done", [])
    if not isinstance(done, list):
        fail(line, "'done' must be a list of {\"when\": {<member>: <value>}, \"text\": ...}")
    for entry in done:
        if not isinstance(entry, _Located) or not isinstance(entry.get("text"), str) or \
                not isinstance(entry.get("when", {}), dict) or set(entry) - {"when", "text"}:
            fail(getattr(entry, "line", line), "an entry of 'done' is {\"when\": {<member>: <value>}, \"text\": ...}")
        for key, value in entry.get("when", {}).items():
            if key not in members:
                fail(entry.line, f"'done': '{key}' is not a member of the parameters")
            _check_value(members[key], value, key, entry.line, fail)
    if done:
        page["done"] = [dict(entry) for entry in done]
    reset = document.get("reset")
    if reset is not None:
        if not isinstance(reset, dict) or set(reset) != {"label", "text"} or \
                not all(isinstance(v, str) for v in reset.values()):
            fail(line, "'reset' is {\"label\": <key text>, \"text\": <what the message line says>}")
        page["reset"] = dict(reset)


def _check_shipped(document: _Located, page: dict, types: dict[str, Global], fail: Fail) -> None:
    """The keys of the shipped pages only: a hand-written script, and the variables a page reads and writes
    beyond what it shows (the scripts' variables, a setting the demo writes)."""
    line = document.line
    if "script" in document:
        if document["script"] not in SCRIPTS:
            fail(line, f"'script' is one of {', '.join(sorted(SCRIPTS))}")
        page["script"] = document["script"]
    reads = document.get("reads", [])
    if not isinstance(reads, list) or not all(isinstance(name, str) for name in reads):
        fail(line, "'reads' must be a list of variable names")
    for name in reads:
        if name.upper() not in types:
            fail(line, f"'reads': unknown variable '{name}': the program has no global variable of that name")
    if reads:
        page["reads"] = [types[name.upper()].name for name in reads]
    writes = document.get("writes", [])
    if not isinstance(writes, list):
        fail(line, "'writes' must be a list of items {\"variable\": ...}")
    if writes:
        page["writes"] = [_check_item("writes", item, line, types, fail, page.get("role", "operator"))
                          for item in writes]
    trail = document.get("trail")
    if trail is not None:
        if not isinstance(trail, dict) or set(trail) != {"valid", "position"}:
            fail(line, "'trail' is {\"valid\": <BOOL>, \"position\": <the TCP pose>}")
        page["trail"] = dict(trail)


def _check_item(section: str, item, parent_line: int, types: dict[str, Global], fail: Fail,
                page_role: str = "operator") -> dict:
    if not isinstance(item, _Located):
        fail(parent_line, f"an item of '{section}' must be an object {{\"variable\": ..., \"label\": ...}}, "
                          f"not {json.dumps(item)}")
    line = item.line
    unknown = sorted(set(item) - ITEM_KEYS[section])
    if unknown:
        fail(line, f"unknown key '{unknown[0]}' in an item of '{section}' "
                   f"(allowed: {', '.join(sorted(ITEM_KEYS[section]))})")
    for key in ("variable", "label") if section != "writes" else ("variable",):
        if not isinstance(item.get(key), str) or not item[key].strip():
            fail(line, f"missing field '{key}' (text) in an item of '{section}'")
    name = item["variable"].strip()
    if name.upper() not in types:
        fail(line, f"unknown variable '{name}': the program has no global variable of that name")
    found = types[name.upper()]
    name, declared = found.name, found.type
    bare = declared if section != "writes" else type_name(found.compiled)
    if section != "writes" and not _is_scalar(bare) and not (section == "status" and bare in TIME_TYPES):
        fail(line, f"'{name}' is {declared}: a described page shows BOOL, integer, REAL/LREAL and STRING "
                   f"variables (and times under 'status')")
    if section == "command" and bare != "BOOL":
        fail(line, f"'{name}' is {declared}: the command must be a BOOL the program acts on")
    result: dict[str, Any] = {"variable": name, "type": bare}
    if section != "writes":
        result["label"] = item["label"].strip()
    unit = item.get("unit", "")
    if not isinstance(unit, str):
        fail(line, f"'unit' of '{name}' must be text such as \"mm/s\"")
    if unit:
        result["unit"] = unit
    if "min" in item or "max" in item:
        if bare not in NUMERIC:
            fail(line, f"'{name}' is {declared}: 'min' and 'max' are for numeric variables only")
        for key in ("min", "max"):
            if not isinstance(item.get(key), (int, float)) or isinstance(item.get(key), bool):
                fail(line, f"'{key}' of '{name}' must be a number (give both 'min' and 'max')")
        if item["min"] > item["max"]:
            fail(line, f"'{name}': min {item['min']} is above max {item['max']}")
        if bare in INT_RANGES:
            low, high = INT_RANGES[bare]
            if item["min"] < low or item["max"] > high:
                fail(line, f"'{name}': {item['min']}..{item['max']} is outside what {bare} holds ({low}..{high})")
        result["min"], result["max"] = item["min"], item["max"]
    role = item.get("role", page_role)
    if role not in ("operator", "engineer"):
        fail(line, f"'role' of '{name}' must be \"operator\" or \"engineer\", not {json.dumps(role)}")
    if section in ("inputs", "writes"):
        result["role"] = role
    if "abnormal" in item:
        if not isinstance(item["abnormal"], bool):
            fail(line, f"'abnormal' must be true or false, not {json.dumps(item['abnormal'])[:40]}")
        if bare != "BOOL":
            fail(line, f"'abnormal' (true or false) is for BOOL status values; '{name}' is {declared}")
        result["abnormal"] = item["abnormal"]
    if "pattern" in item:
        if item["pattern"] != "ipv4" or string_length(bare) is None:
            fail(line, f"'pattern' of '{name}': \"ipv4\" (an IPv4 address), for STRING variables only")
        result["pattern"] = "ipv4"
    if "range_of" in item:
        if not isinstance(item["range_of"], str) or item["range_of"].count(".") != 1:
            fail(line, f"'range_of' of '{name}' names an FB input of the range table, e.g. \"CBT_Connect.Time_Out\"")
        result["range_of"] = item["range_of"]
    if "execute" in item:
        if item["execute"] is not True or bare != "BOOL":
            fail(line, f"'execute': true marks a BOOL the HMI sets with a clean rising edge; '{name}' is {declared}")
        result["execute"] = True
    if "engineer" in item:
        members = _members(found.compiled)
        if not isinstance(item["engineer"], list) or any(m not in members for m in item["engineer"]):
            fail(line, f"'engineer' lists members of {declared} that only the engineer may change")
        result["engineer"] = item["engineer"]
    return result


def load_pages(directory: pathlib.Path | str, plc, shipped: bool = False) -> tuple[dict[str, dict], list[str]]:
    """Every ``*.json`` page description in ``directory`` checked against the program loaded in ``plc``: the good
    pages by name and one error text per bad file (the server starts with the good ones)."""
    directory = pathlib.Path(directory)
    types = user_globals(plc)
    pages: dict[str, dict] = {}
    errors: list[str] = []
    for path in sorted(directory.glob("*.json")):
        name = path.stem
        if not name.replace("_", "").replace("-", "").isalnum() or (name in BUILT_IN_PAGES and not shipped):
            errors.append(f"{path}: '{name}' cannot name a page (letters, digits, - and _, not a built-in page)")
            continue
        try:
            pages[name] = check_description(path, read_description(path), types, shipped)
        except PageError as exc:
            errors.append(str(exc))
    return pages, errors


SPEC_ORDER = ("type", "array", "access", "role", "execute", "maxlen", "pattern", "input", "min", "max", "unit")


def table_document(plc, pages: dict[str, dict], every_global: bool, title: str) -> dict:
    """The variable table (the document Mapping takes) generated from the program's global variables and the
    page descriptions: every variable a page shows is readable (``every_global``: every user global of a type a
    page can show), the described inputs, commands, parameters and writes are writable with the description's
    limits and role. System variables (P_On, _CurrentTime, ...) are left out."""
    found = user_globals(plc)
    variables: dict[str, dict] = {}
    types: dict[str, dict] = {}
    engineering: list[str] = []

    def readable(name: str) -> dict:
        symbol = found[name.upper()]
        if symbol.name not in variables:
            spec: dict[str, Any] = {"type": type_name(symbol.compiled), "access": "r"}
            if symbol.compiled.kind == "array":
                spec["array"] = list(symbol.compiled.dims[0])
            collect_types(symbol.compiled, types)
            variables[symbol.name] = spec
        return variables[symbol.name]

    def writable(item: dict, role: str) -> None:
        spec = readable(item["variable"])
        spec["access"] = "rw"
        if role == "engineer" or spec.get("role") == "engineer":
            spec["role"] = "engineer"
        size = string_length(spec["type"])
        if size is not None:
            spec["maxlen"] = size - 1                # Sysmac STRING[n] holds n-1 characters (NUL)
        for key, target in (("execute", "execute"), ("pattern", "pattern"), ("range_of", "input"),
                            ("min", "min"), ("max", "max"), ("unit", "unit")):
            if key in item:
                spec[target] = item[key]
        for member in item.get("engineer", []):
            if member not in engineering:
                engineering.append(member)

    if every_global:
        for symbol in found.values():
            if _is_scalar(symbol.type):
                readable(symbol.name)
    for page in pages.values():
        role = page.get("role", "operator")
        if page["command"]:
            writable({**page["command"], "execute": True}, role)
        if "parameters" in page:
            writable({"variable": page["parameters"]["variable"], "engineer": page["parameters"]["engineer"]}, role)
            fields = types[page["parameters"]["type"]]["fields"]
            for member, limit in page["parameters"].get("limits", {}).items():
                fields[member].update(limit)             # the member's range, checked by the page and the server
        for item in page["inputs"] + page.get("writes", []):
            writable(item, item.get("role", role))
        for name in [item["variable"] for item in page["status"]] + page.get("reads", []) + \
                ([page["lamp"]] if "lamp" in page else []):
            readable(name)
    ordered = {name: {key: spec[key] for key in SPEC_ORDER if key in spec} for name, spec in variables.items()}
    document: dict[str, Any] = {"title": title}
    if engineering:
        document["engineering_members"] = engineering
    document.update({"types": types, "variables": ordered, "pages": ["index", *[p for p in pages if p != "index"]]})
    return document


def program_table(plc, pages: dict[str, dict]) -> dict:
    """The variable table of a user's program (``python3 -m cbt_hmi.web.cell``): every user global of a type a page
    can show is readable, the described pages' variables as ``table_document`` makes them; the pages go to
    ``custom_pages``."""
    document = table_document(plc, pages, True, "Variable table generated from the program's global variables")
    document["custom_pages"] = pages
    return document
