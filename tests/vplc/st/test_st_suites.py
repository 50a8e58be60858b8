"""Run the ST test suites of this folder (TcUnit style) through `vplc test`."""
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))


def test_prelude_suites_pass():
    r = subprocess.run([sys.executable, "-m", "vplc", "test", HERE], capture_output=True, text=True, timeout=120)
    last = r.stdout.strip().splitlines()[-1]
    assert r.returncode == 0, r.stdout + r.stderr
    assert last.endswith(" passed, 0 failed") and not last.startswith("0 ")
