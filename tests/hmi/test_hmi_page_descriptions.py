"""The shipped pages as page descriptions (issue 25, deliver item 9): the command pages are built from
cbt_hmi/pages/desc/*.json, the variable table (pages/mapping.json) is generated from the example program's global
variables and those descriptions (a drift test regenerates it), the format's FB-instance keys are checked with file
and line, and a user's own FB-instance page (tests/hmi/user_gripper, not an example) runs end to end in Chromium at
800x480 and 1280x800 without any JavaScript of its own. Screenshots: artifacts/screenshots/desc_*.png."""
from __future__ import annotations

import json
import pathlib

import pytest
from browser import chromium_paths
from hmi_system import serving_user_program
from panel_metrics import page_metrics

from cbt_hmi import PAGES
from cbt_hmi.web.mapping import DEFAULT_MAPPING, Mapping
from cbt_hmi.web.pagedesc import DESC_DIR, load_pages
from cbt_hmi.web.shipped import render, shipped_table
from vplc.api import load_plc

ROOT = pathlib.Path(__file__).resolve().parents[2]
GRIPPER = pathlib.Path(__file__).resolve().parent / "user_gripper"
COMMAND_PAGES = {"connect", "changebase", "changetcp", "moverel", "moveabs", "movecircle", "setoutput", "stop"}


@pytest.fixture(scope="module")
def examples():
    plc = load_plc([str(ROOT / "lib" / "CBT_Commands_Lib"), str(ROOT / "examples")])
    yield plc
    plc.close()


def test_the_variable_table_is_generated_from_the_programs_globals_and_the_descriptions(examples):
    """No hand-edited table: regenerating mapping.json gives the committed file (python3 -m cbt_hmi.web.shipped)."""
    assert DEFAULT_MAPPING.read_text(encoding="utf-8") == render(shipped_table(examples)), \
        "pages/mapping.json is stale: run python3 -m cbt_hmi.web.shipped lib/CBT_Commands_Lib examples"


def test_every_command_page_is_built_from_its_description(examples):
    table = shipped_table(examples)
    assert set(table["page_descriptions"]) == COMMAND_PAGES
    assert set(table["pages"]) == {path.stem for path in DESC_DIR.glob("*.json")}
    move = table["page_descriptions"]["moveabs"]
    assert move["command"] == {"variable": "MoveAbs_Execute", "label": "Execute", "type": "BOOL"}
    assert [item["label"] for item in move["status"]] == ["Busy", "Done", "CommandAborted", "Error", "ErrorID",
                                                          "ErrorDescrip", "CmdID_Ack"]
    assert move["lamp"] == "MoveAbs_Active" and table["page_descriptions"]["changebase"]["lamp"] == "ChangeBase_Busy"
    assert table["variables"]["ChangeBase_Param"]["role"] == "engineer"          # "role": "engineer" of the page
    assert table["engineering_members"] == ["ExitNode"]
    assert table["variables"]["Connect_Time_Out"]["input"] == "CBT_Connect.Time_Out"   # ranges.json's row
    script = (PAGES / "hmi.js").read_text(encoding="utf-8")
    assert "const PAGES" not in script and "Set Null Tool Offset" not in script   # no page table in JavaScript
    mapping = Mapping.load()
    mapping.check_against_plc(examples)                                           # every leaf as the PLC declares it
    speed = mapping.document["types"]["stCBT_MovAbsParam"]["fields"]["Speed"]
    assert speed["min"] == 1 and speed["max"] == 4500 and len(speed["ranges"]) == 2   # per data format


BAD = {   # file name -> (content, line of the mistake, words the error must contain)
    "no_execute.json": ('\n{"title": "A",\n "instance": "Nothing"}', 2, "no BOOL 'Nothing_Execute'"),
    "not_a_struct.json": ('{"title": "B", "instance": "MoveAbs",\n "parameters": {\n  "variable": "MoveAbs_Done"}}',
                          2, "'MoveAbs_Done' is BOOL: 'parameters' names a structure"),
    "bad_member.json": ('{"title": "C", "instance": "MoveAbs",\n "parameters": {"variable": "MoveAbs_Param"},\n'
                        ' "presets": {\n  "P": {"Sped": 5}}}', 4, "'Sped' is not a field of this page"),
    "bad_enum.json": ('{"title": "D", "instance": "MoveAbs",\n "parameters": {"variable": "MoveAbs_Param"},\n'
                      ' "presets": {"P": {\n   "DataFormat": "CPP_Ab"}}}', 3, "\"CPP_Ab\" is not one of JPP_Abs"),
    "bad_range.json": ('{"title": "E", "instance": "MoveAbs",\n "parameters": {"variable": "MoveAbs_Param"},\n'
                       ' "presets": {"P": {"Speed": -1}}}', 3, "Speed is UINT: -1 is not a whole number in 0..65535"),
    "no_instance.json": ('{"title": "F",\n "presets": {}, "status": []}', 1, "'presets' is for a page that drives"),
    "bad_done.json": ('{"title": "G", "instance": "MoveAbs",\n "parameters": {"variable": "MoveAbs_Param"},\n'
                      ' "done": [\n  {"when": {"Blending": true}, "text": "x"}]}', 4,
                      "'Blending' is not a member of the parameters"),
    "script.json": ('{"title": "H",\n "script": "pnp"}', 1, "unknown key 'script'"),
}


def test_mistakes_in_the_fb_instance_keys_are_named_with_file_and_line(examples, tmp_path):
    (tmp_path / "good.json").write_text('{"title": "Good", "instance": "MoveRel",\n'
                                        ' "parameters": {"variable": "MoveRel_Param"}}', encoding="utf-8")
    for name, (content, _, _) in BAD.items():
        (tmp_path / name).write_text(content, encoding="utf-8")
    pages, errors = load_pages(tmp_path, examples)
    assert list(pages) == ["good"] and len(errors) == len(BAD)
    for name, (_, line, words) in BAD.items():
        error = next(e for e in errors if e.startswith(f"{tmp_path / name}:"))
        assert error.startswith(f"{tmp_path / name}:{line}: ") and words in error, error


@pytest.fixture(scope="module")
def gripper():
    with serving_user_program(GRIPPER, "Gripper.st", "Gripper") as served:
        yield served


def test_a_users_fb_instance_page_gets_its_table_from_the_description(gripper):
    _, server = gripper
    document = server.mapping.document
    assert document["variables"]["Grip_Param"] == {"type": "stGripParam", "access": "rw"}
    assert document["types"]["stGripParam"]["fields"]["Force"] == {"type": "REAL", "min": 5, "max": 100, "unit": "N"}
    assert document["types"]["eGripMode"] == {"enum": {"GripOpen": 0, "GripClose": 1, "GripHold": 2}}
    assert server.mapping.leaves["Grip_Param.Force"].max == 100                   # the server checks it too
    assert json.loads(json.dumps(document["custom_pages"]["gripper"]))["instance"] == "Grip"


needs_chromium = pytest.mark.skipif(chromium_paths() is None, reason="chromium/chromedriver: run `make browser`")


def sized(browser, size):
    browser.size(*size)


@pytest.fixture
def browser(chromium):
    yield chromium
    chromium.fit()


@needs_chromium
def test_the_users_fb_instance_page_runs_end_to_end(gripper, browser):
    plc, server = gripper
    sized(browser, (800, 480))
    browser.open(server.page_url("gripper", "operator"))
    text = browser.driver.find_element("id", "main").text
    for shown in ("Gripper Settings", "Jaw Command", "Force", "5..100 N", "Done when in position", "Close on Part",
                  "Open", "Execute", "Command Status", "Jaws closed"):
        assert shown in text, shown
    mode = browser.field("Grip_Param.Mode")
    assert mode.tag_name == "select" and mode.text.split() == ["GripOpen", "GripClose", "GripHold"]
    assert browser.field("Grip_Param.Force").get_attribute("value") == "40"     # read from the PLC
    browser.type_into("Grip_Param.Force", "150")
    browser.click("btn-execute")
    browser.wait_for(lambda d: "nothing was sent" in browser.message(), "the refusal")
    assert browser.message() == "Force: 150 is out of range 5..100 N — nothing was sent."
    browser.click("btn-preset-2")                                                # Open
    assert browser.field("Grip_Param.Force").get_attribute("value") == "10"
    browser.click("btn-execute")
    browser.wait_for(lambda d: "Done" in browser.message(), "Done", timeout=5)
    assert browser.message() == "Gripper: Done – the jaws are open."
    browser.wait_status("Grip_Done", "true")
    with plc.lock:
        assert plc.read("Grip_Param.Mode") == "GripOpen" and plc.read("Grip_Param.Width") == 60
    browser.screenshot("desc_gripper_800x480")


@needs_chromium
@pytest.mark.parametrize("size", [(800, 480), (1280, 800)], ids=["800x480", "1280x800"])
def test_the_users_fb_instance_page_meets_the_panel_rules(gripper, browser, size):
    _, server = gripper
    sized(browser, size)
    browser.open(server.page_url("gripper", "operator"))
    browser.screenshot(f"desc_gripper_{size[0]}x{size[1]}")
    assert page_metrics(browser) == {"small": [], "text": [], "contrast": []}
    assert browser.viewport_overflow() == []
