"""Fixtures every test package shares.

`run_cli` starts one of the project's command lines (`vplc`, `tmsim`, `cbtdemo`) as a child process, the way a
user starts it: for tests of the process (start-up, signals, exit). A test of what `vplc` prints and returns runs it
in the test process instead (tests/cli_main.py: no interpreter start, no compile of the same program again).
The packages are installed editable into .venv by the Makefile; from a plain checkout (`python3 -m pytest`, nothing
installed) the child finds them through PYTHONPATH, set here once for every child process a test starts.
"""
from __future__ import annotations

import os
import pathlib
import socket
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
SRC = ROOT / "src"


# A test process loads and drops some hundred projects; each collection of the collector's permanent generation
# (vplc.project.LongLived) walks what is alive and frees what was dropped. With the floor at four million objects
# instead of one, a worker collects it a few times instead of about a dozen. Measured on the 2-core machine, full
# runs back to back, two pairs: the workers' processor time 149 -> 131 and 145 -> 135 CPU-s (the whole machine's
# 272 -> 257 and 268 -> 266), their peak memory 273-432 -> 460-632 MB (eight million: no further gain, 868 MB).
# A process of the product keeps the default.
TEST_RECLAIM_MIN = 4_000_000


def pytest_configure(config):
    paths = os.environ.get("PYTHONPATH", "").split(os.pathsep)
    if str(SRC) not in paths:
        os.environ["PYTHONPATH"] = os.pathsep.join(p for p in [str(SRC), *paths] if p)
    from vplc.project import LONG_LIVED
    LONG_LIVED.RECLAIM_MIN = TEST_RECLAIM_MIN


def _run_cli(*args, module: str = "vplc", cwd=None, timeout: float = 300, **kw) -> subprocess.CompletedProcess:
    """`python -m <module> args...` from the checkout's root (or cwd), output captured as text."""
    return subprocess.run([sys.executable, "-m", module, *map(str, args)], capture_output=True, text=True,
                          cwd=cwd or ROOT, timeout=timeout, **kw)


@pytest.fixture(scope="session")
def run_cli():
    """A function that runs a project command line: run_cli("check", path) -> CompletedProcess."""
    return _run_cli


def _hold(port: int) -> socket.socket | None:
    """A socket holding loopback ``port`` (0: one the kernel picks), None when the port is taken. It binds without
    SO_REUSEADDR, so the bind fails when any socket has the port, then allows SO_REUSEADDR binds besides it."""
    holder = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        holder.bind(("127.0.0.1", port))
    except OSError:
        holder.close()
        return None
    holder.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    return holder


@pytest.fixture
def free_port():
    """A function giving a free loopback port, reserved until the test ends: for a server a test starts on a port of
    its choosing (a child process, a command-line option). ``free_port(n)``: the first of ``n`` consecutive ones.
    A port is held by a socket that is bound and does not listen, with SO_REUSEADDR set after its bind. The kernel
    hands such a port to no bind to port 0 and no outgoing connection (those are what made a port probed free and
    closed again get taken before the test's server bound it), and a bind without SO_REUSEADDR is refused. Our
    servers bind with SO_REUSEADDR and listen, which the holder allows (Linux refuses an SO_REUSEADDR bind only
    next to a socket that listens or that has not set SO_REUSEADDR). A child started with a port derived from a
    reserved one (a default control port) could still take another test's reserved port: give it its ports.
    Each call gives other ports."""
    holders: list[socket.socket] = []

    def reserve(count: int = 1) -> int:
        for _attempt in range(50):
            first = _hold(0)
            assert first is not None, "no free loopback port"
            base = first.getsockname()[1]
            neighbours = range(base + 1, base + count) if base + count <= 65536 else ()
            run = [first] + [h for h in map(_hold, neighbours) if h is not None]
            if len(run) == count:
                holders.extend(run)
                return base
            for holder in run:
                holder.close()
        pytest.skip(f"no {count} free consecutive loopback ports")
    yield reserve
    for holder in holders:
        holder.close()


# The files taking 10 s or more of a full run, longest first (tests/long_files_first.txt says why and when).
LONG_FILES_FIRST = tuple(line.strip() for line in (ROOT / "tests" / "long_files_first.txt").read_text().splitlines()
                         if line.strip() and not line.startswith("#"))


def pytest_collection_modifyitems(session, config, items):
    """The long files first (LONG_FILES_FIRST), every other test in its collected order."""
    rank = {path: n for n, path in enumerate(LONG_FILES_FIRST)}
    order = sorted(range(len(items)), key=lambda i: (rank.get(items[i].nodeid.split("::")[0], len(rank)), i))
    items[:] = [items[i] for i in order]
