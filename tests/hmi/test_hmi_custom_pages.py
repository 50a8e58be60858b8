"""Pages for the user's own program (issue 25 item 12): a small conveyor cell (tests/hmi/user_cell/Conveyor.st, not
one of the examples) and its page description (user_cell/conveyor.json) run end to end on the virtual PLC in real
time and in headless Chromium at 800x480 and 1280x800; the variable table is generated from the program's global
variables; bad page descriptions are reported with their file and line while the good pages are served."""
from __future__ import annotations

import json
import os
import pathlib
import shutil
import urllib.error
import urllib.request

import pytest
from browser import chromium_paths
from hmi_system import serving_user_program
from panel_metrics import page_metrics

from cbt_hmi.web.mapping import Mapping
from cbt_hmi.web.pagedesc import load_pages, program_table
from cbt_hmi.web.server import HmiServer
from vplc.api import load_plc

CELL = pathlib.Path(__file__).resolve().parent / "user_cell"


def cell_plc(directory: pathlib.Path):
    return load_plc([str(directory / "Conveyor.st")], task="Main@10ms", programs=["Conveyor"])


@pytest.fixture(scope="module")
def cell():
    with serving_user_program(CELL, "Conveyor.st", "Conveyor") as served:
        yield served


def test_the_variable_table_is_generated_from_the_programs_global_variables(cell):
    plc, server = cell
    variables = server.mapping.document["variables"]
    assert set(variables) == {"Belt_Start", "Belt_Speed", "Belt_Target", "Belt_Running", "Belt_Jam", "Belt_Count",
                              "Belt_Position"}                 # no system variables (P_On, _CurrentTime, ...)
    assert variables["Belt_Speed"] == {"type": "REAL", "access": "rw", "min": 10, "max": 500, "unit": "mm/s"}
    assert variables["Belt_Start"]["execute"] is True
    assert variables["Belt_Count"] == {"type": "DINT", "access": "r"}       # shown, not written: read only
    assert server.mapping.pages == {"index", "conveyor"}


needs_chromium = pytest.mark.skipif(chromium_paths() is None, reason="chromium/chromedriver: run `make browser`")


@pytest.fixture
def browser(chromium):
    yield chromium
    chromium.fit()


def sized(browser, size):
    browser.size(*size)


@needs_chromium
def test_the_described_page_runs_the_users_cell_end_to_end(cell, browser):
    plc, server = cell
    sized(browser, (800, 480))
    browser.open(server.page_url("conveyor", "operator"))
    text = browser.driver.find_element("id", "main").text
    for shown in ("Belt speed (mm/s)", "10..500 mm/s", "Parts per batch", "1..1000", "Start Batch", "Running",
                  "Jam", "Parts done", "Position (mm)"):
        assert shown in text
    assert browser.field("Belt_Speed").get_attribute("value") == "120"       # read from the PLC
    browser.type_into("Belt_Speed", "500")
    browser.type_into("Belt_Target", "3")
    browser.click("btn-execute")
    browser.wait_status("Belt_Running", "true", timeout=5)
    browser.wait_status("Belt_Count", "3", timeout=10)                     # 300 mm at 500 mm/s: 0.6 s
    browser.wait_status("Belt_Running", "false", timeout=5)
    assert "Start Batch: the PLC took the command" in browser.message()
    with plc.lock:
        assert plc.read("Belt_Speed") == 500.0 and plc.read("Belt_Target") == 3 and plc.read("Belt_Start") is False
    browser.screenshot("custom_conveyor_800x480")


@needs_chromium
def test_a_value_outside_the_descriptions_limits_is_refused_before_it_is_sent(cell, browser):
    plc, server = cell
    sized(browser, (800, 480))
    browser.open(server.page_url("conveyor", "operator"))
    browser.type_into("Belt_Speed", "900")
    browser.click("btn-execute")
    browser.wait_for(lambda d: "nothing was sent" in browser.message(), "the refusal")
    assert browser.message() == "Belt speed: 900 is out of range 10..500 mm/s — nothing was sent."
    with plc.lock:
        assert plc.read("Belt_Speed") != 900.0


@needs_chromium
@pytest.mark.parametrize("size", [(800, 480), (1280, 800)], ids=["800x480", "1280x800"])
def test_the_described_page_and_its_main_page_meet_the_panel_rules(cell, browser, size):
    _, server = cell
    for name in ("conveyor", "index"):
        sized(browser, size)
        browser.open(server.page_url(name, "operator"))
        browser.screenshot(f"custom_{name}_{size[0]}x{size[1]}")
        assert page_metrics(browser) == {"small": [], "text": [], "contrast": []}
        assert browser.viewport_overflow() == []
    assert browser.driver.find_element("id", "nav-conveyor").text == "Conveyor"     # the main page lists it


MARKUP = "Belt <img src=x onerror=\"document.documentElement.dataset.ran = 'yes'\"> & <b>co</b>"


@needs_chromium
def test_markup_in_a_page_description_is_shown_as_text_and_never_run(tmp_path, browser):
    """A page description is a file anyone with the pages folder can edit: its title and labels are shown as
    written, and the server's Content-Security-Policy runs no script written into a page."""
    shutil.copy(CELL / "Conveyor.st", tmp_path / "Conveyor.st")
    description = json.loads((CELL / "conveyor.json").read_text(encoding="utf-8"))
    description["title"] = MARKUP
    description["inputs"][0]["label"] = MARKUP
    description["status"][0]["label"] = MARKUP
    (tmp_path / "conveyor.json").write_text(json.dumps(description), encoding="utf-8")
    with serving_user_program(tmp_path, "Conveyor.st", "Conveyor") as (_plc, server):
        with urllib.request.urlopen(f"{server.url}conveyor.html", timeout=5) as answer:
            policy = answer.headers["Content-Security-Policy"]
        assert "script-src 'self'" in policy and "unsafe-inline" not in policy.split("script-src")[1].split(";")[0]
        for name in ("conveyor", "index"):
            sized(browser, (800, 480))
            browser.open(server.page_url(name, "operator"))
            d = browser.driver
            assert d.execute_script("return document.documentElement.dataset.ran") is None
            assert d.execute_script("return document.querySelectorAll('main img, header img').length") == 0
        assert d.find_element("id", "nav-conveyor").text == MARKUP
        browser.open(server.page_url("conveyor", "operator"))
        assert browser.driver.find_element("css selector", "header h1").text == MARKUP
        assert MARKUP in browser.driver.find_element("id", "main").text            # the input's and status's label
        assert browser.driver.execute_script("return document.documentElement.dataset.ran") is None


BAD = {   # file name -> (content, line of the mistake, words the error must contain)
    "unknown_variable.json": ('{"title": "A",\n "status": [\n  {"variable": "Belt_Running", "label": "Run"},\n'
                              '  {"variable": "Belt_Sped", "label": "Speed"}]}', 4, "unknown variable 'Belt_Sped'"),
    "wrong_type.json": ('{"title": "B",\n "command": {"variable": "Belt_Speed", "label": "Go"}}', 2,
                        "'Belt_Speed' is REAL: the command must be a BOOL"),
    "limits_on_bool.json": ('{"title": "C",\n "inputs": [\n  {"variable": "Belt_Jam", "label": "Jam",\n'
                            '   "min": 0, "max": 1}]}', 3, "'min' and 'max' are for numeric variables only"),
    "missing_label.json": ('{"title": "D",\n "inputs": [{"variable": "Belt_Speed"}]}', 2,
                           "missing field 'label'"),
    "missing_title.json": ('\n{"inputs": [{"variable": "Belt_Speed", "label": "S"}]}', 2, "missing field 'title'"),
    "typo_key.json": ('{"title": "E",\n "status": [{"variable": "Belt_Count", "lable": "Parts"}]}', 2,
                      "unknown key 'lable'"),
    "not_json.json": ('{"title": "F",\n "status": [\n  {"variable": "Belt_Count" "label": "Parts"}]}', 3,
                      "not valid JSON"),
    "abnormal_text.json": ('{"title": "H", "status": [\n {"variable": "Belt_Jam", "label": "J", "abnormal": "yes"}]}',
                           2, "'abnormal' must be true or false, not \"yes\""),
    "int_range.json": ('{"title": "G", "inputs": [\n {"variable": "Belt_Target", "label": "T", "min": 0, '
                       '"max": 99999999999}]}', 2, "outside what DINT holds"),
}


def test_bad_page_descriptions_are_named_with_file_and_line_and_the_good_pages_are_served(tmp_path):
    for name in ("Conveyor.st", "conveyor.json"):
        shutil.copy(CELL / name, tmp_path / name)
    for name, (content, _, _) in BAD.items():
        (tmp_path / name).write_text(content, encoding="utf-8")
    plc = cell_plc(tmp_path)
    try:
        pages, errors = load_pages(tmp_path, plc)
        assert list(pages) == ["conveyor"]
        assert len(errors) == len(BAD)
        for name, (_, line, words) in BAD.items():
            error = next(e for e in errors if e.startswith(f"{tmp_path / name}:"))
            assert error.startswith(f"{tmp_path / name}:{line}: ") and words in error, error
        server = HmiServer(plc, Mapping(program_table(plc, pages)), port=0)
        server.start()
        try:
            with urllib.request.urlopen(f"{server.url}conveyor.html", timeout=5) as answer:
                assert answer.status == 200
            with pytest.raises(urllib.error.HTTPError) as refused:
                urllib.request.urlopen(f"{server.url}wrong_type.html", timeout=5)
            assert refused.value.code == 404
            with urllib.request.urlopen(f"{server.url}api/mapping", timeout=5) as answer:
                assert list(json.load(answer)["custom_pages"]) == ["conveyor"]
        finally:
            server.stop()
    finally:
        plc.close()


def test_a_pipe_or_a_device_in_the_pages_folder_is_named_and_the_good_pages_are_loaded(tmp_path):
    """A pipe nobody writes to is not waited on, a link to /dev/zero is not read (it never ends)."""
    for name in ("Conveyor.st", "conveyor.json"):
        shutil.copy(CELL / name, tmp_path / name)
    os.mkfifo(tmp_path / "pipe.json")
    os.symlink("/dev/zero", tmp_path / "zero.json")
    plc = cell_plc(tmp_path)
    try:
        pages, errors = load_pages(tmp_path, plc)
    finally:
        plc.close()
    assert list(pages) == ["conveyor"]
    assert errors == [f"{tmp_path / name}: not a regular file (a device, pipe, socket or folder): not a page "
                      "description" for name in ("pipe.json", "zero.json")]


def test_the_cell_server_reports_a_bad_page_and_serves_the_others(tmp_path):
    """python3 -m cbt_hmi.web.cell: the bad file is printed with its file and line, the good page is served."""
    import subprocess
    import sys
    for name in ("Conveyor.st", "conveyor.json"):
        shutil.copy(CELL / name, tmp_path / name)
    content, _, _ = BAD["unknown_variable.json"]
    (tmp_path / "unknown_variable.json").write_text(content, encoding="utf-8")
    process = subprocess.Popen([sys.executable, "-m", "cbt_hmi.web.cell", "--pages", str(tmp_path), "--port", "0",
                                "--program", "Conveyor", str(tmp_path / "Conveyor.st")],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = process.stdout.readline()           # printed once the server listens
        assert line.startswith("1 page(s) from"), (line, process.stderr.read() if process.poll() is not None else "")
        url = line.split("operator: ")[1].split("#")[0]
        with urllib.request.urlopen(f"{url}conveyor.html", timeout=5) as answer:
            assert answer.status == 200
    finally:
        process.terminate()
        _, err = process.communicate(timeout=10)
    assert f"error: {tmp_path / 'unknown_variable.json'}:4: unknown variable 'Belt_Sped'" in err
