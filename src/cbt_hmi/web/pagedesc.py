"""Pages for the user's own program: one page description file (JSON) per page says which PLC variables the page
shows, with their labels, units and limits; the HMI builds the page from it (hmi.js customPage) without any
JavaScript of the user's. The variable table those pages use is generated from the program's global variables
(``program_table``), not written by hand.

A page description file ``<page>.json`` (the page is then ``<page>.html``)::

    {"title": "Conveyor",
     "inputs":  [{"variable": "Belt_Speed", "label": "Belt speed", "unit": "mm/s", "min": 0, "max": 500}],
     "command": {"variable": "Belt_Start", "label": "Start belt"},
     "status":  [{"variable": "Belt_Running", "label": "Running"},
                 {"variable": "Belt_Jam", "label": "Jam", "abnormal": true}]}

Keys: ``title`` (text, required); ``inputs`` (fields the operator writes), ``status`` (values shown) and
``command`` (a BOOL the page's command key sets with a clean rising edge; the program resets it) — at least
one of them. Every item needs ``variable`` and ``label``;
``unit`` (text), ``min``/``max`` (numbers, numeric variables only), ``role`` ("operator" or "engineer", inputs
only) and ``abnormal`` (BOOL status only: TRUE is an abnormal state, its lamp turns red) are optional. Every mistake is
reported with the file and the line of the item; a page with a mistake is left out and the others are served."""
from __future__ import annotations

import json
import json.decoder
import json.scanner
import pathlib

from .mapping import INT_RANGES, REAL_TYPES, _string_length

PAGE_KEYS = {"title", "inputs", "status", "command"}
ITEM_KEYS = {"inputs": {"variable", "label", "unit", "min", "max", "role"},
             "status": {"variable", "label", "unit", "abnormal"},
             "command": {"variable", "label"}}
NUMERIC = set(INT_RANGES) | REAL_TYPES
# pages of the HMI itself: a description may not take their names
BUILT_IN_PAGES = {"index", "connect", "changebase", "changetcp", "moverel", "moveabs", "movecircle", "setoutput",
                  "stop", "pnp", "jog", "program"}
MAX_FILE_BYTES = 64 * 1024


class PageError(Exception):
    """A page description file that cannot be used; str() names the file and line."""


class _Located(dict):
    """A JSON object that knows the line it starts on."""
    line = 0


def _located_decoder() -> json.JSONDecoder:
    decoder = json.JSONDecoder()

    def parse_object(s_and_end, strict, scan_once, object_hook, object_pairs_hook, memo=None):
        text, start = s_and_end
        value, end = json.decoder.JSONObject(s_and_end, strict, scan_once, None, None, memo)
        located = _Located(value)
        located.line = text.count("\n", 0, start) + 1
        return located, end

    decoder.parse_object = parse_object
    decoder.scan_once = json.scanner.py_make_scanner(decoder)   # the pure-Python scanner calls parse_object
    return decoder


def read_description(path: pathlib.Path) -> _Located:
    """The page description's JSON, each object with its line; PageError (file:line: reason) when unreadable."""
    try:
        raw = path.read_bytes()[:MAX_FILE_BYTES + 1]
    except OSError as exc:
        raise PageError(f"{path}: cannot be read ({exc.strerror})") from None
    if len(raw) > MAX_FILE_BYTES:
        raise PageError(f"{path}: larger than {MAX_FILE_BYTES // 1024} KiB: not a page description")
    try:
        document = _located_decoder().decode(raw.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise PageError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    except json.JSONDecodeError as exc:
        raise PageError(f"{path}:{exc.lineno}: not valid JSON: {exc.msg} (column {exc.colno})") from None
    if not isinstance(document, _Located):
        raise PageError(f"{path}:1: a page description is a JSON object {{\"title\": ..., \"inputs\": [...]}}")
    return document


def user_globals(plc) -> dict[str, tuple[str, str]]:
    """The program's own global variables (Sysmac system and motion variables and constants left out):
    upper-case name -> (declared name, declared type without namespace)."""
    found = {}
    for name, symbol in plc.project.globals.items():
        if str(getattr(symbol, "global_list", "") or "").startswith("sysmac_") or getattr(symbol, "constant", False):
            continue                     # Sysmac system variables (P_On, _CurrentTime, ...), motion axes, constants
        found[name.upper()] = (symbol.name, plc.var_type(symbol.name).rsplit("\\", 1)[-1])
    return found


def check_description(path: pathlib.Path, document: _Located, types: dict[str, tuple[str, str]]) -> dict:
    """The page as hmi.js builds it: {"title", "inputs", "status", "command"} with each variable's type; raises
    PageError naming the file and line of the first mistake."""
    def fail(line: int, text: str):
        raise PageError(f"{path}:{line}: {text}")

    unknown = sorted(set(document) - PAGE_KEYS)
    if unknown:
        fail(document.line, f"unknown key '{unknown[0]}' (a page has {', '.join(sorted(PAGE_KEYS))})")
    title = document.get("title")
    if not isinstance(title, str) or not title.strip():
        fail(document.line, "missing field 'title': the page's name in its header, as text")
    if not any(key in document for key in ("inputs", "status", "command")):
        fail(document.line, "the page shows nothing: give 'inputs', 'status' or 'command'")
    page = {"title": title.strip(), "inputs": [], "status": [], "command": None}
    for section in ("inputs", "status"):
        items = document.get(section, [])
        if not isinstance(items, list):
            fail(document.line, f"'{section}' must be a list of items {{\"variable\": ..., \"label\": ...}}")
        for item in items:
            page[section].append(_check_item(section, item, document.line, types, fail))
    if "command" in document:
        page["command"] = _check_item("command", document["command"], document.line, types, fail)
    return page


def _check_item(section: str, item, parent_line: int, types: dict, fail) -> dict:
    if not isinstance(item, _Located):
        fail(parent_line, f"an item of '{section}' must be an object {{\"variable\": ..., \"label\": ...}}, "
                          f"not {json.dumps(item)}")
    line = item.line
    unknown = sorted(set(item) - ITEM_KEYS[section])
    if unknown:
        fail(line, f"unknown key '{unknown[0]}' in an item of '{section}' "
                   f"(allowed: {', '.join(sorted(ITEM_KEYS[section]))})")
    for key in ("variable", "label"):
        if not isinstance(item.get(key), str) or not item[key].strip():
            fail(line, f"missing field '{key}' (text) in an item of '{section}'")
    name = item["variable"].strip()
    if name.upper() not in types:
        fail(line, f"unknown variable '{name}': the program has no global variable of that name")
    name, declared = types[name.upper()]
    bare = declared
    if bare not in NUMERIC and bare != "BOOL" and _string_length(bare) is None:
        fail(line, f"'{name}' is {declared}: a described page shows BOOL, integer, REAL/LREAL and STRING "
                   f"variables")
    if section == "command" and bare != "BOOL":
        fail(line, f"'{name}' is {declared}: the command must be a BOOL the program acts on")
    result = {"variable": name, "label": item["label"].strip(), "type": bare}
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
    role = item.get("role", "operator")
    if role not in ("operator", "engineer"):
        fail(line, f"'role' of '{name}' must be \"operator\" or \"engineer\", not {json.dumps(role)}")
    if section == "inputs":
        result["role"] = role
    if "abnormal" in item:
        if not isinstance(item["abnormal"], bool) or bare != "BOOL":
            fail(line, f"'abnormal' (true or false) is for BOOL status values; '{name}' is {declared}")
        result["abnormal"] = item["abnormal"]
    return result


def load_pages(directory: pathlib.Path | str, plc) -> tuple[dict[str, dict], list[str]]:
    """Every ``*.json`` page description in ``directory`` checked against the program loaded in ``plc``: the good
    pages by name and one error text per bad file (the server starts with the good ones)."""
    directory = pathlib.Path(directory)
    types = user_globals(plc)
    pages: dict[str, dict] = {}
    errors: list[str] = []
    for path in sorted(directory.glob("*.json")):
        name = path.stem
        if not name.replace("_", "").replace("-", "").isalnum() or name in BUILT_IN_PAGES:
            errors.append(f"{path}: '{name}' cannot name a page (letters, digits, - and _, not a built-in page)")
            continue
        try:
            pages[name] = check_description(path, read_description(path), types)
        except PageError as exc:
            errors.append(str(exc))
    return pages, errors


def program_table(plc, pages: dict[str, dict]) -> dict:
    """The variable table (the document Mapping takes) generated from the program's global variables: every user
    global of a type a page can show is readable; the described inputs and commands are writable, with the
    page's limits and role. System variables (P_On, _CurrentTime, ...) are left out."""
    variables: dict[str, dict] = {}
    for name, declared in user_globals(plc).values():
        if declared in NUMERIC or declared == "BOOL" or _string_length(declared) is not None:
            variables[name] = {"type": declared, "access": "r"}
    by_upper = {name.upper(): name for name in variables}
    for page in pages.values():
        writable = [dict(item, role=item["role"]) for item in page["inputs"]]
        if page["command"]:
            writable.append({**page["command"], "role": "operator", "execute": True})
        for item in writable:
            spec = variables[by_upper[item["variable"].upper()]]
            spec["access"] = "rw"
            if item["role"] == "engineer" or spec.get("role") == "engineer":
                spec["role"] = "engineer"
            for key in ("min", "max", "unit", "execute"):
                if key in item:
                    spec[key] = item[key]
        for item in page["inputs"] + page["status"] + ([page["command"]] if page["command"] else []):
            item["variable"] = by_upper[item["variable"].upper()]     # the declared spelling
    return {"title": "Variable table generated from the program's global variables", "types": {},
            "variables": variables, "pages": ["index", *pages], "custom_pages": pages}
