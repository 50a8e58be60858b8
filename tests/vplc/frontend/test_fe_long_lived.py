"""What a load or a compile builds goes to the collector's permanent generation (vplc.project.LongLived); the
permanent generation is collected when it has doubled, so a process that loads and drops many projects holds a
bounded number of objects, and garbage frozen with the rest is freed then."""
from __future__ import annotations

import gc
import subprocess
import sys
import weakref
from pathlib import Path

from vplc.project import LongLived


class Cycle:
    """An object that only the cyclic collector can free."""

    def __init__(self):
        self.me = self


def fresh_process(script: str) -> str:
    """What ``script`` prints, run by a new Python process in the checkout (a process of its own: the collector's
    generations are per process)."""
    root = Path(__file__).resolve().parents[3]
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300, cwd=root)
    assert out.returncode == 0, out.stderr
    return out.stdout


def test_a_process_that_loads_once_freezes_what_it_loaded_and_never_collects_the_permanent_generation():
    printed = fresh_process(
        "import gc\n"
        "from vplc.project import LONG_LIVED, load_project\n"
        "proj = load_project(['lib/CBT_Commands_Lib'])\n"
        "assert not proj.has_errors\n"
        "print(gc.isenabled(), gc.get_freeze_count() > 50_000, LONG_LIVED.kept, gc.get_count()[0] < 700)\n")
    assert printed.split() == ["True", "True", "0", "True"]


def test_garbage_frozen_with_the_long_lived_objects_is_collected_when_the_permanent_generation_doubles():
    keeper = LongLived()
    keeper.RECLAIM_MIN = 10_000
    gc.disable()
    try:
        garbage = Cycle()
        alive = weakref.ref(garbage)
        del garbage                      # only the cyclic collector can free it, and it is switched off
        keeper.kept, keeper.since = 10**9, 0
        keeper.keep()                    # frozen: an ordinary full collection no longer sees it
        gc.collect()
        assert alive() is not None
        keeper.kept = 0
        keeper.since = keeper.RECLAIM_MIN + 1
        keeper.keep()                    # the permanent generation has doubled: collected, the rest frozen again
        assert alive() is None
        assert keeper.since == 0 and keeper.kept > 0     # what survived, frozen again
    finally:
        gc.unfreeze()
        gc.enable()


def test_loading_and_dropping_many_projects_keeps_the_permanent_generation_bounded():
    """With the reclaim threshold lowered to 200,000 objects, 12 loads of the library (about 65,000 objects each,
    all garbage once dropped, held together by cycles; the permanent generation is collected three times) leave at
    most twice the threshold frozen."""
    printed = fresh_process(
        "import gc\n"
        "from vplc import project\n"
        "project.LongLived.RECLAIM_MIN = 200_000\n"
        "peak = 0\n"
        "for _ in range(12):\n"
        "    proj = project.load_project(['lib/CBT_Commands_Lib'])\n"
        "    del proj\n"
        "    peak = max(peak, gc.get_freeze_count())\n"
        "print(peak)\n")
    assert int(printed) < 2 * 200_000 + 100_000      # without the reclaim: 12 x 65,000 = 780,000
