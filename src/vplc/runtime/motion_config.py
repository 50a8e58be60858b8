"""The axis configuration file: which virtual servo axes exist and their limits.

A TOML file (read with the standard library's tomllib), one ``[[axis]]`` table per axis::

    [[axis]]
    number = 0                      # _MC_AX[0]
    name = "MC_Shuttle"             # optional: a global _sAXIS_REF of this name is the same axis
    units = "mm"                    # pulse, mm, um, nm, deg, inch
    max_velocity = 500.0            # units/s
    max_acceleration = 5000.0       # units/s^2
    max_deceleration = 5000.0       # optional, default max_acceleration
    max_jerk = 0.0                  # optional, units/s^3: an instruction's Jerk above it runs at it (0 = no limit)
    software_limit_negative = -5.0  # optional pair: software limits (active once home is defined)
    software_limit_positive = 1200.0
    home_position = 0.0             # optional: position MC_Home defines (zero position preset)
    homed = false                   # optional: home defined at start (absolute encoder)

Every mistake is an :class:`AxisConfigError` whose text names the file, the axis and the key.
"""
from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass
from typing import Any

from ..frontend.source import FileRefused, read_file_bytes

MAX_AXES = 64            # _MC_AX[0..63] (prelude/sysmac_motion.st)
UNITS = {"pulse": 0, "mm": 1, "um": 2, "nm": 3, "deg": 4, "inch": 5}     # _eMC_UNITS values
_MAX_FILE_BYTES = 1_000_000


class AxisConfigError(Exception):
    """The axis configuration cannot be used; ``str()`` names the file, the axis and the key."""


@dataclass(frozen=True)
class AxisConfig:
    number: int
    name: str | None
    units: str
    max_velocity: float
    max_acceleration: float
    max_deceleration: float
    max_jerk: float
    limit_negative: float | None
    limit_positive: float | None
    home_position: float
    homed: bool


_KEYS = {"number", "name", "units", "max_velocity", "max_acceleration", "max_deceleration", "max_jerk",
         "software_limit_negative", "software_limit_positive", "home_position", "homed"}


def load_axes(path: str | os.PathLike[str]) -> tuple[AxisConfig, ...]:
    """Read and check the axis configuration file ``path``."""
    path = os.fspath(path)
    try:
        data = read_file_bytes(path, _MAX_FILE_BYTES)
    except OSError as exc:
        raise AxisConfigError(f"{path}: cannot read the axis configuration ({exc.strerror or exc})") from None
    except FileRefused as exc:
        raise AxisConfigError(f"{path}: the axis configuration {exc}") from None
    try:
        doc = tomllib.loads(data.decode("utf-8"))
    except UnicodeDecodeError:
        raise AxisConfigError(f"{path}: the axis configuration is not UTF-8 text") from None
    except tomllib.TOMLDecodeError as exc:
        raise AxisConfigError(f"{path}: not a TOML file: {exc}") from None
    except (RecursionError, MemoryError):
        raise AxisConfigError(f"{path}: the axis configuration nests too deeply to be read") from None
    return parse_axes(doc, path)


def parse_axes(doc: dict[str, Any], path: str = "<axes>") -> tuple[AxisConfig, ...]:
    """Check the parsed document ``doc`` (as tomllib returns it)."""
    extra = sorted(set(doc) - {"axis"})
    if extra:
        raise AxisConfigError(f"{path}: unknown table or key `{extra[0]}`; the file holds [[axis]] tables only")
    tables = doc.get("axis")
    if not isinstance(tables, list) or not tables or not all(isinstance(t, dict) for t in tables):
        raise AxisConfigError(f"{path}: no axis declared; write one [[axis]] table per axis")
    axes: dict[int, AxisConfig] = {}
    names: dict[str, int] = {}
    for i, table in enumerate(tables, 1):
        ax = _axis(table, path, i)
        if ax.number in axes:
            raise AxisConfigError(f"{path}: axis {ax.number}: declared twice (tables {_table_of(tables, ax.number)})")
        if ax.name is not None:
            if ax.name.upper() in names:
                raise AxisConfigError(f"{path}: axis {ax.number}: name `{ax.name}` is also the name of axis "
                                      f"{names[ax.name.upper()]}")
            names[ax.name.upper()] = ax.number
        axes[ax.number] = ax
    return tuple(axes[n] for n in sorted(axes))


def _table_of(tables: list[dict[str, Any]], number: int) -> str:
    return " and ".join(str(i) for i, t in enumerate(tables, 1) if t.get("number") == number)


def _axis(t: dict[str, Any], path: str, index: int) -> AxisConfig:
    where = f"{path}: [[axis]] table {index}"
    number = t.get("number")
    if isinstance(number, bool) or not isinstance(number, int):
        raise AxisConfigError(f"{where}: `number` (the index n of _MC_AX[n]) is missing or not an integer")
    if not 0 <= number < MAX_AXES:
        raise AxisConfigError(f"{where}: axis number {number} is outside _MC_AX[0..{MAX_AXES - 1}]")
    where = f"{path}: axis {number}"
    unknown = sorted(set(t) - _KEYS)
    if unknown:
        raise AxisConfigError(f"{where}: unknown key `{unknown[0]}` (known: {', '.join(sorted(_KEYS))})")
    name = t.get("name")
    if name is not None and (not isinstance(name, str) or not name.isidentifier() or "__" in name):
        raise AxisConfigError(f"{where}: `name` must be an ST identifier such as \"MC_Axis000\" (got {name!r})")
    units = t.get("units", "mm")
    if units not in UNITS:
        raise AxisConfigError(f"{where}: `units` {units!r} is not one of {', '.join(UNITS)}")

    def optional(key: str, *, positive: bool = False) -> float | None:
        """The number under ``key`` (None when absent), checked: finite, > 0 when ``positive``, maxima >= 0."""
        v = t.get(key)
        if v is None:
            return None
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise AxisConfigError(f"{where}: `{key}` must be a finite number (got {v!r})")
        if positive and v <= 0:
            raise AxisConfigError(f"{where}: `{key}` must be greater than 0 (got {v!r})")
        if not positive and key.startswith("max_") and v < 0:
            raise AxisConfigError(f"{where}: `{key}` must not be negative (got {v!r})")
        return float(v)

    def number_of(key: str, default: float | None = None, *, positive: bool = False) -> float:
        """The number under ``key``, ``default`` when absent; absent without a default is an error."""
        v = optional(key, positive=positive)
        if v is not None:
            return v
        if default is None:
            raise AxisConfigError(f"{where}: `{key}` is missing")
        return default

    vmax = number_of("max_velocity", positive=True)
    amax = number_of("max_acceleration", positive=True)
    dmax = number_of("max_deceleration", amax, positive=True)
    jmax = number_of("max_jerk", 0.0)
    lo = optional("software_limit_negative")
    hi = optional("software_limit_positive")
    if (lo is None) != (hi is None):
        raise AxisConfigError(f"{where}: give both `software_limit_negative` and `software_limit_positive`, or "
                              "neither")
    if lo is not None and hi is not None and lo >= hi:
        raise AxisConfigError(f"{where}: `software_limit_negative` {lo:g} must be below `software_limit_positive` "
                              f"{hi:g}")
    home = number_of("home_position", 0.0)
    if lo is not None and hi is not None and not lo <= home <= hi:
        raise AxisConfigError(f"{where}: `home_position` {home:g} is outside the software limits {lo:g} .. {hi:g}")
    homed = t.get("homed", False)
    if not isinstance(homed, bool):
        raise AxisConfigError(f"{where}: `homed` must be true or false (got {homed!r})")
    return AxisConfig(number, name, units, vmax, amax, dmax, jmax, lo, hi, home, homed)
