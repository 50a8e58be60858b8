"""docs/simulator.md ("Limits") shows every bound of tmsim/limits.py with its value (one fact, one home)."""
import pathlib
import re

from tmsim import limits

DOC = pathlib.Path(__file__).resolve().parents[2] / "docs" / "simulator.md"


def test_every_bound_of_limits_py_is_in_the_docs_table_with_its_value():
    text = DOC.read_text(encoding="utf-8")
    shown = {name: float(value) for name, value in re.findall(r"`([A-Z][A-Z_]+)` = (-?[0-9.e]+)", text)}
    bounds = {name: value for name, value in vars(limits).items()
              if name.isupper() and isinstance(value, (int, float))}
    assert set(bounds) <= set(shown), f"missing in docs/simulator.md: {sorted(set(bounds) - set(shown))}"
    for name, value in bounds.items():
        assert shown[name] == float(value), f"{name}: docs say {shown[name]}, sim/limits.py says {value}"
