"""The timing diagrams of docs/library/ are what a real run draws: every FB page shows the diagram of its own
example, and regenerating them all (virtual time, deterministic) reproduces the committed files byte for byte."""
from __future__ import annotations

import filecmp
import importlib.util
import re

import pytest
from doc_steps import STEPS
from rig import ROOT

DOCS = ROOT / "docs" / "library"


def make_traces():
    spec = importlib.util.spec_from_file_location("make_traces", DOCS / "make_traces.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_fb_page_shows_the_diagram_of_its_own_example():
    mt = make_traces()
    for page in STEPS:
        text = (DOCS / f"{page}.md").read_text(encoding="utf-8")
        timing = re.search(r"^## Timing\n(.*?)^## ", text, re.S | re.M).group(1)
        name = mt.trace_name(page)
        assert f"![{name}](traces/{name})" in timing, page
        assert "Drawn from a real run of the example below" in timing, page
        assert (DOCS / "traces" / name).is_file(), name


def test_non_blended_pages_do_not_say_done_on_acceptance():
    for page in ("CBT_MoveRelative", "CBT_MoveCircle"):
        timing = re.search(r"^## Timing\n(.*?)^## ", (DOCS / f"{page}.md").read_text(encoding="utf-8"),
                           re.S | re.M).group(1)
        assert "Not blended (the example): Active from the robot's acceptance, Done when the robot has arrived" \
            in timing


@pytest.mark.slow
def test_every_diagram_is_referenced_and_regenerates_identically(tmp_path):
    committed = {p.name for p in (DOCS / "traces").glob("*.svg")}
    pages = "".join(p.read_text(encoding="utf-8") for p in DOCS.glob("*.md"))
    assert {n for n in committed if f"traces/{n}" not in pages} == set()
    make_traces().main(tmp_path)
    produced = {p.name for p in tmp_path.glob("*.svg")}
    assert produced == committed
    _, mismatch, errors = filecmp.cmpfiles(DOCS / "traces", tmp_path, sorted(committed), shallow=False)
    assert mismatch == [] and errors == [], "run make traces"
