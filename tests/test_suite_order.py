"""The order the workers take the files in (tests/long_files_first.txt, read by tests/conftest.py): every file
named there exists, once, so a renamed or removed file cannot silently fall back to the end of the run; and the
named files are collected before all others."""
from __future__ import annotations

import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[1]
LISTED = [line.strip() for line in (ROOT / "tests" / "long_files_first.txt").read_text().splitlines()
          if line.strip() and not line.startswith("#")]


def test_every_long_file_named_first_exists_once():
    assert len(set(LISTED)) == len(LISTED)
    missing = [path for path in LISTED if not (ROOT / path).is_file()]
    assert not missing, f"named in tests/long_files_first.txt but not a file: {missing}"


def test_the_long_files_are_collected_first(request):
    """In this session's collection (whatever part of the suite was asked for) the named files come first."""
    paths = [item.nodeid.split("::")[0] for item in request.session.items]
    named = [n for n, path in enumerate(paths) if path in LISTED]
    others = [n for n, path in enumerate(paths) if path not in LISTED]
    assert not named or not others or max(named) < min(others)
