"""What the panel's browser may keep of the pages (cbt_hmi.web.assets): the page shell never, a style sheet, script or
data file named with the version of its bytes for good, any other file only with its validator (304 while unchanged).
Over HTTP against the shipped pages and a pages folder of the test's own, and in headless Chromium."""
from __future__ import annotations

import re

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


@pytest.mark.parametrize("query", ["", "?v=0123456789abcdef", "?v=", "?v=%ZZ&v=x", "?load=3"])
def test_a_file_asked_for_without_its_version_is_kept_only_with_its_validator(client, query):
    status, body, headers = client.request(f"/hmi.js{query}")
    assert status == 200 and body == (HMI_DIR / "hmi.js").read_bytes()
    assert headers["Cache-Control"] == "no-cache"
    assert headers["ETag"] == f'"{version_of(body)}"'


@pytest.mark.parametrize("form", ['{tag}', 'W/{tag}', '"0000000000000000", {tag}', '*'])
def test_an_unchanged_file_is_answered_304_without_its_bytes(client, form):
    _, _, headers = client.request("/alarms.js")
    status, body, again = client.request("/alarms.js", headers={"If-None-Match": form.format(tag=headers["ETag"])})
    assert status == 304 and body == b""
    assert again["ETag"] == headers["ETag"] and again["Cache-Control"] == "no-cache"


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


def test_the_second_load_of_a_page_reads_no_script_style_sheet_or_data_file_again(server, chromium):
    """In headless Chromium: after a first load, loading a page afresh takes every file the shell names from the
    browser's own cache (Resource Timing: nothing transferred), and still reads the API."""
    chromium.open(server.page_url("moveabs", "engineer"))
    chromium.open(server.page_url("moveabs", "engineer"))
    entries = chromium.driver.execute_script(
        "return performance.getEntriesByType('resource').map((e) => [e.name, e.transferSize]);")
    files = {re.sub(r"^.*/([^/?]+)\?v=.*$", r"\1", name): size for name, size in entries if "?v=" in name}
    assert sorted(files) == sorted(SHIPPED_REFERENCES), entries
    assert all(size == 0 for size in files.values()), files
    assert any("/api/mapping" in name and size > 0 for name, size in entries), entries
