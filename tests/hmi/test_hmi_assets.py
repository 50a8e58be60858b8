"""What the panel's browser may keep of the pages (cbt_hmi.web.assets): the page shell never, a style sheet, script or
data file named with the version of its bytes for good, any other file only with its validators (304 while unchanged).
Over HTTP against the shipped pages and a pages folder of the test's own, and in headless Chromium."""
from __future__ import annotations

import email.utils
import os
import pathlib
import re
import time

import pytest
from fake_plc import FakePlc, command_program, scanning
from hmi_http import Client

from cbt_hmi.web.assets import version_of
from cbt_hmi.web.mapping import HMI_DIR
from cbt_hmi.web.server import HmiServer

SHIPPED_REFERENCES = ["style.css", "program.css", "errors.json", "tm5_700.json", "limits.js", "robotview.js", "pnp.js",
                      "jog.js", "hmi.js", "program.js", "alarms.js", "custom.js"]


def references(shell: bytes) -> dict[str, str]:
    """name -> version of every src="name?v=version" / href="..." in ``shell``."""
    return {m.group(1).decode(): m.group(2).decode() for m in re.finditer(rb'(?:src|href)="([^"?]+)\?v=([0-9a-f]+)"',
                                                                         shell)}


@pytest.fixture
def own_pages(mapping, tmp_path):
    """An HMI server on a pages folder of the test's own: a shell naming a script, a style sheet and things that are
    not files of the folder; yields (client, folder)."""
    (tmp_path / "index.html").write_text(
        '<link rel="icon" href="data:,"><link rel="stylesheet" href="look.css">\n'
        '<a href="https://example.com/a.js">x</a><a href="missing.js">y</a><a href="index.html">z</a>\n'
        '<script src="app.js" defer></script>', encoding="utf-8")
    (tmp_path / "app.js").write_text("const A = 1;", encoding="utf-8")
    (tmp_path / "look.css").write_text("body { color: #000; }", encoding="utf-8")
    with scanning(FakePlc(mapping, command_program)) as plc:
        server = HmiServer(plc, mapping, port=0, root=tmp_path)
        server.start()
        try:
            yield Client(f"http://127.0.0.1:{server.port}"), tmp_path
        finally:
            server.stop()


def test_the_shell_names_every_file_it_loads_with_the_version_of_its_bytes_and_is_never_kept(client):
    status, shell, headers = client.request("/moveabs.html")
    assert status == 200 and headers["Cache-Control"] == "no-store" and "ETag" not in headers
    named = references(shell)
    assert sorted(named) == sorted(SHIPPED_REFERENCES)
    for name, version in named.items():
        assert version == version_of((HMI_DIR / name).read_bytes()), name


def test_a_file_asked_for_with_its_version_is_kept_for_good(client):
    named = references(client.request("/")[1])
    for name in ("hmi.js", "style.css", "errors.json"):
        status, body, headers = client.request(f"/{name}?v={named[name]}")
        assert status == 200 and body == (HMI_DIR / name).read_bytes()
        assert headers["Cache-Control"] == "max-age=31536000, immutable"
        assert headers["ETag"] == f'"{named[name]}"'


@pytest.mark.parametrize("query", ["", "?v=0123456789abcdef", "?v=", "?v=%ZZ&v=x", "?load=3", "?" + "a&" * 401])
def test_a_file_asked_for_without_its_version_is_kept_only_with_its_validator(client, query):
    status, body, headers = client.request(f"/hmi.js{query}")
    assert status == 200 and body == (HMI_DIR / "hmi.js").read_bytes()
    assert headers["Cache-Control"] == "no-cache"
    assert headers["ETag"] == f'"{version_of(body)}"'


@pytest.mark.parametrize("form", ['{tag}', 'W/{tag}', '"0000000000000000", {tag}', '*'])
def test_an_unchanged_file_is_answered_304_without_its_bytes(client, form):
    _, _, headers = client.request("/alarms.js")
    status, body, again = client.request("/alarms.js", headers={"If-None-Match": form.format(tag=headers["ETag"])})
    assert status == 304 and body == b"" and "Content-Type" not in again
    assert again["ETag"] == headers["ETag"] and again["Cache-Control"] == "no-cache"


def test_a_file_unchanged_since_the_date_a_browser_holds_is_answered_304(own_pages):
    """Chromium revalidates what an HTTP/1.0 server sent with If-Modified-Since only; If-None-Match, when sent,
    decides alone. A file changed within the last two seconds gets no date (a second change in the same second would
    keep it)."""
    client, folder = own_pages
    hour_ago = time.time() - 3600
    os.utime(folder / "app.js", (hour_ago, hour_ago))
    _, _, headers = client.request("/app.js")
    assert headers["Last-Modified"] == email.utils.formatdate(int(hour_ago), usegmt=True)
    status, body, _ = client.request("/app.js", headers={"If-Modified-Since": headers["Last-Modified"]})
    assert status == 304 and body == b""
    for stale in ({"If-Modified-Since": email.utils.formatdate(hour_ago - 60, usegmt=True)},
                  {"If-Modified-Since": "yesterday"},
                  {"If-Modified-Since": headers["Last-Modified"], "If-None-Match": '"0000000000000000"'}):
        assert client.request("/app.js", headers=stale)[0] == 200, stale
    (folder / "app.js").write_text("const A = 3;", encoding="utf-8")        # changed just now: no date to hold
    status, body, headers = client.request("/app.js", headers={"If-Modified-Since": headers["Last-Modified"]})
    assert status == 200 and body == b"const A = 3;" and "Last-Modified" not in headers


def test_a_changed_file_gets_its_bytes_again_and_a_new_version_in_the_next_shell(own_pages):
    client, folder = own_pages
    shell = client.request("/")[1]
    before = references(shell)
    assert before == {"look.css": version_of(b"body { color: #000; }"), "app.js": version_of(b"const A = 1;")}
    # what is not a file of the folder stays as it was: a data: URL, another site, a missing file, the shell itself
    assert b'href="data:,"' in shell and b'href="https://example.com/a.js"' in shell
    assert b'href="missing.js"' in shell and b'href="index.html"' in shell
    etag = client.request("/app.js")[2]["ETag"]
    (folder / "app.js").write_text("const A = 2;", encoding="utf-8")
    status, body, headers = client.request("/app.js", headers={"If-None-Match": etag})
    assert status == 200 and body == b"const A = 2;" and headers["ETag"] != etag
    after = references(client.request("/")[1])
    assert after["app.js"] == version_of(b"const A = 2;") and after["look.css"] == before["look.css"]
    # the old address still answers, with the new bytes, and they are not kept for good under the old version
    status, body, headers = client.request(f"/app.js?v={before['app.js']}")
    assert status == 200 and body == b"const A = 2;" and headers["Cache-Control"] == "no-cache"
    assert references(client.request("/./index.html")[1]) == after          # the shell by any of its names


def test_a_file_that_cannot_be_read_leaves_the_shell_served_and_says_why(own_pages, monkeypatch):
    client, _ = own_pages
    read = pathlib.Path.read_bytes

    def refused(path):
        if path.name == "look.css":
            raise PermissionError(13, "Permission denied")
        return read(path)
    monkeypatch.setattr(pathlib.Path, "read_bytes", refused)
    status, shell, _ = client.request("/")
    assert status == 200 and b'href="look.css"' in shell and b'src="app.js?v=' in shell
    status, answer = client.json("/look.css")
    assert status == 500 and answer["error"] == "the page file /look.css cannot be read: Permission denied"


def test_a_name_the_system_refuses_is_not_found(client):
    status, answer = client.json("/" + "a" * 300 + ".js")
    assert status == 404 and answer["error"].startswith("no such page")


def test_the_second_load_of_a_page_reads_no_script_style_sheet_or_data_file_again(server, chromium):
    """In headless Chromium: after a first load, loading a page afresh takes every file the shell names from the
    browser's own cache (Resource Timing: nothing transferred), and still reads the API."""
    chromium.open(server.page_url("moveabs", "engineer"))
    chromium.open(server.page_url("moveabs", "engineer"))
    entries = chromium.driver.execute_script(
        "return performance.getEntriesByType('resource').map((e) => [e.name, e.transferSize]);")
    files = [(re.sub(r"^.*/([^/?]+)(\?v=[0-9a-f]{16})?$", r"\1\2", name), size) for name, size in entries
             if "/api/" not in name]
    # each file once, under its versioned address (a data file fetched by its plain name would be read twice)
    assert sorted(name.partition("?v=")[0] for name, _ in files) == sorted(SHIPPED_REFERENCES), entries
    assert all("?v=" in name and size == 0 for name, size in files), files
    assert any("/api/mapping" in name and size > 0 for name, size in entries), entries
