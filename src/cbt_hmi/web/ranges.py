"""Parameter ranges of the HMI taken from the library's one range table (cbt_hmi/pages/ranges.json, generated from
docs/library/ranges.tsv by docs/library/make_types.py), never typed into the variable table a second time.

For every structure member (or FB input) in the table, the variable table's spec gets (an FB of which the
variable table feeds no input, e.g. CBT_SetOverride while the HMI has no override setting, is left out; one it
feeds must have every ranged input, so a misspelt name is still an error):
  min / max   the widest range over all conditions: what the server accepts for a single write
  ranges      the conditional ranges ({"when": {"DataFormat": [...]}, "min", "max", "unit", "error"}): the page
              applies the one that matches the selected data format, blending, module ...
  allowed     the data formats a motion command takes ({"when": {"MovementCommand": ["PTP"]}, "allowed": [...]})
A structure-typed member (TargetPosition, MomentOfInertia) passes min / max on to its members.
"""
from __future__ import annotations

import json
import pathlib
from typing import Any


class RangeTableError(ValueError):
    """cbt_hmi/pages/ranges.json is unreadable or names something the variable table does not have."""


def read_json(path: pathlib.Path, what: str, error: type[Exception]) -> Any:
    """The JSON document in ``path``; ``error`` names the file (and line and column) when it cannot be read."""
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise error(f"{path}: cannot read the {what} ({exc.strerror})") from None
    except json.JSONDecodeError as exc:
        raise error(f"{path}:{exc.lineno}:{exc.colno}: invalid JSON: {exc.msg}") from None


def load_ranges(path: pathlib.Path) -> dict:
    table = read_json(path, "range table", RangeTableError)
    return {k: v for k, v in table.items() if not k.startswith("_")}


def apply_ranges(document: dict, table: dict, source: str = "ranges") -> dict:
    """Write the table's ranges into the variable table ``document`` (in place; returned for chaining)."""
    types = document.get("types", {})
    inputs = {spec["input"]: spec for spec in document.get("variables", {}).values() if "input" in spec}
    fed = {name.partition(".")[0] for name in inputs}
    for owner, members in table.items():
        if owner not in types and owner not in fed and not owner.startswith("st"):
            continue                                    # an FB the HMI does not drive
        for member, entries in members.items():
            spec = types[owner].get("fields", {}).get(member) if owner in types else inputs.get(f"{owner}.{member}")
            if spec is None:
                raise RangeTableError(f"{source}: {owner}.{member} is not in the HMI variable table")
            numeric = [e for e in entries if "min" in e]
            allowed = [e for e in entries if "allowed" in e]
            if numeric:
                spec["min"] = min(e["min"] for e in numeric)
                spec["max"] = max(e["max"] for e in numeric)
                spec["ranges"] = numeric
                units = [e["unit"] for e in numeric if e["unit"] not in ("", "—")]
                if units and spec["type"] not in types:
                    spec["unit"] = " or ".join(dict.fromkeys(units))
            if allowed:
                spec["allowed"] = allowed
    return document
